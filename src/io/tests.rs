//! OBJ and supports parsing, malformed input with line numbers, bit-exact round trips.

use std::fs;
use std::path::PathBuf;

use super::*;
use crate::Error;

/// A fresh folder under the system temp dir, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("voussoir-io-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).expect("create temp dir");
        TempDir(dir)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\n";

fn parse_line_error(text: &str) -> (usize, String) {
    match parse_obj(text, "test.obj") {
        Err(Error::Parse { path, line, reason }) => {
            assert_eq!(path, "test.obj");
            (line, reason)
        }
        other => panic!("expected a parse error for {text:?}, got {other:?}"),
    }
}

#[test]
fn quads_and_polygons_are_fan_triangulated() {
    let text = format!("{SQUARE}v 2 0.5 0\nf 1 2 3 4\nf 2 5 3\nf 1 2 5 3 4\n");
    let (positions, faces) = parse_obj(&text, "quad.obj").unwrap();
    assert_eq!(positions.len(), 5);
    assert_eq!(positions[2], [1.0, 1.0, 0.5]);
    assert_eq!(
        faces,
        vec![
            [0, 1, 2],
            [0, 2, 3],
            [1, 4, 2],
            [0, 1, 4],
            [0, 4, 2],
            [0, 2, 3]
        ]
    );
}

#[test]
fn slash_forms_negative_indices_and_ignored_lines() {
    let text = "# a comment\r\n\
                o thing\n\
                v 0 0 0 1.0\n\
                v 1 0 0 # trailing comment\n\
                vt 0.5 0.5\n\
                vn 0 0 1\n\
                v 1 1 0 0.2 0.3 0.4\n\
                v 0 1 0\r\n\
                g group\n\
                s off\n\
                usemtl stone\n\
                mtllib stone.mtl\n\
                vp 0.5\n\
                l 1 2\n\
                f 1/1/1 2/2/1 3/3/1\n\
                f 1//1 3//1 4//1\n\
                f 1/5 3/6 4/7\n\
                f -4 -3 -2\n\
                f -1/1 -4/1/1 -2//1\n\
                \n   \t\n";
    let (positions, faces) = parse_obj(text, "forms.obj").unwrap();
    assert_eq!(positions.len(), 4);
    assert_eq!(positions[3], [0.0, 1.0, 0.0]);
    assert_eq!(
        faces,
        vec![[0, 1, 2], [0, 2, 3], [0, 2, 3], [0, 1, 2], [3, 0, 2]]
    );
}

