//! Hostile input through the C ABI: every case gets the right status, a one-line message that
//! names the argument at fault, and leaves its outputs untouched.

mod capi_support;

use capi_support::{assert_failed, assert_ok, doubles, last_error, settings, Dome};
use std::ffi::CStr;
use std::ptr::{null, null_mut};
use voussoir::capi::*;
use VsrStatus as S;

/// A recognisable non-NULL pointer that must never be written over or dereferenced.
fn sentinel<T>() -> *mut T {
    0xdead_bee8usize as *mut T
}

/// Calls `vsr_mesh_create` with the dome's arrays, letting `f` spoil them first.
fn create_with(
    f: impl FnOnce(&mut Vec<f64>, &mut Vec<u32>, &mut Vec<u32>),
) -> (VsrStatus, *mut VsrMesh) {
    let mut d = Dome::new(3, 8);
    f(&mut d.positions, &mut d.triangles, &mut d.anchored);
    let mut out = sentinel();
    let s = unsafe {
        vsr_mesh_create(
            d.positions.as_ptr(),
            d.positions.len() / 3,
            d.triangles.as_ptr(),
            d.triangles.len() / 3,
            d.anchored.as_ptr(),
            d.anchored.len(),
            &mut out,
        )
    };
    (s, out)
}

#[test]
fn mesh_create_rejects_null_pointers() {
    let d = Dome::new(2, 6);
    let (nv, nt, na) = (d.n_vertices(), d.n_triangles(), d.anchored.len());
    let (p, t, a) = (
        d.positions.as_ptr(),
        d.triangles.as_ptr(),
        d.anchored.as_ptr(),
    );
    let cases: [(&str, *const f64, *const u32, *const u32); 3] = [
        ("positions", null(), t, a),
        ("triangles", p, null(), a),
        ("anchored", p, t, null()),
    ];
    for (name, p, t, a) in cases {
        let mut out = sentinel();
        let s = unsafe { vsr_mesh_create(p, nv, t, nt, a, na, &mut out) };
        assert_failed(s, S::NullPointer, name);
        assert_eq!(out, sentinel());
    }
    let s = unsafe { vsr_mesh_create(p, nv, t, nt, a, na, null_mut()) };
    assert_failed(s, S::NullPointer, "out");
}

#[test]
fn mesh_create_rejects_overflowing_and_huge_lengths() {
    let d = Dome::new(2, 6);
    let (p, t, a) = (
        d.positions.as_ptr(),
        d.triangles.as_ptr(),
        d.anchored.as_ptr(),
    );
    let (nv, nt, na) = (d.n_vertices(), d.n_triangles(), d.anchored.len());
    let cases = [
        ("positions", usize::MAX, nt, na),            // n * 3 overflows
        ("positions", usize::MAX / 3, nt, na),        // n * 3 * 8 overflows
        ("positions", u32::MAX as usize + 1, nt, na), // more vertices than ids
        ("triangles", nv, usize::MAX / 2, na),
        ("triangles", nv, (u32::MAX / 6) as usize + 1, na),
        ("anchored", nv, nt, usize::MAX),
        ("anchored", nv, nt, usize::MAX / 4 + 1),
    ];
    for (name, nv, nt, na) in cases {
        let mut out = sentinel();
        // The arrays are far shorter than the lengths claim: they must never be read.
        let s = unsafe { vsr_mesh_create(p, nv, t, nt, a, na, &mut out) };
        assert_failed(s, S::LengthOverflow, name);
        assert_eq!(out, sentinel());
    }
}

#[test]
fn mesh_create_rejects_empty_input() {
    let mut out = sentinel();
    let s = unsafe { vsr_mesh_create(null(), 0, null(), 0, null(), 0, &mut out) };
    assert_failed(s, S::EmptyMesh, "positions");
    assert_eq!(out, sentinel());
    let d = Dome::new(2, 6);
    let s = unsafe {
        vsr_mesh_create(
            d.positions.as_ptr(),
            d.n_vertices(),
            null(),
            0,
            null(),
            0,
            &mut out,
        )
    };
    assert_failed(s, S::EmptyMesh, "triangles");
    assert_eq!(out, sentinel());
}

#[test]
fn mesh_create_rejects_bad_ids_values_and_topology() {
    type Spoil = fn(&mut Vec<f64>, &mut Vec<u32>, &mut Vec<u32>);
    let cases: [(Spoil, VsrStatus, &str, &str); 8] = [
        (
            |_, t, _| t[7] = 10_000,
            S::IndexOutOfRange,
            "triangles",
            "face 2",
        ),
        (
            |_, _, a| a[0] = 10_000,
            S::IndexOutOfRange,
            "anchored",
            "10000",
        ),
        (
            |_, _, a| a[1] = a[0],
            S::InvalidArgument,
            "anchored",
            "twice",
        ),
        (
            |p, _, _| p[3 * 5 + 2] = f64::NAN,
            S::NonFinite,
            "positions",
            "vertex 5",
        ),
        (
            |p, _, _| p[3 * 4] = f64::INFINITY,
            S::NonFinite,
            "positions",
            "vertex 4",
        ),
        (
            |_, t, _| {
                let f: Vec<u32> = t[..3].to_vec();
                t.extend(f);
            },
            S::InvalidTopology,
            "triangles",
            "face",
        ),
        (
            |_, t, _| t[1] = t[0],
            S::InvalidTopology,
            "triangles",
            "face 0",
        ),
        (|_, _, a| a.clear(), S::NoSupport, "anchored", "anchored"),
    ];
    for (spoil, status, name, detail) in cases {
        let (s, out) = create_with(spoil);
        assert_failed(s, status, name);
        assert!(last_error().contains(detail), "{}", last_error());
        assert_eq!(out, sentinel());
    }
    // A flat plan folded over itself.
    let (s, out) = create_with(|p, _, _| {
        p[3] = -p[3];
        p[4] = -p[4];
        p[3 * 3] = 5.0;
    });
    assert!(
        matches!(s, S::InvalidPlan | S::InvalidTopology),
        "{s:?}: {}",
        last_error()
    );
    assert!(!last_error().is_empty());
    assert_eq!(out, sentinel());
}

