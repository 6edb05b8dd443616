//! OFF, STL and PLY: parsing, malformed files with the line or element at fault, bit-exact
//! round trips through the extension dispatch, and welding.

use std::fs;
use std::path::{Path, PathBuf};

use super::*;
use crate::Error;

/// A fresh folder under the system temp dir, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("voussoir-fmt-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).expect("create temp dir");
        TempDir(dir)
    }

    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

/// Awkward values: not representable in short decimals, tiny, huge, negative zero.
fn awkward_mesh() -> RawMesh {
    let positions = vec![
        [0.1, 1.0 / 3.0, -0.0],
        [2.0f64.sqrt(), 5e-324, 1e-300],
        [-2.5e17, std::f64::consts::PI, 123456.789 + 1e-10],
        [7.0, -1.0e-7, 0.30000000000000004],
    ];
    (positions, vec![[0, 1, 2], [0, 2, 3]])
}

fn bits(positions: &[[f64; 3]]) -> Vec<[u64; 3]> {
    positions.iter().map(|p| p.map(f64::to_bits)).collect()
}

#[test]
fn obj_off_ply_keep_positions_bit_for_bit() {
    let dir = TempDir::new("bits");
    let (positions, faces) = awkward_mesh();
    for name in ["m.obj", "m.off", "m.ply", "m.PLY"] {
        let path = dir.path(name);
        write_mesh(&path, &positions, &faces).unwrap();
        let (p, f) = read_mesh(&path).unwrap();
        assert_eq!(bits(&p), bits(&positions), "{name}");
        assert_eq!(f, faces, "{name}");
    }
    let path = dir.path("ascii.ply");
    let format = MeshFormat::from_path(&path).unwrap().ascii();
    write_mesh_as(&path, format, &positions, &faces).unwrap();
    assert!(fs::read_to_string(&path)
        .unwrap()
        .contains("format ascii 1.0"));
    let (p, f) = read_mesh(&path).unwrap();
    assert_eq!((bits(&p), f), (bits(&positions), faces));
}

#[test]
fn stl_rounds_to_single_precision_in_both_encodings() {
    let dir = TempDir::new("stl");
    let (positions, faces) = awkward_mesh();
    let binary = dir.path("m.stl");
    write_mesh(&binary, &positions, &faces).unwrap();
    assert_eq!(fs::metadata(&binary).unwrap().len(), 84 + 50 * 2);
    let ascii = dir.path("a.stl");
    write_mesh_as(
        &ascii,
        MeshFormat::Stl { binary: false },
        &positions,
        &faces,
    )
    .unwrap();
    assert!(fs::read_to_string(&ascii).unwrap().starts_with("solid "));
    for path in [binary, ascii] {
        let (p, f) = read_mesh(&path).unwrap();
        assert_eq!(f, vec![[0, 1, 2], [3, 4, 5]]);
        let expected: Vec<[f64; 3]> = [0, 1, 2, 0, 2, 3]
            .iter()
            .map(|&v: &usize| positions[v].map(|c| f64::from(c as f32)))
            .collect();
        assert_eq!(bits(&p), bits(&expected), "{}", path.display());
    }
}

#[test]
fn unknown_extensions_are_named() {
    for (name, needle) in [("m.xyz", "`.xyz`"), ("m", "no extension")] {
        match write_mesh(Path::new(name), &[], &[]) {
            Err(Error::InvalidArgument { reason, .. }) => {
                assert!(reason.contains(needle), "{reason}")
            }
            other => panic!("{name}: {other:?}"),
        }
        assert!(read_mesh(Path::new(name)).is_err());
    }
}

