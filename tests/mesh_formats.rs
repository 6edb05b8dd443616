//! Round trips of the nine shared models through every format: OBJ → OFF → PLY (binary and
//! ASCII) → OBJ keeps positions bit for bit; STL, after welding, keeps the vertex set rounded
//! to single precision and the connectivity. Skipped when ../shared/data/models is absent
//! (failing in CI: tests/common/models.rs).

mod common;

use std::path::{Path, PathBuf};

use common::{models_dir, MODELS};
use voussoir::io::{self, MeshFormat};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("voussoir-formats-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn bits(positions: &[[f64; 3]]) -> Vec<[u64; 3]> {
    positions.iter().map(|p| p.map(f64::to_bits)).collect()
}

fn through(dir: &Path, name: &str, format: Option<MeshFormat>, mesh: &io::RawMesh) -> io::RawMesh {
    let path = dir.join(name);
    match format {
        Some(f) => io::write_mesh_as(&path, f, &mesh.0, &mesh.1).unwrap(),
        None => io::write_mesh(&path, &mesh.0, &mesh.1).unwrap(),
    }
    io::read_mesh(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn obj_off_ply_obj_keeps_every_bit() {
    let Some(models) = models_dir() else {
        return;
    };
    for model in MODELS {
        let dir = scratch(model);
        let original = io::read_mesh(&models.join(format!("{model}.obj"))).unwrap();
        let off = through(&dir, "m.off", None, &original);
        let ply = through(&dir, "m.ply", None, &off);
        let ascii = through(&dir, "a.ply", Some(MeshFormat::Ply { binary: false }), &ply);
        let obj = through(&dir, "m.obj", None, &ascii);
        assert_eq!(bits(&obj.0), bits(&original.0), "{model}: positions");
        assert_eq!(obj.1, original.1, "{model}: faces");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn stl_after_welding_keeps_vertices_in_single_precision_and_connectivity() {
    let Some(models) = models_dir() else {
        return;
    };
    for model in MODELS {
        let dir = scratch(&format!("{model}-stl"));
        let (positions, faces) = io::read_mesh(&models.join(format!("{model}.obj"))).unwrap();
        for (name, format) in [
            ("m.stl", MeshFormat::Stl { binary: true }),
            ("a.stl", MeshFormat::Stl { binary: false }),
        ] {
            let soup = through(
                &dir,
                name,
                Some(format),
                &(positions.clone(), faces.clone()),
            );
            assert_eq!(soup.0.len(), 3 * faces.len());
            let welded = io::weld(&soup.0, &soup.1, io::DEFAULT_WELD_TOLERANCE).unwrap();
            // A one-to-one map between welded and original vertices through the faces.
            let mut original_of = vec![u32::MAX; welded.positions.len()];
            for (w, f) in welded.faces.iter().zip(&faces) {
                for k in 0..3 {
                    let slot = &mut original_of[w[k] as usize];
                    assert!(
                        *slot == u32::MAX || *slot == f[k],
                        "{model}: {name} merges vertices"
                    );
                    *slot = f[k];
                }
            }
            let referenced: std::collections::BTreeSet<u32> =
                faces.iter().flatten().copied().collect();
            assert_eq!(welded.positions.len(), referenced.len(), "{model}: {name}");
            assert!(welded.collapsed_faces.is_empty());
            for (w, &o) in original_of.iter().enumerate() {
                let single = positions[o as usize].map(|c| f64::from(c as f32));
                assert_eq!(welded.positions[w], single, "{model}: {name} vertex {o}");
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// Polygons are split into fans; the diagonals the split adds are listed, in every format that
/// has polygons (none for STL, whose faces are triangles).
#[test]
fn polygon_diagonals_are_listed_for_every_polygon_format() {
    let dir = scratch("diagonals");
    let xy = [[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [0, 1], [1, 2]];
    let vertices: Vec<String> = xy.iter().map(|[x, y]| format!("{x} {y} 0")).collect();
    // A quad 0 1 4 5 and a pentagon 1 2 3 6 4.
    let (quad, pentagon) = ([0u32, 1, 4, 5], [1u32, 2, 3, 6, 4]);
    let list = |p: &[u32], base: u32| {
        p.iter()
            .map(|v| (v + base).to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let obj = format!(
        "v {}\nf {}\nf {}\n",
        vertices.join("\nv "),
        list(&quad, 1),
        list(&pentagon, 1)
    );
    let off = format!(
        "OFF\n7 2 0\n{}\n4 {}\n5 {}\n",
        vertices.join("\n"),
        list(&quad, 0),
        list(&pentagon, 0)
    );
    let ply = format!(
        "ply\nformat ascii 1.0\nelement vertex 7\nproperty double x\nproperty double y\n\
         property double z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n\
         {}\n4 {}\n5 {}\n",
        vertices.join("\n"),
        list(&quad, 0),
        list(&pentagon, 0)
    );
    let expected = vec![[0, 4], [1, 3], [1, 6]];
    for (name, text) in [("m.obj", obj), ("m.off", off), ("m.ply", ply)] {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let ((_, faces), diagonals) = io::read_mesh_with_diagonals(&path).unwrap();
        assert_eq!(faces.len(), 5, "{name}");
        assert_eq!(diagonals, expected, "{name}");
    }
    let stl = dir.join("m.stl");
    io::write_mesh(
        &stl,
        &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[[0, 1, 2]],
    )
    .unwrap();
    assert!(io::read_mesh_with_diagonals(&stl).unwrap().1.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}