#[test]
fn mesh_create_rejects_plans_overlapping_away_from_shared_vertices() {
    // Two unit squares, the second shifted by (0.5, 0.5): two components stacked in plan.
    let positions = [
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0, //
        0.5, 0.5, 1.0, 1.5, 0.5, 1.0, 1.5, 1.5, 1.0, 0.5, 1.5, 1.0,
    ];
    let triangles = [0u32, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7];
    // A strip between radii 1 and 2 winding 1.6 turns, rising: one component, every vertex
    // on the boundary, no face flipped.
    let mut strip = Vec::new();
    for s in 0..=16 {
        let angle = std::f64::consts::TAU * f64::from(s) / 10.0;
        for r in [1.0, 2.0] {
            strip.extend([r * angle.cos(), r * angle.sin(), 0.1 * f64::from(s)]);
        }
    }
    let strip_triangles: Vec<u32> = (0..16u32)
        .flat_map(|s| [2 * s, 2 * s + 1, 2 * s + 3, 2 * s, 2 * s + 3, 2 * s + 2])
        .collect();
    type Case<'a> = (&'a [f64], &'a [u32], &'a [u32], &'a str);
    let cases: [Case; 2] = [
        (&positions, &triangles, &[0, 4], "faces 0 and 2 overlap"),
        (&strip, &strip_triangles, &[0, 1], "faces 0 and 20 overlap"),
    ];
    for (p, t, a, detail) in cases {
        let mut out = sentinel();
        let s = unsafe {
            vsr_mesh_create(
                p.as_ptr(),
                p.len() / 3,
                t.as_ptr(),
                t.len() / 3,
                a.as_ptr(),
                a.len(),
                &mut out,
            )
        };
        assert_failed(s, S::InvalidPlan, "positions");
        assert!(last_error().contains(detail), "{}", last_error());
        assert_eq!(out, sentinel());
    }
}

#[test]
fn destroy_null_is_a_no_op_and_keeps_the_last_error() {
    let mut out = sentinel();
    let s = unsafe { vsr_mesh_create(null(), 0, null(), 0, null(), 0, &mut out) };
    assert_eq!(s, S::EmptyMesh);
    let message = last_error();
    unsafe {
        vsr_mesh_destroy(null_mut());
        vsr_settings_destroy(null_mut());
        vsr_result_destroy(null_mut());
    }
    assert_eq!(last_error(), message);
    assert_eq!(out, sentinel());
}

/// Loads seen by a solve: the observable state of a mesh's loading.
fn loads_of(mesh: *const VsrMesh) -> (Vec<f64>, Vec<f64>) {
    let s = settings();
    unsafe { vsr_settings_set_tau_mode(s, VsrTauMode::Prescribed as u32) };
    let mut r = null_mut();
    assert_ok(unsafe { vsr_analyse(mesh, s, &mut r) });
    let out = (doubles(r, vsr_result_loads), doubles(r, vsr_result_tau));
    unsafe {
        vsr_result_destroy(r);
        vsr_settings_destroy(s);
    }
    out
}

