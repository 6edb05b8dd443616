//! The printable solid (`voussoir::thicken`): closed, oriented outwards, free of
//! self-intersections, of volume area × thickness, refused when too thick, and written to every
//! mesh format (3MF included) without losing it.

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};

use voussoir::generate::{cap_dome, dome_with_hole};
use voussoir::io::{self, MeshFormat};
use voussoir::{thicken, Error, Mesh, Solid, Thickness};

/// Every directed edge once, and its reverse once: closed, consistently oriented.
fn assert_watertight(faces: &[[u32; 3]]) {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for f in faces {
        for k in 0..3 {
            *directed.entry((f[k], f[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "edge {a}->{b} is used {n} times in this direction");
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "edge {a}->{b} has no opposite"
        );
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn area(mesh: &Mesh, f: usize) -> f64 {
    let [a, b, c] = mesh.faces()[f].map(|v| mesh.positions()[v as usize]);
    dot(cross(sub(b, a), sub(c, a)), cross(sub(b, a), sub(c, a))).sqrt() / 2.0
}

fn surface_area(mesh: &Mesh) -> f64 {
    (0..mesh.n_faces()).map(|f| area(mesh, f)).sum()
}

/// The volume computed here (divergence theorem about the first vertex), not the library's.
fn volume(positions: &[[f64; 3]], faces: &[[u32; 3]]) -> f64 {
    let o = positions[0];
    faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| sub(positions[v as usize], o));
            dot(a, cross(b, c)) / 6.0
        })
        .sum()
}

/// Whether segment `p`-`q` crosses triangle `t` (strictly: general position).
fn segment_crosses(p: [f64; 3], q: [f64; 3], t: [[f64; 3]; 3]) -> bool {
    let orient = |a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]| {
        dot(sub(a, d), cross(sub(b, d), sub(c, d)))
    };
    let (sp, sq) = (orient(t[0], t[1], t[2], p), orient(t[0], t[1], t[2], q));
    if sp * sq >= 0.0 {
        return false;
    }
    let s = [
        orient(p, q, t[0], t[1]),
        orient(p, q, t[1], t[2]),
        orient(p, q, t[2], t[0]),
    ];
    s.iter().all(|x| *x > 0.0) || s.iter().all(|x| *x < 0.0)
}

/// Pairs of faces sharing no vertex whose edges cross each other (all pairs: small meshes).
fn crossing_pairs(solid: &Solid) -> Vec<(usize, usize)> {
    let tri = |f: &[u32; 3]| f.map(|v| solid.positions[v as usize]);
    let mut pairs = Vec::new();
    for (i, a) in solid.faces.iter().enumerate() {
        for (j, b) in solid.faces.iter().enumerate().skip(i + 1) {
            if a.iter().any(|v| b.contains(v)) {
                continue;
            }
            let (ta, tb) = (tri(a), tri(b));
            let edge_hits = |t: [[f64; 3]; 3], other: [[f64; 3]; 3]| {
                (0..3).any(|k| segment_crosses(t[k], t[(k + 1) % 3], other))
            };
            if edge_hits(ta, tb) || edge_hits(tb, ta) {
                pairs.push((i, j));
            }
        }
    }
    pairs
}

#[test]
fn dome_solid_is_closed_outward_and_of_volume_area_times_thickness() {
    let mesh = cap_dome(0.9, 300).unwrap();
    let t = 0.05;
    let solid = thicken(&mesh, mesh.positions(), &Thickness::Uniform(t)).unwrap();
    assert_eq!(solid.positions.len(), 2 * mesh.n_vertices());
    let boundary_edges = mesh.edges().iter().filter(|e| e.is_boundary()).count();
    assert_eq!(solid.faces.len(), 2 * mesh.n_faces() + 2 * boundary_edges);
    assert_watertight(&solid.faces);
    let v = volume(&solid.positions, &solid.faces);
    assert!(v > 0.0, "inward orientation: volume {v}");
    assert!((solid.volume() - v).abs() < 1e-12 * v);
    let expected = surface_area(&mesh) * t;
    assert!(
        (v / expected - 1.0).abs() < 2e-3,
        "volume {v}, area x thickness {expected}"
    );
    assert!(crossing_pairs(&solid).is_empty());
}