#[test]
fn writers_reject_bad_meshes_and_leave_no_file() {
    let dir = TempDir::new("bad-write");
    let (positions, _) = awkward_mesh();
    let mut nan = positions.clone();
    nan[2][1] = f64::NAN;
    for name in ["m.obj", "m.off", "m.stl", "m.ply"] {
        let path = dir.path(name);
        let out_of_range = write_mesh(&path, &positions, &[[0, 1, 4]]).unwrap_err();
        assert!(
            out_of_range.to_string().contains("vertex 4"),
            "{out_of_range}"
        );
        let non_finite = write_mesh(&path, &nan, &[[0, 1, 2]]).unwrap_err();
        assert!(non_finite.to_string().contains("vertex 2"), "{non_finite}");
        assert!(!path.exists());
    }
    assert_eq!(fs::read_dir(&dir.0).unwrap().count(), 0);
}

fn parse_error(result: Result<RawMesh>) -> (String, String) {
    match result {
        Err(Error::Parse { line, reason, .. }) => (format!("line {line}"), reason),
        Err(Error::Malformed {
            element, reason, ..
        }) => (element, reason),
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn off_variants_as_cgal_and_geomview_write_them() {
    let text = "# made by hand\nOFF\n# counts\n4 2 0\n\n0 0 0\n1 0 0 # a comment\n1 1 0.5\n0 1 0\n4 0 1 2 3 255 0 0\n3 1 3 2\n";
    let (p, f) = parse_off(text.as_bytes(), "x.off").unwrap();
    assert_eq!(p[2], [1.0, 1.0, 0.5]);
    assert_eq!(f, vec![[0, 1, 2], [0, 2, 3], [1, 3, 2]]);
    // Counts on the keyword's line, colours and normals after the coordinates, no keyword.
    let coff = "NOFF 3 1 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n";
    assert_eq!(parse_off(coff.as_bytes(), "x").unwrap().1, vec![[0, 1, 2]]);
    let bare = "3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(parse_off(bare.as_bytes(), "x").unwrap().0.len(), 3);
}

#[test]
fn malformed_off_files_report_their_line() {
    const HEAD: &str = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n";
    let cases: Vec<(String, &str, &str)> = vec![
        (String::new(), "line 1", "ends before the OFF header"),
        ("OFF\n".into(), "line 1", "ends before the counts"),
        ("OFF\n3 x 0\n".into(), "line 2", "bad face count `x`"),
        ("OFF\n3\n".into(), "line 2", "missing face count"),
        ("OFF BINARY\n".into(), "line 1", "binary OFF"),
        ("4OFF\n".into(), "line 1", "not a supported OFF variant"),
        ("OFF\n3 1 0\n0 0 0\n1 0\n".into(), "line 4", "2 coordinates"),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 nan\n".into(),
            "line 4",
            "not finite",
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 e 0\n".into(),
            "line 4",
            "bad number `e`",
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 0\n".into(),
            "line 4",
            "before vertex 2",
        ),
        (HEAD.into(), "line 5", "before face 0"),
        (format!("{HEAD}3 0 1 7\n"), "line 6", "vertex 7"),
        (
            format!("{HEAD}3 0 1\n"),
            "line 6",
            "declares 3 vertices but lists 2",
        ),
        (format!("{HEAD}2 0 1\n"), "line 6", "2 vertices"),
        (
            format!("{HEAD}3 0 2 2\n"),
            "line 6",
            "face 0 lists vertex 2 twice",
        ),
        (
            format!("{HEAD}3 0 -1 2\n"),
            "line 6",
            "bad vertex index `-1`",
        ),
        (
            format!("{HEAD}3 0 1 2\n3 0 1 2\n"),
            "line 7",
            "content after",
        ),
    ];
    for (text, at, needle) in cases {
        let (where_, reason) = parse_error(parse_off(text.as_bytes(), "bad.off"));
        assert_eq!(where_, at, "{text:?}: {reason}");
        assert!(reason.contains(needle), "{text:?}: {reason}");
    }
}

fn binary_stl(header: &[u8; 80], triangles: &[[f32; 9]]) -> Vec<u8> {
    let mut bytes = header.to_vec();
    bytes.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        bytes.extend([0u8; 12]);
        for c in t {
            bytes.extend(c.to_le_bytes());
        }
        bytes.extend([0u8; 2]);
    }
    bytes
}

