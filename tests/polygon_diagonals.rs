//! Polygon diagonals on a mesh built from arrays: `vsr_mesh_set_polygon_diagonals` (and
//! `Problem::with_polygon_diagonals`) mark what `vsr_mesh_read` marks for a file's polygons,
//! so the same quad dome solves the same from arrays as from its OBJ file; hostile input is
//! refused naming the pair, and leaves the marks as they were.

mod capi_support;

use std::ffi::CString;
use std::ptr::{null, null_mut};

use capi_support::{assert_failed, assert_ok, doubles, settings};
use voussoir::capi::*;
use voussoir::io::{read_model, ReadOptions, Supports};
use voussoir::{analyse, Problem, StressSettings};

const RINGS: usize = 4;
const SECTORS: usize = 16;

/// A latitude-longitude dome in quads around a centre fan, as OBJ (1-based ids), with its
/// rim's 0-based vertex ids. Each ring of quads is split along the same diagonal when read:
/// no network with every q >= q_min > 0 balances it unless the diagonals are free.
fn quad_dome() -> (String, Vec<u32>) {
    let mut obj = String::from("v 0 0 0.6\n");
    for r in 1..=RINGS {
        for s in 0..SECTORS {
            let a = std::f64::consts::TAU * s as f64 / SECTORS as f64;
            let rr = r as f64 / RINGS as f64;
            obj += &format!("v {} {} {}\n", rr * a.cos(), rr * a.sin(), 0.6 * (1.0 - rr));
        }
    }
    let id = |r: usize, s: usize| 2 + (r - 1) * SECTORS + s % SECTORS;
    for s in 0..SECTORS {
        obj += &format!("f 1 {} {}\n", id(1, s), id(1, s + 1));
    }
    for r in 1..RINGS {
        for s in 0..SECTORS {
            let q = [id(r, s), id(r + 1, s), id(r + 1, s + 1), id(r, s + 1)];
            obj += &format!("f {} {} {} {}\n", q[0], q[1], q[2], q[3]);
        }
    }
    let rim = (0..SECTORS).map(|s| id(RINGS, s) as u32 - 1).collect();
    (obj, rim)
}

/// The dome read from its file (named after `test`: tests run in parallel) by the library's
/// read path.
fn dome_model(test: &str) -> voussoir::io::Model {
    let (obj, rim) = quad_dome();
    let name = format!("voussoir-diagonals-{}-{test}.obj", std::process::id());
    let path = std::env::temp_dir().join(name);
    std::fs::write(&path, obj).unwrap();
    let model = read_model(&path, &ReadOptions::new(Supports::Ids(rim))).unwrap();
    std::fs::remove_file(&path).unwrap();
    model
}

/// The dome's arrays as `vsr_mesh_create` takes them.
fn create(model: &voussoir::io::Model) -> *mut VsrMesh {
    let m = &model.problem.mesh;
    let positions: Vec<f64> = m.positions().iter().flatten().copied().collect();
    let triangles: Vec<u32> = m.input_faces().into_iter().flatten().collect();
    let anchored: Vec<u32> = (0..m.n_vertices() as u32)
        .filter(|&v| m.anchored()[v as usize])
        .collect();
    let mut mesh = null_mut();
    assert_ok(unsafe {
        vsr_mesh_create(
            positions.as_ptr(),
            m.n_vertices(),
            triangles.as_ptr(),
            m.n_faces(),
            anchored.as_ptr(),
            anchored.len(),
            &mut mesh,
        )
    });
    mesh
}

fn marked(mesh: *const VsrMesh) -> Vec<u32> {
    let mut n = 0;
    assert_ok(unsafe { vsr_mesh_polygon_diagonals(mesh, null_mut(), 0, &mut n) });
    let mut out = vec![0; n];
    assert_ok(unsafe { vsr_mesh_polygon_diagonals(mesh, out.as_mut_ptr(), n, &mut n) });
    out
}

fn force_densities(mesh: *const VsrMesh) -> Vec<f64> {
    let s = settings();
    let mut result = null_mut();
    assert_ok(unsafe { vsr_analyse(mesh, s, &mut result) });
    let q = doubles(result, vsr_result_force_densities);
    unsafe {
        vsr_result_destroy(result);
        vsr_settings_destroy(s);
    }
    q
}