#[test]
fn mesh_setters_reject_bad_input_and_keep_the_previous_values() {
    let d = Dome::new(3, 8);
    let mesh = d.create();
    let nv = d.n_vertices();
    let nf = d.n_triangles();
    let before = loads_of(mesh);
    let good_v = vec![0.5; nv];
    let good_f = vec![2.0; nf];
    let mut nan_v = good_v.clone();
    nan_v[3] = f64::NAN;
    let mut neg_f = good_f.clone();
    neg_f[2] = -1.0;
    let mut neg_v = good_v.clone();
    neg_v[1] = -1.0;
    type Setter = unsafe extern "C" fn(*mut VsrMesh, *const f64, usize) -> VsrStatus;
    let cases: [(Setter, *mut VsrMesh, *const f64, usize, VsrStatus, &str); 16] = [
        (
            vsr_mesh_set_face_density,
            null_mut(),
            good_f.as_ptr(),
            nf,
            S::NullPointer,
            "mesh",
        ),
        (
            vsr_mesh_set_face_density,
            mesh,
            null(),
            nf,
            S::NullPointer,
            "density",
        ),
        (
            vsr_mesh_set_face_density,
            mesh,
            good_f.as_ptr(),
            nf - 1,
            S::InvalidArgument,
            "n_faces",
        ),
        (
            vsr_mesh_set_face_density,
            mesh,
            good_f.as_ptr(),
            0,
            S::InvalidArgument,
            "n_faces",
        ),
        (
            vsr_mesh_set_face_density,
            mesh,
            neg_f.as_ptr(),
            nf,
            S::InvalidArgument,
            "density",
        ),
        (
            vsr_mesh_set_face_density,
            mesh,
            nan_v.as_ptr(),
            nf,
            S::NonFinite,
            "density",
        ),
        (
            vsr_mesh_set_extra_loads,
            null_mut(),
            good_v.as_ptr(),
            nv,
            S::NullPointer,
            "mesh",
        ),
        (
            vsr_mesh_set_extra_loads,
            mesh,
            null(),
            nv,
            S::NullPointer,
            "loads",
        ),
        (
            vsr_mesh_set_extra_loads,
            mesh,
            nan_v.as_ptr(),
            nv,
            S::NonFinite,
            "loads",
        ),
        (
            vsr_mesh_set_extra_loads,
            mesh,
            good_v.as_ptr(),
            usize::MAX,
            S::LengthOverflow,
            "loads",
        ),
        (
            vsr_mesh_set_prescribed_tau,
            mesh,
            neg_v.as_ptr(),
            nv,
            S::InvalidArgument,
            "tau",
        ),
        (
            vsr_mesh_set_prescribed_tau,
            mesh,
            nan_v.as_ptr(),
            nv,
            S::NonFinite,
            "tau",
        ),
        (
            vsr_mesh_set_prescribed_tau,
            mesh,
            null(),
            nv,
            S::NullPointer,
            "tau",
        ),
        (
            vsr_mesh_set_horizontal_forces,
            mesh,
            null(),
            nv,
            S::NullPointer,
            "forces",
        ),
        (
            vsr_mesh_set_horizontal_forces,
            mesh,
            good_v.as_ptr(),
            usize::MAX,
            S::LengthOverflow,
            "forces",
        ),
        (
            vsr_mesh_set_horizontal_forces,
            mesh,
            good_v.as_ptr(),
            nv / 2,
            S::InvalidArgument,
            "n_vertices",
        ),
    ];
    for (i, (set, m, data, len, status, name)) in cases.into_iter().enumerate() {
        let s = unsafe { set(m, data, len) };
        assert_failed(s, status, name);
        let _ = i;
    }
    // A horizontal force at the centre vertex (interior) is refused.
    let mut forces = vec![0.0; 2 * nv];
    forces[0] = 1.0;
    let s = unsafe { vsr_mesh_set_horizontal_forces(mesh, forces.as_ptr(), nv) };
    assert_failed(s, S::InvalidArgument, "forces");
    assert!(last_error().contains("vertex 0"), "{}", last_error());
    assert_eq!(loads_of(mesh), before, "a failed setter changed the mesh");

    // Reuse after failed calls: valid values are taken.
    assert_ok(unsafe { vsr_mesh_set_face_density(mesh, good_f.as_ptr(), nf) });
    assert_ok(unsafe { vsr_mesh_set_extra_loads(mesh, good_v.as_ptr(), nv) });
    assert_ok(unsafe { vsr_mesh_set_prescribed_tau(mesh, good_v.as_ptr(), nv) });
    let after = loads_of(mesh);
    for (v, (a, b)) in after.0.iter().zip(&before.0).enumerate() {
        assert!(
            (a - (2.0 * b + 0.5)).abs() < 1e-12,
            "vertex {v}: {a} vs {b}"
        );
    }
    unsafe { vsr_mesh_destroy(mesh) };
}

#[test]
fn mesh_queries_reject_null_and_short_buffers() {
    let d = Dome::new(3, 8);
    let mesh = d.create();
    let mut n = [7usize; 4];
    let [a, b, c, e] = n.each_mut().map(|x| x as *mut usize);
    assert_failed(
        unsafe { vsr_mesh_counts(null(), a, b, c, e) },
        S::NullPointer,
        "mesh",
    );
    assert_failed(
        unsafe { vsr_mesh_counts(mesh, null_mut(), b, c, e) },
        S::NullPointer,
        "n_vertices",
    );
    assert_failed(
        unsafe { vsr_mesh_counts(mesh, a, b, c, null_mut()) },
        S::NullPointer,
        "n_holes",
    );
    assert_eq!(n, [7; 4]);
    let [a, b, c, e] = n.each_mut().map(|x| x as *mut usize);
    assert_ok(unsafe { vsr_mesh_counts(mesh, a, b, c, e) });
    assert_eq!(n[0], d.n_vertices());
    assert_eq!(n[2], d.n_triangles());
    assert_eq!(n[3], 0);
    let n_edges = n[1];
    let mut buf = vec![u32::MAX; 2 * n_edges - 1];
    let mut needed = 0;
    let s = unsafe { vsr_mesh_edges(mesh, buf.as_mut_ptr(), buf.len(), &mut needed) };
    assert_failed(s, S::BufferTooSmall, "len");
    assert_eq!(needed, 2 * n_edges);
    assert!(buf.iter().all(|&x| x == u32::MAX));
    unsafe { vsr_mesh_destroy(mesh) };
}