#[test]
fn holes_get_walls_too() {
    let mesh = dome_with_hole(300).unwrap();
    assert_eq!(mesh.holes().count(), 1);
    let solid = thicken(&mesh, mesh.positions(), &Thickness::Uniform(0.03)).unwrap();
    assert_watertight(&solid.faces);
    let expected = surface_area(&mesh) * 0.03;
    let v = volume(&solid.positions, &solid.faces);
    assert!((v / expected - 1.0).abs() < 2e-3, "{v} vs {expected}");
    assert!(crossing_pairs(&solid).is_empty());
}

#[test]
fn thickness_from_density_varies_per_face() {
    let mesh = cap_dome(0.9, 200).unwrap();
    // Heavier (thicker) faces towards the rim.
    let density: Vec<f64> = (0..mesh.n_faces())
        .map(|f| {
            let c = mesh.faces()[f].map(|v| mesh.positions()[v as usize]);
            let r =
                ((c[0][0] + c[1][0] + c[2][0]) / 3.0).hypot((c[0][1] + c[1][1] + c[2][1]) / 3.0);
            2.0 * (0.02 + 0.04 * r)
        })
        .collect();
    let thickness = Thickness::from_density(&density, 2.0).unwrap();
    let solid = thicken(&mesh, mesh.positions(), &thickness).unwrap();
    assert_watertight(&solid.faces);
    let expected: f64 = (0..mesh.n_faces())
        .map(|f| area(&mesh, f) * density[f] / 2.0)
        .sum();
    let v = volume(&solid.positions, &solid.faces);
    assert!((v / expected - 1.0).abs() < 1e-2, "{v} vs {expected}");
    let (lo, hi) = solid
        .vertex_thickness
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), t| {
            (lo.min(*t), hi.max(*t))
        });
    assert!(lo < 0.03 && hi > 0.05, "thickness from {lo} to {hi}");
    assert!(matches!(
        Thickness::from_density(&density, 0.0),
        Err(Error::InvalidArgument {
            name: "unit_weight",
            ..
        })
    ));
}