#[test]
fn arrays_with_marked_diagonals_solve_as_the_file_does() {
    let model = dome_model("arrays");
    assert_eq!(model.diagonals.len(), (RINGS - 1) * SECTORS);
    let from_file = analyse(&model.problem, &StressSettings::default()).unwrap();
    let bits = |q: &[f64]| q.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    // Rust: a problem of the same mesh with the same diagonals marked.
    let rust = Problem::new(model.problem.mesh.clone())
        .with_polygon_diagonals(&model.diagonals)
        .unwrap();
    assert_eq!(rust.polygon_diagonal, model.problem.polygon_diagonal);
    // C: arrays, then the diagonals (in either order of their ends).
    let mesh = create(&model);
    let unmarked = force_densities(mesh);
    let pairs: Vec<u32> = model.diagonals.iter().flat_map(|&[a, b]| [b, a]).collect();
    let n = model.diagonals.len();
    assert_ok(unsafe { vsr_mesh_set_polygon_diagonals(mesh, pairs.as_ptr(), n) });
    let expected: Vec<u32> = model.problem.polygon_diagonals().concat();
    assert_eq!(marked(mesh), expected);
    let q = force_densities(mesh);
    assert_eq!(bits(&q), bits(&from_file.force_densities));
    // Unmarked, q_min binds the diagonals: another answer.
    assert_ne!(bits(&unmarked), bits(&q));
    // The file's diagonals, read back through the C API.
    let (obj, rim) = quad_dome();
    let path = std::env::temp_dir().join(format!("voussoir-diag-c-{}.obj", std::process::id()));
    std::fs::write(&path, obj).unwrap();
    let c_path = CString::new(path.to_str().unwrap()).unwrap();
    let mut read = null_mut();
    assert_ok(unsafe {
        vsr_mesh_read(
            c_path.as_ptr(),
            null(),
            rim.as_ptr(),
            rim.len(),
            1e-9,
            1e-4,
            null_mut(),
            &mut read,
        )
    });
    std::fs::remove_file(&path).unwrap();
    assert_eq!(marked(read), expected);
    unsafe {
        vsr_mesh_destroy(read);
        vsr_mesh_destroy(mesh);
    }
}

#[test]
fn hostile_diagonals_are_refused_and_change_nothing() {
    let model = dome_model("hostile");
    let mesh = create(&model);
    let first = model.diagonals[0];
    assert_ok(unsafe { vsr_mesh_set_polygon_diagonals(mesh, first.as_ptr(), 1) });
    let before = marked(mesh);
    assert_eq!(before, first.to_vec());
    let set =
        |ids: &[u32], n: usize| unsafe { vsr_mesh_set_polygon_diagonals(mesh, ids.as_ptr(), n) };
    assert_failed(
        unsafe { vsr_mesh_set_polygon_diagonals(null_mut(), first.as_ptr(), 1) },
        VsrStatus::NullPointer,
        "mesh",
    );
    assert_failed(
        unsafe { vsr_mesh_set_polygon_diagonals(mesh, null(), 1) },
        VsrStatus::NullPointer,
        "diagonals",
    );
    assert_failed(
        set(&first, usize::MAX),
        VsrStatus::LengthOverflow,
        "diagonals",
    );
    let n = model.problem.mesh.n_vertices() as u32;
    assert_failed(
        set(&[1, 2, 0, n], 2),
        VsrStatus::IndexOutOfRange,
        "diagonals",
    );
    assert!(capi_support::last_error().contains(&format!("pair 1 has vertex {n}")));
    // A rim edge is a boundary edge, the centre and the rim share no edge.
    let (rim_a, rim_b) = (n - 1, n - SECTORS as u32);
    for pair in [[rim_a, rim_b], [0, rim_a]] {
        assert_failed(set(&pair, 1), VsrStatus::InvalidArgument, "diagonals");
        assert!(
            capi_support::last_error().contains("pair 0"),
            "{}",
            capi_support::last_error()
        );
    }
    assert_eq!(marked(mesh), before);
    // A count of 0 clears them, whatever the pointer.
    assert_ok(unsafe { vsr_mesh_set_polygon_diagonals(mesh, null(), 0) });
    assert!(marked(mesh).is_empty());
    assert_failed(
        unsafe { vsr_mesh_polygon_diagonals(null(), null_mut(), 0, null_mut()) },
        VsrStatus::NullPointer,
        "mesh",
    );
    unsafe { vsr_mesh_destroy(mesh) };
    // Rust: the same refusals, naming the pair.
    let p = Problem::new(model.problem.mesh.clone());
    for pair in [[0, n], [rim_a, rim_b]] {
        match p.clone().with_polygon_diagonals(&[first, pair]) {
            Err(voussoir::Error::InvalidArgument { name, reason }) => {
                assert_eq!(name, "diagonals");
                assert!(reason.starts_with("pair 1 "), "{reason}");
            }
            other => panic!("{other:?}"),
        }
    }
}