#[test]
fn settings_setters_reject_bad_values() {
    let s = settings();
    type F64Setter = unsafe extern "C" fn(*mut VsrSettings, f64) -> VsrStatus;
    let doubles: [(F64Setter, &str, f64, VsrStatus); 25] = [
        (vsr_settings_set_fairness, "gamma", -0.1, S::InvalidArgument),
        (vsr_settings_set_fairness, "gamma", f64::NAN, S::NonFinite),
        (
            vsr_settings_set_max_height_change,
            "diagonals",
            0.0,
            S::InvalidArgument,
        ),
        (
            vsr_settings_set_max_height_change,
            "diagonals",
            f64::INFINITY,
            S::NonFinite,
        ),
        (vsr_settings_set_fairness, "settings", 0.1, S::NullPointer),
        (
            vsr_settings_set_tolerance,
            "tolerance",
            f64::NAN,
            S::NonFinite,
        ),
        (
            vsr_settings_set_tolerance,
            "tolerance",
            f64::INFINITY,
            S::NonFinite,
        ),
        (
            vsr_settings_set_tolerance,
            "tolerance",
            -1e-3,
            S::InvalidArgument,
        ),
        (
            vsr_settings_set_tolerance,
            "tolerance",
            0.0,
            S::InvalidArgument,
        ),
        (
            vsr_settings_set_regularisation,
            "epsilon",
            f64::NAN,
            S::NonFinite,
        ),
        (
            vsr_settings_set_regularisation,
            "epsilon",
            -1.0,
            S::InvalidArgument,
        ),
        (
            vsr_settings_set_schedule_mu0,
            "mu0",
            -1.0,
            S::InvalidArgument,
        ),
        (vsr_settings_set_schedule_mu0, "mu0", f64::NAN, S::NonFinite),
        (
            vsr_settings_set_schedule_beta,
            "beta",
            1.5,
            S::InvalidArgument,
        ),
        (
            vsr_settings_set_schedule_beta,
            "beta",
            -0.5,
            S::InvalidArgument,
        ),
        (
            vsr_settings_set_schedule_beta,
            "beta",
            f64::NAN,
            S::NonFinite,
        ),
        (
            vsr_settings_set_schedule_mu_min,
            "mu_min",
            -1.0,
            S::InvalidArgument,
        ),
        (
            vsr_settings_set_schedule_mu_min,
            "mu_min",
            f64::NEG_INFINITY,
            S::NonFinite,
        ),
        (
            vsr_settings_set_schedule_eta,
            "eta",
            0.0,
            S::InvalidArgument,
        ),
        (vsr_settings_set_schedule_eta, "eta", f64::NAN, S::NonFinite),
        (
            vsr_settings_set_schedule_pull,
            "pull",
            -1.0,
            S::InvalidArgument,
        ),
        (
            vsr_settings_set_schedule_pull,
            "pull",
            f64::INFINITY,
            S::NonFinite,
        ),
        (
            vsr_settings_set_proximal_weight,
            "weight",
            -1e-6,
            S::InvalidArgument,
        ),
        (
            vsr_settings_set_proximal_weight,
            "weight",
            f64::NAN,
            S::NonFinite,
        ),
        (vsr_settings_set_tolerance, "settings", 1e-6, S::NullPointer),
    ];
    for (set, name, value, status) in doubles {
        let target = if status == S::NullPointer {
            null_mut()
        } else {
            s
        };
        assert_failed(unsafe { set(target, value) }, status, name);
    }
    type EnumSetter = unsafe extern "C" fn(*mut VsrSettings, u32) -> VsrStatus;
    let enums: [(EnumSetter, &str, u32); 6] = [
        (vsr_settings_set_method, "method", 2),
        (vsr_settings_set_tau_mode, "mode", 3),
        (vsr_settings_set_hole_mode, "mode", 2),
        (vsr_settings_set_load_rule, "rule", 3),
        (vsr_settings_set_formulation, "formulation", u32::MAX),
        (vsr_settings_set_q_min_scope, "scope", 2),
    ];
    for (set, name, value) in enums {
        assert_failed(unsafe { set(s, value) }, S::InvalidEnum, name);
        assert_failed(unsafe { set(null_mut(), 0) }, S::NullPointer, "settings");
    }
    assert_failed(
        unsafe { vsr_settings_set_odt_free_boundary(s, 2) },
        S::InvalidArgument,
        "enable",
    );
    assert_ok(unsafe { vsr_settings_set_odt_free_boundary(s, 0) });
    assert_ok(unsafe { vsr_settings_set_odt_iterations(s, 3) });
    assert_failed(
        unsafe { vsr_settings_set_odt_iterations(null_mut(), 3) },
        S::NullPointer,
        "settings",
    );
    assert_failed(
        unsafe { vsr_settings_set_max_iterations(s, 0) },
        S::InvalidArgument,
        "max_iterations",
    );
    assert_failed(
        unsafe { vsr_settings_set_max_iterations(null_mut(), 5) },
        S::NullPointer,
        "settings",
    );
    assert_failed(
        unsafe { vsr_settings_set_stall_window(s, 0) },
        S::InvalidArgument,
        "iterations",
    );
    assert_failed(
        unsafe { vsr_settings_set_q_min(s, f64::NAN, 0) },
        S::NonFinite,
        "value",
    );
    assert_failed(
        unsafe { vsr_settings_set_q_min(s, -0.1, 0) },
        S::InvalidArgument,
        "value",
    );
    assert_failed(
        unsafe { vsr_settings_set_q_min(s, 0.1, 2) },
        S::InvalidEnum,
        "kind",
    );
    assert_failed(
        unsafe { vsr_settings_set_q_max(s, 0.0, 0) },
        S::InvalidArgument,
        "value",
    );
    assert_failed(
        unsafe { vsr_settings_set_q_max(s, f64::NAN, 1) },
        S::NonFinite,
        "value",
    );
    assert_failed(
        unsafe { vsr_settings_set_q_max(s, 1.0, 7) },
        S::InvalidEnum,
        "kind",
    );
    // q_max below q_min (same kind), in either order of setting.
    assert_ok(unsafe { vsr_settings_set_q_min(s, 0.5, VsrBoundKind::Relative as u32) });
    assert_failed(
        unsafe { vsr_settings_set_q_max(s, 0.1, VsrBoundKind::Relative as u32) },
        S::InvalidArgument,
        "q_max",
    );
    assert_ok(unsafe { vsr_settings_set_q_max(s, 1.0, VsrBoundKind::Relative as u32) });
    assert_failed(
        unsafe { vsr_settings_set_q_min(s, 2.0, VsrBoundKind::Relative as u32) },
        S::InvalidArgument,
        "q_max",
    );
    assert_ok(unsafe { vsr_settings_set_q_max(s, f64::INFINITY, 0) });
    assert_ok(unsafe { vsr_settings_set_q_min(s, 2.0, VsrBoundKind::Relative as u32) });
    // Dual edge length bounds: lo >= 0 finite, hi > lo; (0, +inf) removes them.
    assert_failed(
        unsafe { vsr_settings_set_dual_length_bounds(s, -1.0, 1.0) },
        S::InvalidArgument,
        "lo",
    );
    assert_failed(
        unsafe { vsr_settings_set_dual_length_bounds(s, f64::NAN, 1.0) },
        S::NonFinite,
        "lo",
    );
    assert_failed(
        unsafe { vsr_settings_set_dual_length_bounds(s, 0.5, 0.5) },
        S::InvalidArgument,
        "hi",
    );
    assert_failed(
        unsafe { vsr_settings_set_dual_length_bounds(s, 0.1, f64::NAN) },
        S::InvalidArgument,
        "hi",
    );
    assert_ok(unsafe { vsr_settings_set_dual_length_bounds(s, 0.01, 0.5) });
    assert_ok(unsafe { vsr_settings_set_dual_length_bounds(s, 0.0, f64::INFINITY) });
    assert_failed(
        unsafe { vsr_settings_set_dual_length_smoothing(s, -0.1, 0.5) },
        S::InvalidArgument,
        "mu",
    );
    assert_failed(
        unsafe { vsr_settings_set_dual_length_smoothing(s, f64::INFINITY, 0.5) },
        S::NonFinite,
        "mu",
    );
    assert_failed(
        unsafe { vsr_settings_set_dual_length_smoothing(s, 1.0, 1.0) },
        S::InvalidArgument,
        "decay",
    );
    assert_failed(
        unsafe { vsr_settings_set_dual_length_smoothing(s, 1.0, f64::NAN) },
        S::NonFinite,
        "decay",
    );
    assert_ok(unsafe { vsr_settings_set_dual_length_smoothing(s, 0.0, 0.5) });
    assert_failed(
        unsafe { vsr_settings_set_progress(null_mut(), None, null_mut()) },
        S::NullPointer,
        "settings",
    );
    assert_failed(
        unsafe { vsr_settings_create(null_mut()) },
        S::NullPointer,
        "out",
    );
    unsafe { vsr_settings_destroy(s) };
}