#[test]
fn too_thick_is_refused_naming_the_face_and_what_fits() {
    let mesh = cap_dome(0.9, 200).unwrap();
    let err = thicken(&mesh, mesh.positions(), &Thickness::Uniform(3.0))
        .unwrap_err()
        .to_string();
    assert!(err.contains("turns over"), "{err}");
    assert!(err.contains("lower offset face"), "{err}");
    let face: usize = err
        .split("at face ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(face < mesh.n_faces());
    let fits: f64 = err
        .split("at most ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(fits > 1.0 && fits < 3.0, "{err}");
    // The limit is for that face; the thinnest spot of the whole dome may be lower still.
    let smaller = thicken(&mesh, mesh.positions(), &Thickness::Uniform(0.5 * fits));
    assert!(smaller.is_ok(), "{:?}", smaller.err());
}

/// Issue 48: a thickness of 1e154 or more overflowed the fold check and passed (or failed
/// only when written), one of 1e-20 vanished in `p + offset - p` and was refused as "no
/// thickness fits". Both now get the largest thickness that fits or a range error.
#[test]
fn extreme_thicknesses_get_what_fits_or_the_range() {
    let mesh = cap_dome(0.9, 200).unwrap();
    let p = mesh.positions();
    let fits = |t: f64| {
        let err = thicken(&mesh, p, &Thickness::Uniform(t))
            .unwrap_err()
            .to_string();
        assert!(err.contains("turns over"), "{t:e}: {err}");
        let tail = err.split("at most ").nth(1).unwrap();
        tail.split(' ').next().unwrap().parse::<f64>().unwrap()
    };
    let reference = fits(3.0);
    for t in [1e154, 1e160, 1e200, 1e300, f64::MAX] {
        assert_eq!(fits(t), reference, "{t:e}");
    }
    for t in [1e-11, 1e-9, 1e-3] {
        let solid = thicken(&mesh, p, &Thickness::Uniform(t)).unwrap();
        assert!(solid.volume() > 0.0, "{t:e}");
    }
    let named = |err: &str, before: &str| -> f64 {
        let tail = err.split(before).nth(1).unwrap();
        tail.trim_end_matches(|c: char| !c.is_ascii_digit())
            .parse()
            .unwrap()
    };
    for t in [1e-13, 1e-20, 1e-300, 5e-324] {
        let err = thicken(&mesh, p, &Thickness::Uniform(t))
            .unwrap_err()
            .to_string();
        assert!(err.contains("too small for a solid"), "{t:e}: {err}");
        let least = named(&err, "give at least ");
        assert!(least > 1e-12 && least < 1e-11, "{err}");
    }
    // A flat plate folds at no thickness: beyond the range, the range is the answer.
    let mut flat = p.to_vec();
    for q in &mut flat {
        q[2] = 0.0;
    }
    let plate = Mesh::new(flat.clone(), mesh.faces().to_vec(), &[0]).unwrap();
    let err = thicken(&plate, &flat, &Thickness::Uniform(1e154))
        .unwrap_err()
        .to_string();
    assert!(err.contains("too large for a solid"), "{err}");
    let most = named(&err, "give at most ");
    assert!(most > 1e12 && most < 1e13, "{err}");
    assert!(thicken(&plate, &flat, &Thickness::Uniform(most)).is_ok());
}

#[test]
fn bad_thickness_and_positions_are_refused() {
    let mesh = cap_dome(0.9, 100).unwrap();
    let p = mesh.positions();
    for (t, needle) in [
        (Thickness::Uniform(0.0), "face 0: 0 must be > 0"),
        (Thickness::Uniform(-1.0), "face 0: -1 must be > 0"),
        (Thickness::Uniform(f64::NAN), "face 0: NaN is not finite"),
        (
            Thickness::PerFace(vec![0.1; 3]),
            "has 3 entries, expected one per face",
        ),
    ] {
        let err = thicken(&mesh, p, &t).unwrap_err().to_string();
        assert!(err.contains(needle), "{err}");
    }
    let mut bad = p.to_vec();
    bad[4][2] = f64::INFINITY;
    let err = thicken(&mesh, &bad, &Thickness::Uniform(0.1)).unwrap_err();
    assert!(err.to_string().contains("vertex 4"), "{err}");
    let err = thicken(&mesh, &p[1..], &Thickness::Uniform(0.1)).unwrap_err();
    assert!(err.to_string().contains("expected one per vertex"), "{err}");
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("voussoir-solid-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The vertices and triangles of a 3MF file's model part, read here with the zip crate and
/// string scanning (this writer puts one element per line).
fn read_3mf(path: &Path) -> io::RawMesh {
    let file = std::fs::File::open(path).unwrap();
    let mut archive = zip::ZipArchive::new(file).unwrap();
    for part in ["[Content_Types].xml", "_rels/.rels"] {
        assert!(archive.by_name(part).is_ok(), "no {part}");
    }
    let mut xml = String::new();
    archive
        .by_name("3D/3dmodel.model")
        .unwrap()
        .read_to_string(&mut xml)
        .unwrap();
    let attr = |line: &str, name: &str| -> String {
        let start = line.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        line[start..].split('"').next().unwrap().to_string()
    };
    let (mut positions, mut faces) = (Vec::new(), Vec::new());
    for line in xml.lines() {
        if line.starts_with("<vertex ") {
            positions.push(["x", "y", "z"].map(|k| attr(line, k).parse::<f64>().unwrap()));
        } else if line.starts_with("<triangle ") {
            faces.push(["v1", "v2", "v3"].map(|k| attr(line, k).parse::<u32>().unwrap()));
        }
    }
    (positions, faces)
}

#[test]
fn every_format_keeps_the_solid() {
    let mesh = dome_with_hole(200).unwrap();
    let solid = thicken(&mesh, mesh.positions(), &Thickness::Uniform(0.04)).unwrap();
    let dir = scratch("formats");
    let bits = |p: &[[f64; 3]]| p.iter().map(|x| x.map(f64::to_bits)).collect::<Vec<_>>();
    for name in ["s.off", "s.obj", "s.ply", "s-ascii.ply", "s.3mf"] {
        let path = dir.join(name);
        let mut format = MeshFormat::from_path(&path).unwrap();
        if name.contains("ascii") {
            format = format.ascii();
        }
        io::write_mesh_as(&path, format, &solid.positions, &solid.faces).unwrap();
        let (p, f) = if name.ends_with(".3mf") {
            read_3mf(&path)
        } else {
            io::read_mesh(&path).unwrap()
        };
        assert_eq!(bits(&p), bits(&solid.positions), "{name}");
        assert_eq!(f, solid.faces, "{name}");
    }
    for (name, binary) in [("s.stl", true), ("s-ascii.stl", false)] {
        let path = dir.join(name);
        io::write_mesh_as(
            &path,
            MeshFormat::Stl { binary },
            &solid.positions,
            &solid.faces,
        )
        .unwrap();
        let (p, f) = io::read_mesh(&path).unwrap();
        let welded = io::weld(&p, &f, io::DEFAULT_WELD_TOLERANCE).unwrap();
        assert_eq!(welded.positions.len(), solid.positions.len(), "{name}");
        assert_watertight(&welded.faces);
        let v = volume(&welded.positions, &welded.faces);
        assert!((v / solid.volume() - 1.0).abs() < 1e-5, "{name}: {v}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn three_mf_refuses_an_open_mesh() {
    let mesh = cap_dome(0.9, 50).unwrap();
    let dir = scratch("open-3mf");
    let path = dir.join("shell.3mf");
    let err = io::write_mesh(&path, mesh.positions(), mesh.faces()).unwrap_err();
    assert!(err.to_string().contains("3MF holds closed solids"), "{err}");
    assert!(!path.exists());
    let err = io::read_mesh(&path).unwrap_err();
    assert!(
        err.to_string().contains("3MF is written, not read"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A gable roof over [-1, 1] x [0, 1], its ridge along x = 0 cut by a slit `gap` wide: the
/// lower offsets of the two slopes move towards each other under the slit.
fn slit_roof(gap: f64) -> Mesh {
    use voussoir::generate::{lift, rectangle, triangulate, Domain};
    let g = gap / 2.0;
    let domain = Domain {
        outer: rectangle(-1.0, 0.0, 1.0, 1.0, 20, 10),
        holes: vec![vec![[-g, 0.2], [g, 0.2], [g, 0.8], [-g, 0.8]]],
    };
    let (points, triangles) = triangulate(&domain, 0.002).unwrap();
    lift(
        &points,
        &triangles,
        |[x, _]| -1.5 * x.abs(),
        |_, outer| outer,
    )
    .unwrap()
}

#[test]
fn parts_that_meet_across_a_slit_are_refused() {
    let mesh = slit_roof(0.005);
    let thin = thicken(&mesh, mesh.positions(), &Thickness::Uniform(0.002)).unwrap();
    assert_watertight(&thin.faces);
    let err = thicken(&mesh, mesh.positions(), &Thickness::Uniform(0.0075))
        .unwrap_err()
        .to_string();
    assert!(err.contains("would intersect itself where"), "{err}");
    assert!(err.contains("crosses"), "{err}");
}

#[test]
fn clockwise_input_and_unreferenced_vertices_still_give_an_outward_closed_solid() {
    let dome = cap_dome(0.9, 100).unwrap();
    let anchored: Vec<u32> = (0..dome.n_vertices() as u32)
        .filter(|&v| dome.anchored()[v as usize])
        .collect();
    let mut positions = dome.positions().to_vec();
    positions.push([5.0, 5.0, 5.0]);
    let clockwise: Vec<[u32; 3]> = dome.faces().iter().map(|&[a, b, c]| [a, c, b]).collect();
    let mesh = Mesh::new(positions, clockwise, &anchored).unwrap();
    assert!(mesh.reversed());
    let solid = thicken(&mesh, mesh.positions(), &Thickness::Uniform(0.05)).unwrap();
    assert_eq!(
        solid.positions.len(),
        2 * dome.n_vertices(),
        "the lone vertex is left out"
    );
    assert_watertight(&solid.faces);
    assert!(volume(&solid.positions, &solid.faces) > 0.0);
}