#[test]
fn binary_stl_whose_header_begins_with_solid_is_binary() {
    let mut header = [b' '; 80];
    header[..12].copy_from_slice(b"solid part 1");
    let t = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.5];
    let bytes = binary_stl(&header, &[t, t]);
    let (p, f) = parse_stl(&bytes, "x.stl").unwrap();
    assert_eq!(p.len(), 6);
    assert_eq!(p[5], [0.0, 1.0, 0.5]);
    assert_eq!(f, vec![[0, 1, 2], [3, 4, 5]]);
}

#[test]
fn ascii_stl_with_several_solids_and_a_nameless_one() {
    let facet = "facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n vertex 0 1 0\n endloop\nendfacet\n";
    let text = format!("solid\n{facet}endsolid\nsolid two\n{facet}{facet}endsolid two\n");
    let (p, f) = parse_stl(text.as_bytes(), "x.stl").unwrap();
    assert_eq!((p.len(), f.len()), (9, 3));
    // A solid without facets is no parse error: the mesh it makes is empty.
    let (p, f) = parse_stl(b"solid x\nendsolid x\n", "x.stl").unwrap();
    assert!(p.is_empty() && f.is_empty());
}

#[test]
fn malformed_stl_files_name_the_triangle() {
    let t = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.5];
    let good = binary_stl(&[0; 80], &[t, t, t]);
    let mut nan = t;
    nan[4] = f32::NAN;
    let facet = "facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n vertex 0 1 0\n endloop\nendfacet\n";
    let mut cases: Vec<(Vec<u8>, &str, &str)> = vec![
        (
            good[..good.len() - 7].to_vec(),
            "header",
            "this file has 227 bytes",
        ),
        (
            [good.as_slice(), b"xx"].concat(),
            "header",
            "declaring 3 triangles",
        ),
        (b"garbage".to_vec(), "header", "neither ASCII STL"),
        (binary_stl(&[0; 80], &[t, nan]), "triangle 1", "corner 1"),
        (
            format!(
                "solid x\n{facet}{}",
                facet.replace("vertex 1 0 0", "vertex 1 zero 0")
            )
            .into(),
            "line 12",
            "triangle 1: corner 1: `zero` is not a number",
        ),
        (
            format!("solid x\n{facet}facet normal 0 0 1\n outer loop\n").into(),
            "line 10",
            "ends where `vertex x y z` for corner 0 of triangle 1 is expected",
        ),
        (
            format!("solid x\n{facet}").into(),
            "line 8",
            "ends where `facet normal` for triangle 1 or `endsolid` is expected",
        ),
        (
            format!("solid x\n{facet}endsolid x\nstray bytes\n").into(),
            "line 10",
            "only another solid may follow",
        ),
        (
            format!("solid x\n{facet}")
                .replace("endloop", "endloop x")
                .into(),
            "line 7",
            "expected `endloop` of triangle 0 (`endloop x`)",
        ),
        (
            format!("solid x\n{}endsolid\n", facet.replace("0 1 0", "0 1e39 0")).into(),
            "line 6",
            "corner 2 has a NaN or infinite coordinate",
        ),
    ];
    let long = format!(
        "solid x\n{}endsolid\n",
        facet.replace("1 0 0", &"1".repeat(100_000))
    );
    let long_excerpt = format!(
        "expected `vertex x y z` for corner 1 of triangle 0 (`vertex {}…`)",
        "1".repeat(33)
    );
    cases.push((long.into(), "line 5", &long_excerpt));
    for (bytes, at, needle) in cases {
        let (where_, reason) = parse_error(parse_stl(&bytes, "bad.stl"));
        assert_eq!(where_, at, "{reason}");
        assert!(reason.contains(needle), "{reason}");
        assert!(!reason.contains('\n'), "{reason}");
        assert!(reason.len() < 200, "{reason}");
    }
}