#[test]
fn solves_reject_null_handles_and_leave_out_untouched() {
    let d = Dome::new(3, 8);
    let mesh = d.create();
    let s = settings();
    type Solve =
        unsafe extern "C" fn(*const VsrMesh, *const VsrSettings, *mut *mut VsrResult) -> VsrStatus;
    for solve in [vsr_analyse as Solve, vsr_form_find as Solve] {
        let mut out = sentinel();
        assert_failed(
            unsafe { solve(null(), s, &mut out) },
            S::NullPointer,
            "mesh",
        );
        assert_failed(
            unsafe { solve(mesh, null(), &mut out) },
            S::NullPointer,
            "settings",
        );
        assert_eq!(out, sentinel());
        assert_failed(unsafe { solve(mesh, s, null_mut()) }, S::NullPointer, "out");
    }
    unsafe {
        vsr_settings_destroy(s);
        vsr_mesh_destroy(mesh);
    }
}

#[test]
fn result_getters_check_pointers_buffers_and_kind() {
    let d = Dome::new(3, 8);
    let mesh = d.create();
    let s = settings();
    let mut analysis = null_mut();
    assert_ok(unsafe { vsr_analyse(mesh, s, &mut analysis) });
    let mut form = null_mut();
    assert_ok(unsafe { vsr_form_find(mesh, s, &mut form) });
    let nv = d.n_vertices();

    // Short buffer: BUFFER_TOO_SMALL, `needed` written, buffer untouched.
    let mut buf = vec![-7.0; 3 * nv - 1];
    let mut needed = 0;
    let st = unsafe { vsr_result_positions(form, buf.as_mut_ptr(), buf.len(), &mut needed) };
    assert_failed(st, S::BufferTooSmall, "len");
    assert_eq!(needed, 3 * nv);
    assert!(buf.iter().all(|&x| x == -7.0));
    // NULL buffer with a length, NULL result.
    let st = unsafe { vsr_result_loads(form, null_mut(), 5, &mut needed) };
    assert_failed(st, S::NullPointer, "out");
    let mut needed = 99;
    let st = unsafe { vsr_result_loads(null(), buf.as_mut_ptr(), buf.len(), &mut needed) };
    assert_failed(st, S::NullPointer, "result");
    assert_eq!(needed, 99);
    assert!(buf.iter().all(|&x| x == -7.0));
    // `needed` is optional; size query with out = NULL, len = 0.
    assert_ok(unsafe { vsr_result_loads(form, buf.as_mut_ptr(), buf.len(), null_mut()) });
    let mut n = 0;
    assert_ok(unsafe { vsr_result_residuals(form, null_mut(), 0, &mut n) });
    assert_eq!(n, nv);

    // Form-finding-only quantities on an analysis result.
    let mut h = vec![-1.0; 100];
    let mut needed = 5;
    let st = unsafe { vsr_result_eps_history(analysis, h.as_mut_ptr(), h.len(), &mut needed) };
    assert_failed(st, S::NotAvailable, "result");
    assert_eq!(needed, 5);
    assert!(h.iter().all(|&x| x == -1.0));
    let mut solvers = [VsrQpSolver::Clarabel; 3];
    let st = unsafe { vsr_result_step_solvers(analysis, solvers.as_mut_ptr(), 3, &mut needed) };
    assert_failed(st, S::NotAvailable, "result");
    assert!(
        last_error().contains("only a result of vsr_form_find has the step solvers"),
        "{}",
        last_error()
    );
    assert_eq!((needed, solvers), (5, [VsrQpSolver::Clarabel; 3]));
    let (mut t, mut it) = (VsrTermination::Cancelled, 77usize);
    assert_failed(
        unsafe { vsr_result_termination(analysis, &mut t, &mut it) },
        S::NotAvailable,
        "result",
    );
    assert_eq!((t, it), (VsrTermination::Cancelled, 77));
    let (mut a, mut b) = (-1.0, -1.0);
    assert_failed(
        unsafe { vsr_result_distances(analysis, &mut a, &mut b) },
        S::NotAvailable,
        "result",
    );
    assert_eq!((a, b), (-1.0, -1.0));
    assert_failed(
        unsafe { vsr_result_distances(form, null_mut(), &mut b) },
        S::NullPointer,
        "hausdorff",
    );
    assert_failed(
        unsafe { vsr_result_distances(form, &mut a, null_mut()) },
        S::NullPointer,
        "l2",
    );
    assert_eq!((a, b), (-1.0, -1.0));
    assert_ok(unsafe { vsr_result_distances(form, &mut a, &mut b) });
    assert!(a >= 0.0 && b >= 0.0 && a >= b);
    let (mut rms, mut max) = (-1.0, -1.0);
    assert_failed(
        unsafe { vsr_result_height_change(analysis, &mut rms, &mut max) },
        S::NotAvailable,
        "result",
    );
    assert_failed(
        unsafe { vsr_result_height_change(form, null_mut(), &mut max) },
        S::NullPointer,
        "rms",
    );
    assert_eq!((rms, max), (-1.0, -1.0));
    assert_ok(unsafe { vsr_result_height_change(form, &mut rms, &mut max) });
    assert!(rms >= 0.0 && max >= rms);

    // Scalar getters: every NULL slot.
    let (mut st_, mut eps, mut obj, mut qi) = (VsrStressStatus::NumericalError, -1.0, -1.0, 0usize);
    assert_failed(
        unsafe { vsr_result_stress_summary(form, null_mut(), &mut eps, &mut obj, &mut qi) },
        S::NullPointer,
        "status",
    );
    assert_failed(
        unsafe { vsr_result_stress_summary(form, &mut st_, null_mut(), &mut obj, &mut qi) },
        S::NullPointer,
        "eps_inf",
    );
    assert_failed(
        unsafe { vsr_result_stress_summary(form, &mut st_, &mut eps, null_mut(), &mut qi) },
        S::NullPointer,
        "objective",
    );
    assert_failed(
        unsafe { vsr_result_stress_summary(form, &mut st_, &mut eps, &mut obj, null_mut()) },
        S::NullPointer,
        "qp_iterations",
    );
    assert_eq!(
        (st_, eps, obj, qi),
        (VsrStressStatus::NumericalError, -1.0, -1.0, 0)
    );
    assert_ok(unsafe { vsr_result_stress_summary(form, &mut st_, &mut eps, &mut obj, &mut qi) });
    assert_eq!(st_, VsrStressStatus::Solved);
    assert_ok(unsafe { vsr_result_termination(form, &mut t, &mut it) });
    assert_eq!(t, VsrTermination::Converged);
    assert!(eps < 1e-6, "eps_inf {eps}");
    let history = doubles(form, vsr_result_eps_history);
    assert!(!history.is_empty() && history.len() <= 2 * it + 1);
    // One solver per stress step, all native on this small cap.
    let mut steps = usize::MAX;
    assert_ok(unsafe { vsr_result_step_solvers(form, null_mut(), 0, &mut steps) });
    assert_eq!(steps, it);
    let mut solvers = vec![VsrQpSolver::Clarabel; steps];
    assert_ok(unsafe { vsr_result_step_solvers(form, solvers.as_mut_ptr(), steps, null_mut()) });
    assert!(
        solvers.iter().all(|&s| s == VsrQpSolver::Native),
        "{solvers:?}"
    );

    let (mut x, mut y, mut z) = (-1.0, -1.0, -1.0);
    assert_failed(
        unsafe { vsr_result_timings(form, &mut x, &mut y, null_mut()) },
        S::NullPointer,
        "total_seconds",
    );
    assert_eq!((x, y, z), (-1.0, -1.0, -1.0));
    assert_ok(unsafe { vsr_result_timings(form, &mut x, &mut y, &mut z) });
    assert!(x >= 0.0 && y >= 0.0 && z >= x);
    let mut k = VsrResultKind::FormFinding;
    assert_failed(
        unsafe { vsr_result_kind(null(), &mut k) },
        S::NullPointer,
        "result",
    );
    assert_ok(unsafe { vsr_result_kind(analysis, &mut k) });
    assert_eq!(k, VsrResultKind::Analysis);

    // Termination message: NUL-terminated, short buffer untouched.
    let mut msg = vec![b'#' as std::ffi::c_char; 4];
    let mut needed = 0;
    let st =
        unsafe { vsr_result_termination_message(form, msg.as_mut_ptr(), msg.len(), &mut needed) };
    assert_failed(st, S::BufferTooSmall, "len");
    assert!(msg.iter().all(|&c| c == b'#' as std::ffi::c_char));
    let mut msg = vec![0 as std::ffi::c_char; needed];
    assert_ok(unsafe {
        vsr_result_termination_message(form, msg.as_mut_ptr(), msg.len(), null_mut())
    });
    let text = unsafe { CStr::from_ptr(msg.as_ptr()) }.to_str().unwrap();
    assert!(text.starts_with("converged"), "{text}");
    let mut stalled = vec![5u32; 3];
    let mut needed = 9;
    assert_ok(unsafe { vsr_result_stalled_vertices(form, stalled.as_mut_ptr(), 3, &mut needed) });
    assert_eq!(needed, 0);

    // Segments and their edge ids agree; every id is an interior edge.
    let seg = doubles(form, vsr_result_force_diagram_segments);
    let mut ids = vec![0u32; seg.len() / 4];
    let mut m = 0;
    assert_ok(unsafe {
        vsr_result_force_diagram_segment_edges(form, ids.as_mut_ptr(), ids.len(), &mut m)
    });
    assert_eq!(m, seg.len() / 4);
    assert!(ids.windows(2).all(|w| w[0] < w[1]));

    unsafe {
        vsr_result_destroy(analysis);
        vsr_result_destroy(form);
        vsr_settings_destroy(s);
        vsr_mesh_destroy(mesh);
    }
}

