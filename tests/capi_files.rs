//! Mesh files through the C ABI: `vsr_mesh_read` in every format with supports from a JSON
//! sidecar or from ids, welding and its id map, `vsr_result_write` keeping every bit, and
//! hostile paths and files (status, a message naming the argument, untouched outputs).

mod capi_support;
mod common;

use std::ffi::{c_char, CString};
use std::fs;
use std::path::{Path, PathBuf};
use std::ptr::{null, null_mut};

use capi_support::{assert_failed, assert_ok, last_error, settings};
use voussoir::capi::*;
use voussoir::io;
use VsrStatus as S;

/// A square of 4 triangles around a raised centre vertex, its corners anchored.
const POSITIONS: [[f64; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.5, 0.5, 0.3],
];
const TRIANGLES: [[u32; 3]; 4] = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];

struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> TempDir {
        let dir =
            std::env::temp_dir().join(format!("voussoir-capi-files-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
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

fn c(path: &Path) -> CString {
    CString::new(path.to_str().unwrap()).unwrap()
}

fn sentinel<T>() -> *mut T {
    0xdead_bee8usize as *mut T
}

/// `vsr_mesh_read` of `path` with ids or a sidecar; the status, handle and merged count.
fn read(
    path: &Path,
    supports: Option<&Path>,
    ids: &[u32],
    weld: f64,
) -> (VsrStatus, *mut VsrMesh, usize) {
    let path = c(path);
    let supports = supports.map(c);
    let mut out = sentinel();
    let mut merged = usize::MAX;
    let s = unsafe {
        vsr_mesh_read(
            path.as_ptr(),
            supports.as_ref().map_or(null(), |s| s.as_ptr()),
            if ids.is_empty() { null() } else { ids.as_ptr() },
            ids.len(),
            weld,
            1e-4,
            &mut merged,
            &mut out,
        )
    };
    (s, out, merged)
}

fn welded_ids(mesh: *const VsrMesh) -> Vec<u32> {
    let mut needed = 0;
    assert_ok(unsafe { vsr_mesh_welded_ids(mesh, null_mut(), 0, &mut needed) });
    let mut ids = vec![u32::MAX; needed];
    assert_ok(unsafe { vsr_mesh_welded_ids(mesh, ids.as_mut_ptr(), ids.len(), &mut needed) });
    ids
}

fn positions(result: *const VsrResult) -> Vec<[f64; 3]> {
    let mut needed = 0;
    assert_ok(unsafe { vsr_result_positions(result, null_mut(), 0, &mut needed) });
    let mut flat = vec![0.0; needed];
    assert_ok(unsafe { vsr_result_positions(result, flat.as_mut_ptr(), needed, &mut needed) });
    flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

fn form_find(mesh: *const VsrMesh) -> *mut VsrResult {
    let s = settings();
    let mut result = null_mut();
    assert_ok(unsafe { vsr_form_find(mesh, s, &mut result) });
    unsafe { vsr_settings_destroy(s) };
    result
}

fn bits(p: &[[f64; 3]]) -> Vec<[u64; 3]> {
    p.iter().map(|p| p.map(f64::to_bits)).collect()
}

#[test]
fn every_format_reads_form_finds_and_writes_back_every_bit() {
    let dir = TempDir::new("formats");
    let sidecar = dir.path("s.json");
    fs::write(&sidecar, "{\"anchored\": [0, 1, 2, 3]}").unwrap();
    for name in ["m.obj", "m.off", "m.ply"] {
        let file = dir.path(name);
        io::write_mesh(&file, &POSITIONS, &TRIANGLES).unwrap();
        let (s, mesh, merged) = read(&file, Some(&sidecar), &[], 1e-9);
        assert_ok(s);
        assert_eq!(merged, 0);
        assert_eq!(welded_ids(mesh), vec![0, 1, 2, 3, 4]);
        let result = form_find(mesh);
        for out in ["r.obj", "r.off", "r.ply"] {
            let out = dir.path(out);
            assert_ok(unsafe { vsr_result_write(result, mesh, c(&out).as_ptr()) });
            let (p, f) = io::read_mesh(&out).unwrap();
            assert_eq!(
                bits(&p),
                bits(&positions(result)),
                "{name} -> {}",
                out.display()
            );
            assert_eq!(f, TRIANGLES.to_vec());
        }
        unsafe {
            vsr_result_destroy(result);
            vsr_mesh_destroy(mesh);
        }
    }
}

/// A latitude-longitude dome in quads: each ring is split along the same diagonal, which no
/// network with every q >= q_min > 0 balances; q_min does not bind the diagonals of a file's
/// polygons, so it form-finds with the default settings.
#[test]
fn a_quad_dome_read_from_a_file_form_finds_with_defaults() {
    let (obj, rim) = common::quad_dome_obj(4, 16);
    let dir = TempDir::new("quads");
    let file = dir.path("dome.obj");
    fs::write(&file, obj).unwrap();
    let (s, mesh, _) = read(&file, None, &rim, 1e-9);
    assert_ok(s);
    let result = form_find(mesh);
    let (mut termination, mut iterations) = (VsrTermination::Cancelled, 0);
    assert_ok(unsafe { vsr_result_termination(result, &mut termination, &mut iterations) });
    assert_eq!(termination, VsrTermination::Converged);
    unsafe {
        vsr_result_destroy(result);
        vsr_mesh_destroy(mesh);
    }
}

#[test]
fn stl_is_welded_and_ids_refer_to_its_own_vertices() {
    let dir = TempDir::new("stl");
    let file = dir.path("m.stl");
    io::write_mesh(&file, &POSITIONS, &TRIANGLES).unwrap();
    // The corners as the STL numbers them (corner k of triangle t is 3t + k): 0, 1, 4, 7 are
    // vertices 0, 1, 2, 3, and 3 is vertex 1 again, anchored once.
    let (s, mesh, merged) = read(&file, None, &[0, 1, 4, 7, 3], 1e-9);
    assert_ok(s);
    assert_eq!(merged, 12 - 5);
    assert_eq!(welded_ids(mesh), vec![0, 1, 2, 1, 3, 2, 3, 4, 2, 4, 0, 2]);
    let result = form_find(mesh);
    let out = dir.path("r.stl");
    assert_ok(unsafe { vsr_result_write(result, mesh, c(&out).as_ptr()) });
    assert_eq!(fs::metadata(&out).unwrap().len(), 84 + 4 * 50);
    unsafe {
        vsr_result_destroy(result);
        vsr_mesh_destroy(mesh);
    }
}

#[test]
fn a_clockwise_file_is_written_back_in_its_own_orientation() {
    let dir = TempDir::new("clockwise");
    let clockwise: Vec<[u32; 3]> = TRIANGLES.iter().map(|&[a, b, c]| [a, c, b]).collect();
    let file = dir.path("cw.off");
    io::write_mesh(&file, &POSITIONS, &clockwise).unwrap();
    let (s, mesh, _) = read(&file, None, &[0, 1, 2, 3], 0.0);
    assert_ok(s);
    let result = form_find(mesh);
    let out = dir.path("r.off");
    assert_ok(unsafe { vsr_result_write(result, mesh, c(&out).as_ptr()) });
    assert_eq!(io::read_mesh(&out).unwrap().1, clockwise);
    unsafe {
        vsr_result_destroy(result);
        vsr_mesh_destroy(mesh);
    }
}

#[test]
fn mesh_read_rejects_hostile_paths_and_files() {
    let dir = TempDir::new("hostile");
    let good = dir.path("m.off");
    io::write_mesh(&good, &POSITIONS, &TRIANGLES).unwrap();
    let ids = [0u32, 1, 2, 3];
    let mut out = sentinel();
    let mut merged = 77usize;
    let merged_ptr: *mut usize = &mut merged;
    let path = c(&good);
    let call = |p: *const c_char, sp: *const c_char, a: *const u32, n: usize, w: f64, out| unsafe {
        vsr_mesh_read(p, sp, a, n, w, 1e-4, merged_ptr, out)
    };
    assert_failed(
        call(null(), null(), ids.as_ptr(), 4, 0.0, &mut out),
        S::NullPointer,
        "path",
    );
    assert_failed(
        call(path.as_ptr(), null(), ids.as_ptr(), 4, 0.0, null_mut()),
        S::NullPointer,
        "out",
    );
    assert_failed(
        call(path.as_ptr(), null(), null(), 4, 0.0, &mut out),
        S::NullPointer,
        "anchored",
    );
    let bad_utf8 = CString::new(vec![0xff, b'.', b'o', b'f', b'f']).unwrap();
    assert_failed(
        call(bad_utf8.as_ptr(), null(), ids.as_ptr(), 4, 0.0, &mut out),
        S::InvalidArgument,
        "path",
    );
    for w in [f64::NAN, -1.0, f64::INFINITY] {
        assert_failed(
            call(path.as_ptr(), null(), ids.as_ptr(), 4, w, &mut out),
            S::InvalidArgument,
            "weld_tolerance",
        );
    }
    let sidecar = c(&dir.path("s.json"));
    assert_failed(
        call(
            path.as_ptr(),
            sidecar.as_ptr(),
            ids.as_ptr(),
            4,
            0.0,
            &mut out,
        ),
        S::InvalidArgument,
        "anchored",
    );
    let missing = c(&dir.path("s.json"));
    assert_failed(
        call(path.as_ptr(), missing.as_ptr(), null(), 0, 0.0, &mut out),
        S::InvalidArgument,
        "supports_path",
    );
    assert!(last_error().contains("s.json"), "{}", last_error());
    assert_failed(
        call(path.as_ptr(), null(), [0u32, 9].as_ptr(), 2, 0.0, &mut out),
        S::IndexOutOfRange,
        "anchored",
    );
    assert_failed(
        call(path.as_ptr(), null(), null(), 0, 0.0, &mut out),
        S::NoSupport,
        "anchored",
    );
    // Issue 48: a PLY count beyond 64 bits returned VSR_STATUS_PANIC.
    let huge_count = b"ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let long_face = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2 3\n";
    let bad_files: [(&str, &[u8], &str); 8] = [
        (
            "h.ply",
            huge_count,
            "h.ply:3: bad header: element `vertex`: count `99999999999999999999999` is larger",
        ),
        (
            "f.ply",
            long_face,
            "f.ply:14: face 0: 1 more number than its properties take",
        ),
        ("missing.obj", b"", "missing.obj"),
        ("m.xyz", b"OFF", "unknown extension"),
        ("t.off", b"OFF\n5 4 0\n0 0 0\n", "t.off:3: the file ends before vertex 1"),
        ("i.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n", "i.off:6: face 0 refers to vertex 5"),
        ("g.stl", b"\x01\x02", "neither ASCII STL"),
        ("n.ply", b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 1e999\n", "vertex 0: `z` is inf"),
    ];
    for (name, bytes, message) in bad_files {
        let file = dir.path(name);
        if name != "missing.obj" {
            fs::write(&file, bytes).unwrap();
        }
        let p = c(&file);
        assert_failed(
            call(p.as_ptr(), null(), ids.as_ptr(), 4, 0.0, &mut out),
            S::InvalidArgument,
            "path",
        );
        assert!(last_error().contains(message), "{name}: {}", last_error());
    }
    assert_eq!(out, sentinel());
    assert_eq!(merged, 77);
}

#[test]
fn result_write_rejects_hostile_arguments_and_writes_nothing() {
    let dir = TempDir::new("write");
    let file = dir.path("m.obj");
    io::write_mesh(&file, &POSITIONS, &TRIANGLES).unwrap();
    let (s, mesh, _) = read(&file, None, &[0, 1, 2, 3], 0.0);
    assert_ok(s);
    let result = form_find(mesh);
    let out = c(&dir.path("r.off"));
    unsafe {
        assert_failed(
            vsr_result_write(null(), mesh, out.as_ptr()),
            S::NullPointer,
            "result",
        );
        assert_failed(
            vsr_result_write(result, null(), out.as_ptr()),
            S::NullPointer,
            "mesh",
        );
        assert_failed(
            vsr_result_write(result, mesh, null()),
            S::NullPointer,
            "path",
        );
        let unknown = c(&dir.path("r.3mf"));
        assert_failed(
            vsr_result_write(result, mesh, unknown.as_ptr()),
            S::InvalidArgument,
            "path",
        );
        let no_folder = c(&dir.path("no/such/folder/r.off"));
        assert_failed(
            vsr_result_write(result, mesh, no_folder.as_ptr()),
            S::InvalidArgument,
            "path",
        );
        // A result of another mesh.
        let other = dir.path("big.obj");
        let mut more = POSITIONS.to_vec();
        more.push([2.0, 2.0, 0.0]);
        io::write_mesh(&other, &more, &TRIANGLES).unwrap();
        let (s, big, _) = read(&other, None, &[0, 1, 2, 3], 0.0);
        assert_ok(s);
        assert_failed(
            vsr_result_write(result, big, out.as_ptr()),
            S::InvalidArgument,
            "mesh",
        );
        vsr_mesh_destroy(big);
        // Issue 48: a device or FIFO behind the path was replaced by a regular file.
        #[cfg(unix)]
        for (name, target) in [("full.off", "/dev/full"), ("null.off", "/dev/null")] {
            let link = dir.path(name);
            std::os::unix::fs::symlink(target, &link).unwrap();
            let p = c(&link);
            assert_failed(
                vsr_result_write(result, mesh, p.as_ptr()),
                S::InvalidArgument,
                "path",
            );
            assert!(
                last_error().contains("character device"),
                "{}",
                last_error()
            );
            fs::remove_file(&link).unwrap();
            assert!(!fs::metadata(target).unwrap().is_file());
        }
    }
    assert_eq!(
        fs::read_dir(&dir.0).unwrap().count(),
        2,
        "only the two inputs"
    );
    unsafe {
        vsr_result_destroy(result);
        vsr_mesh_destroy(mesh);
    }
}

/// The square with a sliver: vertex 5 a hair past the middle of the diagonal (0, 2), in the
/// face (0, 2, 5) whose plan area is about -1e-11 of the median.
fn sliver_square(dir: &TempDir) -> PathBuf {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.75, 0.25, 0.3],
        [0.5 + 1e-11, 0.5 - 1e-11, 0.3],
    ];
    let faces = vec![
        [0, 1, 4],
        [1, 2, 4],
        [4, 2, 0],
        [0, 5, 3],
        [5, 2, 3],
        [0, 2, 5],
    ];
    let path = dir.path("sliver.off");
    io::write_mesh(&path, &positions, &faces).unwrap();
    path
}

fn rows(
    mesh: *const VsrMesh,
    get: unsafe extern "C" fn(*const VsrMesh, *mut u32, usize, *mut usize) -> VsrStatus,
) -> Vec<u32> {
    let mut needed = usize::MAX;
    assert_ok(unsafe { get(mesh, null_mut(), 0, &mut needed) });
    let mut out = vec![u32::MAX; needed];
    assert_ok(unsafe { get(mesh, out.as_mut_ptr(), out.len(), &mut needed) });
    out
}

#[test]
fn plan_slivers_are_repaired_and_listed_unless_the_tolerance_is_zero() {
    let dir = TempDir::new("repair");
    let path = c(&sliver_square(&dir));
    let ids = [0u32, 1, 2, 3];
    let mut out = sentinel();
    let strict = unsafe {
        vsr_mesh_read(
            path.as_ptr(),
            null(),
            ids.as_ptr(),
            4,
            0.0,
            0.0,
            null_mut(),
            &mut out,
        )
    };
    assert_failed(strict, S::InvalidPlan, "positions");
    assert!(last_error().contains('5'), "{}", last_error());
    assert_eq!(out, sentinel());
    let status = unsafe {
        vsr_mesh_read(
            path.as_ptr(),
            null(),
            ids.as_ptr(),
            4,
            0.0,
            1e-4,
            null_mut(),
            &mut out,
        )
    };
    assert_ok(status);
    // Faces 5 (the sliver) and 2 shared the diagonal (0, 2); they now share (5, 4).
    assert_eq!(rows(out, vsr_mesh_plan_flips), vec![5, 2, 0, 2, 5, 4]);
    assert_eq!(rows(out, vsr_mesh_plan_nudges), Vec::<u32>::new());
    let result = form_find(out);
    unsafe {
        vsr_result_destroy(result);
        vsr_mesh_destroy(out);
    }
    // A mesh from arrays has no repairs.
    let mesh = capi_support::Dome::new(2, 6).create();
    assert!(rows(mesh, vsr_mesh_plan_flips).is_empty());
    assert_failed(
        unsafe { vsr_mesh_plan_nudges(null(), null_mut(), 0, null_mut()) },
        S::NullPointer,
        "mesh",
    );
    unsafe { vsr_mesh_destroy(mesh) };
}

/// Every directed edge of `faces` once, and its reverse once.
fn is_watertight(faces: &[[u32; 3]]) -> bool {
    let mut directed = std::collections::HashMap::new();
    for f in faces {
        for k in 0..3 {
            *directed.entry((f[k], f[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    directed
        .iter()
        .all(|(&(a, b), &n)| n == 1 && directed.get(&(b, a)) == Some(&1))
}

#[test]
fn result_write_solid_writes_a_closed_solid_in_every_format() {
    let dir = TempDir::new("solid");
    let file = dir.path("m.obj");
    io::write_mesh(&file, &POSITIONS, &TRIANGLES).unwrap();
    let (s, mesh, _) = read(&file, None, &[0, 1, 2, 3], 0.0);
    assert_ok(s);
    let result = form_find(mesh);
    let shape = positions(result);
    for name in ["s.off", "s.obj", "s.ply", "s.stl", "s.3mf"] {
        let out = c(&dir.path(name));
        assert_ok(unsafe { vsr_result_write_solid(result, mesh, 0.02, out.as_ptr()) });
        assert!(dir.path(name).is_file(), "{name}");
        if name == "s.3mf" {
            continue;
        }
        let (p, f) = io::read_mesh(&dir.path(name)).unwrap();
        let w = io::weld(&p, &f, 1e-9).unwrap();
        assert_eq!(w.positions.len(), 2 * POSITIONS.len(), "{name}");
        assert!(is_watertight(&w.faces), "{name}");
        let volume = voussoir::signed_volume(&w.positions, &w.faces);
        let area: f64 = TRIANGLES
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| shape[v as usize]);
                let (u, v) = (
                    [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                    [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
                );
                let n = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() / 2.0
            })
            .sum();
        assert!(
            (volume / (area * 0.02) - 1.0).abs() < 0.05,
            "{name}: {volume}"
        );
    }
    // Density 1 everywhere and unit weight 50: thickness 0.02 again.
    let out = c(&dir.path("d.off"));
    assert_ok(unsafe { vsr_result_write_solid_from_density(result, mesh, 50.0, out.as_ptr()) });
    let from_density = io::read_mesh(&dir.path("d.off")).unwrap();
    assert_eq!(from_density, io::read_mesh(&dir.path("s.off")).unwrap());
    unsafe {
        vsr_result_destroy(result);
        vsr_mesh_destroy(mesh);
    }
}

#[test]
fn result_write_solid_rejects_hostile_arguments_and_writes_nothing() {
    let dir = TempDir::new("solid-bad");
    let file = dir.path("m.obj");
    io::write_mesh(&file, &POSITIONS, &TRIANGLES).unwrap();
    let (s, mesh, _) = read(&file, None, &[0, 1, 2, 3], 0.0);
    assert_ok(s);
    let result = form_find(mesh);
    let out = c(&dir.path("s.stl"));
    unsafe {
        assert_failed(
            vsr_result_write_solid(null(), mesh, 0.1, out.as_ptr()),
            S::NullPointer,
            "result",
        );
        assert_failed(
            vsr_result_write_solid(result, null(), 0.1, out.as_ptr()),
            S::NullPointer,
            "mesh",
        );
        assert_failed(
            vsr_result_write_solid(result, mesh, 0.1, null()),
            S::NullPointer,
            "path",
        );
        for t in [0.0, -1.0, f64::NAN, f64::INFINITY, 50.0] {
            assert_failed(
                vsr_result_write_solid(result, mesh, t, out.as_ptr()),
                S::InvalidArgument,
                "thickness",
            );
        }
        assert!(last_error().contains("turns over"), "{}", last_error());
        for w in [0.0, -2.0, f64::NAN] {
            assert_failed(
                vsr_result_write_solid_from_density(result, mesh, w, out.as_ptr()),
                S::InvalidArgument,
                "unit_weight",
            );
        }
        let unknown = c(&dir.path("s.xyz"));
        assert_failed(
            vsr_result_write_solid(result, mesh, 0.1, unknown.as_ptr()),
            S::InvalidArgument,
            "path",
        );
        let surface = c(&dir.path("s.3mf"));
        assert_failed(
            vsr_result_write(result, mesh, surface.as_ptr()),
            S::InvalidArgument,
            "path",
        );
    }
    assert_eq!(fs::read_dir(&dir.0).unwrap().count(), 1, "only the input");
    unsafe {
        vsr_result_destroy(result);
        vsr_mesh_destroy(mesh);
    }
}