#[test]
fn a_byte_order_mark_at_the_start_is_skipped() {
    let (positions, faces) =
        parse_obj("\u{feff}v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "x").unwrap();
    assert_eq!(positions.len(), 3);
    assert_eq!(faces, vec![[0, 1, 2]]);
}

#[test]
fn lines_may_end_in_cr_alone_or_cr_lf() {
    for text in [
        "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r",
        "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3",
    ] {
        let (positions, faces) = parse_obj(text, "x").unwrap();
        assert_eq!(positions, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        assert_eq!(faces, vec![[0, 1, 2]]);
    }
    // Line numbers count CR LF as one ending.
    assert_eq!(parse_line_error("v 0 0 0\r\nv 1 0\r\n").0, 2);
    assert_eq!(parse_line_error("v 0 0 0\rv 1 0\r").0, 2);
}

#[test]
fn a_vertex_may_carry_w_or_colours_but_not_another_statement() {
    let (positions, _) = parse_obj("v 0 0 1 0.5 0.2 0.1\nv 1 0 0 1\nv 0 1 0\n", "x").unwrap();
    assert_eq!(positions[0], [0.0, 0.0, 1.0]);
    for text in [
        "v 0 0 0 1 2 3 v 4 5 6 f 1 2 3\n",
        "v 0 0 0 1 2 3 4 5\n",
        "v 0 0 0 x\n",
    ] {
        let (line, reason) = parse_line_error(text);
        assert_eq!(line, 1, "{text:?}");
        assert!(
            reason.contains("after the vertex's coordinates"),
            "{reason}"
        );
    }
}

#[test]
fn faces_may_refer_to_later_vertices() {
    let (positions, faces) = parse_obj("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "x").unwrap();
    assert_eq!(positions.len(), 3);
    assert_eq!(faces, vec![[0, 1, 2]]);
}

#[test]
fn malformed_lines_report_their_line_number() {
    let cases: &[(&str, usize, &str)] = &[
        ("v 0 0 0\nv 1 0\n", 2, "3 are needed"),
        ("v 0 0 0\n\nv 1 x 0\n", 3, "bad number `x`"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", 4, "2 vertices"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf\n", 4, "0 vertices"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 0 2\n", 4, "index 0"),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n",
            5,
            "vertex 9",
        ),
        (
            "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\nf 1 2 4\n",
            5,
            "vertex 4",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 a 2\n",
            4,
            "bad vertex index `a`",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 /2 3\n",
            4,
            "bad vertex index `/2`",
        ),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2.5 3\n", 4, "`2.5`"),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n",
            4,
            "face lists vertex 2 twice",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3 -3\n",
            5,
            "face lists vertex 2 twice",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n",
            4,
            "relative vertex index -4",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999\n",
            4,
            "too large",
        ),
        // Statements that are not OBJ's would drop a face or a vertex unseen.
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nF 1 2 3\n",
            4,
            "unknown statement `F`",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf, 1 2 3\n",
            4,
            "unknown statement `f,`",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\n\u{200b}f 1 2 3\n",
            4,
            "unknown statement `\\u{200b}f`",
        ),
        ("v 0 0 0\n\u{feff}v 1 0 0\n", 2, "unknown statement"),
        ("vertex 0 0 0\n", 1, "only v and f are read"),
    ];
    for &(text, line, needle) in cases {
        let (got, reason) = parse_line_error(text);
        assert_eq!(got, line, "{text:?}: {reason}");
        assert!(
            reason.contains(needle),
            "{text:?}: {reason:?} lacks {needle:?}"
        );
        let message = Error::Parse {
            path: "test.obj".into(),
            line,
            reason,
        }
        .to_string();
        assert!(message.starts_with(&format!("test.obj:{line}: ")));
    }
}

#[test]
fn write_then_read_is_bit_exact() {
    let dir = TempDir::new("roundtrip");
    let positions = vec![
        [0.1, 1.0 / 3.0, -0.0],
        [1e-300, 1.797_693_134_862_315_7e308, 5e-324],
        [std::f64::consts::PI, -123_456_789.123_456_79, 2.0f64.sqrt()],
        [-1e22, 4.35e-7, 0.30000000000000004],
    ];
    let faces = vec![[0, 1, 2], [0, 2, 3]];
    let path = dir.0.join("out.obj");
    write_obj(&path, &positions, &faces).unwrap();
    let (p, f) = read_obj(&path).unwrap();
    assert_eq!(f, faces);
    let bits = |p: &[[f64; 3]]| -> Vec<u64> { p.iter().flatten().map(|c| c.to_bits()).collect() };
    assert_eq!(bits(&p), bits(&positions));
    // Overwriting an existing file works and leaves no temporary file behind.
    write_obj(&path, &positions[..3], &faces[..1]).unwrap();
    assert_eq!(read_obj(&path).unwrap().1, vec![[0, 1, 2]]);
    let names: Vec<_> = fs::read_dir(&dir.0)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("out.obj")]);
}

#[test]
fn write_failures_leave_nothing() {
    let dir = TempDir::new("write-fail");
    let missing = dir.0.join("no-such-folder").join("out.obj");
    let err = write_obj(&missing, &[[0.0; 3]; 3], &[[0, 1, 2]]).unwrap_err();
    assert!(
        matches!(&err, Error::Io { path, .. } if path.contains("out.obj")),
        "{err:?}"
    );
    let path = dir.0.join("bad.obj");
    let err = write_obj(&path, &[[0.0; 3]; 3], &[[0, 1, 3]]).unwrap_err();
    assert!(matches!(err, Error::InvalidArgument { name: "faces", .. }));
    assert!(err.to_string().contains("face 0 refers to vertex 3"));
    assert_eq!(fs::read_dir(&dir.0).unwrap().count(), 0);
}