#[test]
fn status_names_and_versions() {
    for (status, name) in [
        (S::Ok, "VSR_STATUS_OK"),
        (S::NullPointer, "VSR_STATUS_NULL_POINTER"),
        (S::BufferTooSmall, "VSR_STATUS_BUFFER_TOO_SMALL"),
        (S::Panic, "VSR_STATUS_PANIC"),
    ] {
        let got = unsafe { CStr::from_ptr(vsr_status_name(status as u32)) };
        assert_eq!(got.to_str().unwrap(), name);
    }
    let header =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/include/voussoir.h"))
            .unwrap();
    for value in 0..=200u32 {
        let got = unsafe { CStr::from_ptr(vsr_status_name(value)) }
            .to_str()
            .unwrap();
        if got != "VSR_STATUS_UNKNOWN" {
            assert!(
                header.contains(&format!("{got} = {value},")),
                "{got} = {value}"
            );
        }
    }
    assert_eq!(
        unsafe { CStr::from_ptr(vsr_status_name(12345)) }
            .to_str()
            .unwrap(),
        "VSR_STATUS_UNKNOWN"
    );
    assert_eq!(vsr_abi_version(), VSR_ABI_VERSION);
}

#[test]
fn a_successful_call_clears_the_last_error() {
    let mut out = sentinel();
    let s = unsafe { vsr_mesh_create(null(), 0, null(), 0, null(), 0, &mut out) };
    assert_ne!(s, S::Ok);
    assert!(!last_error().is_empty());
    let st = settings(); // asserts an empty message after success
    unsafe { vsr_settings_destroy(st) };
}