const PLY_HEAD: &str = "ply\nformat ascii 1.0\ncomment hand made\nelement vertex 4\nproperty float x\nproperty float y\nproperty double z\nproperty uchar red\nelement face 2\nproperty list uchar int vertex_index\nend_header\n";

#[test]
fn ascii_and_big_endian_ply_with_other_properties() {
    let text = format!("{PLY_HEAD}0 0 0 1\n1 0 0 2\n1 1 0.5 3\n0 1 0 4\n4 0 1 2 3\n3 1 3 2\n");
    let (p, f) = parse_ply(text.as_bytes(), "x.ply").unwrap();
    assert_eq!(p[2], [1.0, 1.0, 0.5]);
    assert_eq!(f, vec![[0, 1, 2], [0, 2, 3], [1, 3, 2]]);
    let mut bytes = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
    for c in [0.0f64, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.25] {
        bytes.extend(c.to_be_bytes());
    }
    bytes.push(3);
    for i in [0u32, 1, 2] {
        bytes.extend(i.to_be_bytes());
    }
    let (p, f) = parse_ply(&bytes, "x.ply").unwrap();
    assert_eq!((p[2], f), ([0.0, 1.0, 0.25], vec![[0, 1, 2]]));
    // The sized type names some exporters write.
    let sized = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float32 x\nproperty float32 y\nproperty float64 z\nelement face 1\nproperty list uint8 int32 vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 2.5\n3 0 1 2\n";
    let (p, f) = parse_ply(sized.as_bytes(), "x.ply").unwrap();
    assert_eq!((p[2], f), ([0.0, 1.0, 2.5], vec![[0, 1, 2]]));
}

#[test]
fn malformed_ply_files_name_the_line_or_element() {
    let dir = TempDir::new("ply-bad");
    let (positions, faces) = awkward_mesh();
    let path = dir.path("m.ply");
    write_mesh(&path, &positions, &faces).unwrap();
    let binary = fs::read(&path).unwrap();
    let body = |rest: &str| format!("{PLY_HEAD}0 0 0 1\n1 0 0 2\n1 1 0.5 3\n{rest}").into_bytes();
    let cases: Vec<(Vec<u8>, &str, &str)> = vec![
        (b"solid x".to_vec(), "line 1", "not a PLY file"),
        (
            PLY_HEAD
                .replace("element vertex 4", "element vertex four")
                .into_bytes(),
            "line 4",
            "bad header: element `vertex`: count `four` is not a whole number",
        ),
        (body(""), "line 14", "ends before vertex 3"),
        (body("0 1 zero 4\n"), "line 15", "vertex 3"),
        (
            body("0 1 1e999 4\n4 0 1 2 3\n3 1 3 2\n"),
            "line 15",
            "not finite",
        ),
        (
            body("0 1 0 4\n4 0 1 2 3\n"),
            "line 16",
            "ends before face 1",
        ),
        (
            body("0 1 0 4\n4 0 1 2 3\n3 1 3 2\n1\n"),
            "line 18",
            "content after",
        ),
        (body("0 1 0 4\n4 0 1 2 9\n3 1 3 2\n"), "face 0", "vertex 9"),
        (body("0 1 0 4\n2 0 1\n3 1 3 2\n"), "face 0", "2 vertices"),
        (
            binary[..binary.len() - 5].to_vec(),
            "face 1",
            "ends inside it",
        ),
        (
            binary[..binary.len() - 20].to_vec(),
            "face 0",
            "ends inside it",
        ),
        (
            binary[..binary.len() - 26].to_vec(),
            "face 0",
            "ends before it",
        ),
        ([binary.as_slice(), b"x"].concat(), "end", "1 byte after"),
    ];
    for (bytes, at, needle) in cases {
        let (where_, reason) = parse_error(parse_ply(&bytes, "bad.ply"));
        assert_eq!(where_, at, "{reason}");
        assert!(reason.contains(needle), "{at}: {reason}");
        assert!(!reason.contains('\n'), "{reason}");
    }
}