/// Issue 48: a write replaced whatever its path named. Links are written through (the link
/// kept, the file it names replaced); devices, FIFOs and folders are refused untouched.
#[cfg(unix)]
#[test]
fn writes_go_through_links_and_never_replace_special_files() {
    use std::os::unix::fs::{symlink, FileTypeExt};
    let dir = TempDir::new("targets");
    let triangle = ([[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [[0u32, 1, 2]]);
    let write = |path: &std::path::Path| write_obj(path, &triangle.0, &triangle.1);
    let real = dir.0.join("real.obj");
    fs::write(&real, "old").unwrap();
    symlink("real.obj", dir.0.join("link.obj")).unwrap();
    symlink(dir.0.join("link.obj"), dir.0.join("chain.obj")).unwrap();
    write(&dir.0.join("chain.obj")).unwrap();
    assert!(fs::symlink_metadata(dir.0.join("link.obj"))
        .unwrap()
        .is_symlink());
    assert!(fs::symlink_metadata(dir.0.join("chain.obj"))
        .unwrap()
        .is_symlink());
    assert_eq!(read_obj(&real).unwrap().1, vec![[0, 1, 2]]);
    // A dangling link gets its file.
    symlink("made.obj", dir.0.join("dangling.obj")).unwrap();
    write(&dir.0.join("dangling.obj")).unwrap();
    assert!(dir.0.join("made.obj").is_file());
    // A loop of links is an error, not a hang.
    symlink("loop-b.obj", dir.0.join("loop-a.obj")).unwrap();
    symlink("loop-a.obj", dir.0.join("loop-b.obj")).unwrap();
    let err = write(&dir.0.join("loop-a.obj")).unwrap_err().to_string();
    assert!(err.contains("symbolic links in a row"), "{err}");

    let fifo = dir.0.join("pipe.obj");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.unwrap().success(), "mkfifo {}", fifo.display());
    symlink("pipe.obj", dir.0.join("to-pipe.obj")).unwrap();
    fs::create_dir(dir.0.join("folder.obj")).unwrap();
    let before = fs::read_dir(&dir.0).unwrap().count();
    let cases = [
        (fifo.clone(), "is a FIFO (named pipe), not a regular file"),
        (dir.0.join("to-pipe.obj"), "is a FIFO"),
        (dir.0.join("folder.obj"), "is a folder"),
        ("/dev/null".into(), "is a character device"),
        ("/dev/full".into(), "is a character device"),
    ];
    for (path, needle) in cases {
        if !path.starts_with(&dir.0) && !path.exists() {
            continue;
        }
        let err = write(&path).unwrap_err();
        assert!(
            matches!(&err, Error::Io { path: p, .. } if *p == path.display().to_string()),
            "{err:?}"
        );
        assert!(err.to_string().contains(needle), "{err}");
    }
    assert!(fs::metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
    assert_eq!(fs::read_dir(&dir.0).unwrap().count(), before);
}

#[test]
fn unreadable_files_are_io_errors() {
    let dir = TempDir::new("missing");
    let path = dir.0.join("absent.obj");
    assert!(matches!(read_obj(&path), Err(Error::Io { path: p, .. }) if p.contains("absent.obj")));
    assert!(matches!(read_supports(&path), Err(Error::Io { .. })));
    assert!(matches!(read_obj(&dir.0), Err(Error::Io { .. })));
}

#[test]
fn supports_in_both_shapes() {
    let object = "{\n \"anchored\": [3, 0, 7],\n \"counts\": {\"V\": 9},\n \"note\": \"x\"\n}";
    assert_eq!(parse_supports(object, "s.json").unwrap(), vec![3, 0, 7]);
    assert_eq!(
        parse_supports("[1, 2, 3]", "s.json").unwrap(),
        vec![1, 2, 3]
    );
    assert_eq!(parse_supports("[]", "s.json").unwrap(), Vec::<u32>::new());
    assert_eq!(
        parse_supports("{\"anchored\": []}", "s.json").unwrap(),
        Vec::<u32>::new()
    );
}

#[test]
fn malformed_supports_report_line_and_reason() {
    let cases: &[(&str, usize, &str)] = &[
        ("{\n \"anchored\": [1,\n -2]\n}", 3, "-2"),
        ("{\n \"anchored\": [1,\n 2.5]\n}", 3, "2.5"),
        ("[1, 2,\n \"3\"]", 2, "\"3\""),
        ("[1, 4294967296]", 1, "4294967296"),
        ("{\n \"supports\": [1]\n}", 3, "missing field `anchored`"),
        ("{\"anchored\": 5}", 1, "anchored"),
        ("42", 1, "found a number"),
        ("null", 1, "found null"),
        ("{\n \"anchored\": [1, 2\n", 3, "invalid JSON"),
        ("", 1, "invalid JSON"),
    ];
    // A long bad value is quoted by an excerpt, not in full.
    let long = format!("[\"{}\"]", "x".repeat(100_000));
    match parse_supports(&long, "s.json") {
        Err(Error::Parse { reason, .. }) => {
            assert!(reason.len() < 200, "{} bytes", reason.len());
            assert!(
                reason.contains(&format!("\"{}…\"", "x".repeat(40))),
                "{reason}"
            );
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    for &(text, line, needle) in cases {
        match parse_supports(text, "s.json") {
            Err(Error::Parse {
                path,
                line: got,
                reason,
            }) => {
                assert_eq!(path, "s.json");
                assert_eq!(got, line, "{text:?}: {reason}");
                assert!(
                    reason.contains(needle),
                    "{text:?}: {reason:?} lacks {needle:?}"
                );
            }
            other => panic!("{text:?}: expected a parse error, got {other:?}"),
        }
    }
}

#[test]
fn load_model_from_files() {
    let dir = TempDir::new("load");
    let obj = dir.0.join("m.obj");
    let json = dir.0.join("m.json");
    fs::write(&obj, format!("{SQUARE}v 9 9 9\nf 1 2 3 4\n")).unwrap();
    fs::write(&json, "{\"anchored\": [0, 1]}").unwrap();
    let mesh = load_model(&obj, &json).unwrap().mesh;
    assert_eq!(
        (mesh.n_vertices(), mesh.n_edges(), mesh.n_faces()),
        (5, 5, 2)
    );
    assert_eq!(mesh.unreferenced, vec![4]);
    fs::write(&json, "[0, 0]").unwrap();
    assert_eq!(
        load_model(&obj, &json).unwrap_err(),
        Error::InvalidAnchor {
            index: 0,
            reason: "listed twice"
        }
    );
}