unsafe extern "C" fn cancel_at_two(
    user: *mut std::ffi::c_void,
    iteration: usize,
    eps: f64,
) -> std::ffi::c_int {
    let seen = unsafe { &mut *(user as *mut Vec<(usize, f64)>) };
    seen.push((iteration, eps));
    (iteration == 2) as std::ffi::c_int
}

#[test]
fn progress_callback_sees_every_iteration_and_can_cancel() {
    let d = Dome::new(4, 10);
    // Start from a flat-ish shape so that form finding needs several iterations.
    let mut flat = Dome::new(4, 10);
    flat.positions
        .iter_mut()
        .skip(2)
        .step_by(3)
        .for_each(|z| *z *= 0.2);
    let _ = d;
    let mesh = flat.create();
    let s = settings();
    let mut seen: Vec<(usize, f64)> = Vec::new();
    assert_ok(unsafe { vsr_settings_set_tolerance(s, 1e-14) });
    assert_ok(unsafe {
        vsr_settings_set_progress(
            s,
            Some(cancel_at_two),
            &mut seen as *mut _ as *mut std::ffi::c_void,
        )
    });
    let mut r = null_mut();
    assert_ok(unsafe { vsr_form_find(mesh, s, &mut r) });
    let (mut t, mut it) = (VsrTermination::Converged, 0);
    assert_ok(unsafe { vsr_result_termination(r, &mut t, &mut it) });
    assert_eq!(t, VsrTermination::Cancelled);
    assert_eq!(it, 3);
    let history = doubles(r, vsr_result_eps_history);
    assert_eq!(seen.iter().map(|s| s.0).collect::<Vec<_>>(), vec![0, 1, 2]);
    assert_eq!(seen.iter().map(|s| s.1).collect::<Vec<_>>(), history);
    let _ = last_error();
    unsafe {
        vsr_result_destroy(r);
        vsr_settings_destroy(s);
        vsr_mesh_destroy(mesh);
    }
}

#[test]
fn odt_sweeps_move_the_plan_through_the_c_abi() {
    let mut d = Dome::new(4, 10);
    d.positions
        .iter_mut()
        .skip(2)
        .step_by(3)
        .for_each(|z| *z *= 0.3);
    let mesh = d.create();
    let s = settings();
    assert_ok(unsafe { vsr_settings_set_odt_iterations(s, 2) });
    let mut r = null_mut();
    assert_ok(unsafe { vsr_form_find(mesh, s, &mut r) });
    let p = doubles(r, vsr_result_positions);
    let moved = (0..d.n_vertices())
        .map(|v| (p[3 * v] - d.positions[3 * v]).hypot(p[3 * v + 1] - d.positions[3 * v + 1]))
        .fold(0.0, f64::max);
    assert!(moved.is_finite());
    for &a in &d.anchored {
        let a = a as usize;
        assert_eq!(&p[3 * a..3 * a + 3], &d.positions[3 * a..3 * a + 3]);
    }
    unsafe {
        vsr_result_destroy(r);
        vsr_settings_destroy(s);
        vsr_mesh_destroy(mesh);
    }
}