/// The header counts, versions and ASCII face lines of issue 48's reproducers: each a parse
/// error naming its line, never a panic, never a face dropped.
#[test]
fn ply_counts_beyond_64_bits_and_face_lines_against_their_count() {
    let head = |vertices: &str, faces: &str, format: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex {vertices}\nproperty float x\n\
             property float y\nproperty float z\nelement face {faces}\n\
             property list uchar int vertex_indices\nend_header\n"
        )
    };
    let vertices = "0 0 0\n1 0 0\n0 1 0\n1 1 1\n";
    let huge = "99999999999999999999999";
    let cases: Vec<(String, &str, &str)> = vec![
        (
            head(huge, "1", "ascii") + vertices,
            "line 3",
            "count `99999999999999999999999` is larger than 18446744073709551615",
        ),
        (
            head("4", huge, "ascii") + vertices,
            "line 7",
            "element `face`: count `99999999999999999999999` is larger",
        ),
        (
            head(huge, "1", "binary_little_endian"),
            "line 3",
            "is larger than 18446744073709551615",
        ),
        (
            head("4", "1", "ascii") + vertices + "3 0 1 2 3\n",
            "line 14",
            "face 0: 1 more number than its properties take, in `3 0 1 2 3`",
        ),
        (
            head("4", "2", "ascii") + vertices + "3 0 1 2 3 1 3 2\n3 0 1 3\n",
            "line 14",
            "face 0: 4 more numbers than its properties take",
        ),
        (
            head("4", "1", "ascii") + vertices + "4 0 1 2\n",
            "line 14",
            "face 0: the line ends before item 3 of `vertex_indices` (4 numbers in `4 0 1 2`)",
        ),
        (
            head("4", "1", "ascii") + vertices + "256 0 1 2\n",
            "line 14",
            "the count of `vertex_indices`: 256 is out of the range of uchar (0 to 255)",
        ),
        (
            head("4", "1", "ascii") + vertices + "3 0 1 99999999999\n",
            "line 14",
            "item 2 of `vertex_indices`: 99999999999 is out of the range of int",
        ),
        (
            head("4", "1", "ascii") + "0 0 0 7\n",
            "line 10",
            "vertex 0: 1 more number than its properties take",
        ),
        (
            head("4", "1", "ascii") + vertices + "3 0 1 1\n",
            "face 0",
            "lists vertex 1 twice",
        ),
        (
            head("4", "1", "ascii").replace("property float y", "property floot y"),
            "line 5",
            "unknown property type `floot`",
        ),
        (
            head("4", "1", "ascii").replace("property float z\n", ""),
            "line 3",
            "element `vertex` has no number `z`",
        ),
    ];
    for (text, at, needle) in cases {
        let (where_, reason) = parse_error(parse_ply(text.as_bytes(), "bad.ply"));
        assert_eq!(where_, at, "{text:?}: {reason}");
        assert!(reason.contains(needle), "{at}: {reason}");
    }
    // Any version number is read (the crate this parser replaced panicked beyond 64 bits).
    let text =
        head("4", "1", "ascii").replace("1.0", &format!("{huge}.0")) + vertices + "3 0 1 2\n";
    assert_eq!(
        parse_ply(text.as_bytes(), "v.ply").unwrap().1,
        vec![[0, 1, 2]]
    );
    // A binary face whose count runs past the end of the file allocates nothing first.
    let mut bytes = head("3", "1", "binary_little_endian").into_bytes();
    bytes.extend([0u8; 36]);
    bytes.push(255);
    bytes.extend(0i32.to_le_bytes());
    let (where_, reason) = parse_error(parse_ply(&bytes, "bad.ply"));
    assert_eq!(where_, "face 0");
    assert!(reason.contains("declares 255 items, 1 fit"), "{reason}");
}