#[test]
fn both_methods_through_the_c_abi_equal_the_rust_ones_bit_for_bit() {
    let mut d = Dome::new(4, 10);
    d.positions
        .iter_mut()
        .skip(2)
        .step_by(3)
        .for_each(|z| *z *= 0.6);
    let rust_mesh = voussoir::Mesh::new(
        d.positions.chunks(3).map(|p| [p[0], p[1], p[2]]).collect(),
        d.triangles.chunks(3).map(|t| [t[0], t[1], t[2]]).collect(),
        &d.anchored,
    )
    .unwrap();
    let problem = voussoir::Problem::new(rust_mesh);
    let mesh = d.create();
    for (method, rust_method) in [
        (VsrMethod::Nearest, voussoir::FormMethod::Nearest),
        (VsrMethod::Paper, voussoir::FormMethod::Paper),
    ] {
        let s = settings();
        assert_ok(unsafe { vsr_settings_set_method(s, method as u32) });
        let mut r = null_mut();
        assert_ok(unsafe { vsr_form_find(mesh, s, &mut r) });
        let settings = voussoir::FormFindSettings::default().with_method(rust_method);
        let expected = voussoir::form_find(&problem, &settings, None).unwrap();
        let flat: Vec<f64> = expected.positions.iter().flatten().copied().collect();
        assert_eq!(doubles(r, vsr_result_positions), flat, "{method:?}");
        let (mut rms, mut max) = (0.0, 0.0);
        assert_ok(unsafe { vsr_result_height_change(r, &mut rms, &mut max) });
        assert_eq!((rms, max), (expected.rms_change, expected.max_change));
        unsafe {
            vsr_result_destroy(r);
            vsr_settings_destroy(s);
        }
    }
    unsafe { vsr_mesh_destroy(mesh) };
}

/// A progress callback that makes a failing call (a NULL handle) and lets the solve go on.
unsafe extern "C" fn fail_inside(
    _user: *mut std::ffi::c_void,
    _iteration: usize,
    _eps: f64,
) -> std::ffi::c_int {
    let s = unsafe { vsr_settings_set_tolerance(null_mut(), 1e-6) };
    assert_eq!(s, S::NullPointer);
    0
}

#[test]
fn a_failing_call_inside_the_progress_callback_leaves_no_message() {
    let mesh = Dome::new(3, 8).create();
    let s = settings();
    assert_ok(unsafe { vsr_settings_set_progress(s, Some(fail_inside), null_mut()) });
    let mut r = null_mut();
    let status = unsafe { vsr_form_find(mesh, s, &mut r) };
    assert_eq!(status, S::Ok);
    assert_eq!(last_error(), "", "a stale message after a successful solve");
    unsafe {
        vsr_result_destroy(r);
        vsr_settings_destroy(s);
        vsr_mesh_destroy(mesh);
    }
}

/// Loads a solve cannot use: none at all (density 0 everywhere), or models in units whose
/// loads double precision cannot carry (coordinates of 1e78 or 1e-100); coordinates of 1e200
/// are refused by `vsr_mesh_create` itself. Each gets its status and a message that says why.
#[test]
fn solves_reject_weightless_and_unrepresentable_loads() {
    let s = settings();
    let d = Dome::new(3, 8);
    let weightless = d.create();
    let zeros = vec![0.0; d.n_triangles()];
    assert_ok(unsafe { vsr_mesh_set_face_density(weightless, zeros.as_ptr(), zeros.len()) });
    let mut meshes = vec![(weightless, "no weight to balance")];
    for factor in [1e78, 1e-100] {
        let mut scaled = Dome::new(3, 8);
        scaled.positions.iter_mut().for_each(|c| *c *= factor);
        meshes.push((scaled.create(), "cannot be represented in double precision"));
    }
    for (mesh, why) in meshes {
        for solve in [vsr_analyse, vsr_form_find] {
            let mut out = sentinel();
            assert_failed(
                unsafe { solve(mesh, s, &mut out) },
                S::InvalidArgument,
                "loads",
            );
            assert!(last_error().contains(why), "{}", last_error());
            // Issue 48: "argument `loads`: invalid argument `loads`: ..." said it twice.
            assert!(
                !last_error().contains("invalid argument"),
                "{}",
                last_error()
            );
            assert_eq!(out, sentinel());
        }
        unsafe { vsr_mesh_destroy(mesh) };
    }
    let (status, out) = create_with(|p, _, _| p.iter_mut().for_each(|c| *c *= 1e200));
    assert_failed(status, S::InvalidArgument, "positions");
    assert!(
        last_error().contains("cannot be represented"),
        "{}",
        last_error()
    );
    assert_eq!(out, sentinel());
    unsafe { vsr_settings_destroy(s) };
}

/// A dome drawn upside down is read as its mirror image (docs/method.md §13.1) and the C
/// result says so; the upright dome is not; an analysis has no such answer.
#[test]
fn a_hanging_dome_is_reported_mirrored_through_the_c_abi() {
    for (scale, expected) in [(1.0, 0), (-1.0, 1)] {
        let mut d = Dome::new(4, 10);
        d.positions
            .iter_mut()
            .skip(2)
            .step_by(3)
            .for_each(|z| *z *= scale);
        let mesh = d.create();
        let s = settings();
        let (mut form, mut analysis) = (null_mut(), null_mut());
        assert_ok(unsafe { vsr_form_find(mesh, s, &mut form) });
        assert_ok(unsafe { vsr_analyse(mesh, s, &mut analysis) });
        let mut mirrored = -1;
        assert_failed(
            unsafe { vsr_result_mirrored(form, null_mut()) },
            S::NullPointer,
            "mirrored",
        );
        assert_failed(
            unsafe { vsr_result_mirrored(analysis, &mut mirrored) },
            S::NotAvailable,
            "result",
        );
        assert_eq!(mirrored, -1, "written on failure");
        assert_ok(unsafe { vsr_result_mirrored(form, &mut mirrored) });
        assert_eq!(mirrored, expected, "heights × {scale}");
        unsafe {
            vsr_result_destroy(form);
            vsr_result_destroy(analysis);
            vsr_settings_destroy(s);
            vsr_mesh_destroy(mesh);
        }
    }
}
