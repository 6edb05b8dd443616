//! Masonry assessment through the C ABI: `vsr_assess` equals the Rust `assess` bit for bit
//! (thickness and surface envelopes, every objective the tests can afford), its certificate
//! holds when recomputed from the copied-out arrays, and hostile input gets the right status,
//! a one-line message naming the argument, and untouched outputs.

mod capi_support;

use capi_support::{assert_failed, assert_ok, last_error, Dome};
use std::ffi::{c_int, c_void, CStr};
use std::ptr::{null, null_mut};
use voussoir::capi::*;
use voussoir::{assess, AssessResult, AssessSettings, Envelope, Mesh, Objective, Problem};
use voussoir::{Termination, Thickness};
use VsrStatus as S;

/// A recognisable non-NULL pointer that must never be written over or dereferenced.
fn sentinel<T>() -> *mut T {
    0xdead_bee8usize as *mut T
}

fn rows3(flat: &[f64]) -> Vec<[f64; 3]> {
    flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

fn rust_mesh(d: &Dome) -> Mesh {
    let faces = d
        .triangles
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    Mesh::new(rows3(&d.positions), faces, &d.anchored).unwrap()
}

fn envelope_of(mesh: *const VsrMesh, thickness: &[f64]) -> *mut VsrEnvelope {
    let mut e = null_mut();
    assert_ok(unsafe {
        vsr_envelope_from_thickness(mesh, thickness.as_ptr(), thickness.len(), &mut e)
    });
    e
}

fn assess_settings() -> *mut VsrAssessSettings {
    let mut s = null_mut();
    assert_ok(unsafe { vsr_assess_settings_create(&mut s) });
    s
}

fn run(
    mesh: *const VsrMesh,
    e: *const VsrEnvelope,
    s: *const VsrAssessSettings,
) -> *mut VsrAssessment {
    let mut a = null_mut();
    assert_ok(unsafe { vsr_assess(mesh, e, s, &mut a) });
    a
}

type Getter = unsafe extern "C" fn(*const VsrAssessment, *mut f64, usize, *mut usize) -> VsrStatus;

fn doubles(a: *const VsrAssessment, get: Getter) -> Vec<f64> {
    let mut n = usize::MAX;
    assert_ok(unsafe { get(a, null_mut(), 0, &mut n) });
    let mut v = vec![f64::NAN; n];
    let mut m = 0;
    assert_ok(unsafe { get(a, v.as_mut_ptr(), v.len(), &mut m) });
    assert_eq!(m, n);
    v
}

fn envelope_doubles(
    e: *const VsrEnvelope,
    get: unsafe extern "C" fn(*const VsrEnvelope, *mut f64, usize, *mut usize) -> VsrStatus,
) -> Vec<f64> {
    let mut n = 0;
    assert_ok(unsafe { get(e, null_mut(), 0, &mut n) });
    let mut v = vec![f64::NAN; n];
    assert_ok(unsafe { get(e, v.as_mut_ptr(), n, &mut n) });
    v
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// Every figure and array of the C assessment equals the Rust result's, bit for bit.
fn assert_same(a: *const VsrAssessment, r: &AssessResult) {
    let flat = |v: &[[f64; 3]]| v.iter().flatten().copied().collect::<Vec<_>>();
    let flat2 = |v: &[[f64; 2]]| v.iter().flatten().copied().collect::<Vec<_>>();
    let arrays: [(Getter, Vec<f64>); 7] = [
        (vsr_assessment_positions, flat(&r.positions)),
        (vsr_assessment_force_densities, r.force_densities.clone()),
        (vsr_assessment_loads, r.loads.clone()),
        (vsr_assessment_residuals, r.residuals.clone()),
        (vsr_assessment_lower, r.lower.clone()),
        (vsr_assessment_upper, r.upper.clone()),
        (vsr_assessment_reactions, flat2(&r.reactions)),
    ];
    for (k, (get, want)) in arrays.iter().enumerate() {
        assert_eq!(bits(&doubles(a, *get)), bits(want), "array {k}");
    }
    let (mut feasible, mut t, mut it, mut sec) = (9, VsrTermination::Blocked, 0, 0.0);
    assert_ok(unsafe { vsr_assessment_outcome(a, &mut feasible, &mut t, &mut it, &mut sec) });
    assert_eq!(feasible, u32::from(r.feasible));
    assert_eq!(
        (t, it),
        (VsrTermination::of_test(&r.termination), r.iterations)
    );
    assert!(sec >= 0.0);
    let mut f = [f64::NAN; 4];
    let [f0, f1, f2, f3] = &mut f;
    assert_ok(unsafe { vsr_assessment_figures(a, f0, f1, f2, f3) });
    let want = [
        r.thickness_scale,
        r.safety_factor,
        r.thrust_horizontal,
        r.load_factor,
    ];
    assert_eq!(bits(&f), bits(&want));
    let mut unbounded = 7;
    assert_ok(unsafe { vsr_assessment_unbounded(a, &mut unbounded) });
    assert_eq!(unbounded, u32::from(r.unbounded));
    let (mut eps, mut h, mut w, mut wb, mut wr) = (f64::NAN, f64::NAN, f64::NAN, 7, 7);
    assert_ok(unsafe { vsr_assessment_certificate(a, &mut eps, &mut h, &mut w, &mut wb, &mut wr) });
    assert_eq!(
        bits(&[eps, h, w]),
        bits(&[r.eps_inf, r.horizontal_imbalance, r.worst_bound.0])
    );
    assert_eq!(wb, r.worst_bound.1.unwrap_or(VSR_NO_VERTEX));
    assert_eq!(wr, r.worst_residual_vertex.unwrap_or(VSR_NO_VERTEX));
    assert_same_joints(a, r);
}

/// The springing joints of the C assessment equal the Rust result's, bit for bit.
fn assert_same_joints(a: *const VsrAssessment, r: &AssessResult) {
    let rows: Vec<f64> = (r.joints.iter())
        .flat_map(|j| {
            let (h, p) = (j.horizontal, j.point);
            [
                j.springing,
                j.reach,
                h[0],
                h[1],
                j.vertical,
                p[0],
                p[1],
                p[2],
                j.offset,
            ]
        })
        .collect();
    assert_eq!(bits(&doubles(a, vsr_assessment_joints)), bits(&rows));
    let mut n = usize::MAX;
    assert_ok(unsafe { vsr_assessment_joint_vertices(a, null_mut(), 0, &mut n) });
    let mut vertices = vec![u32::MAX; n];
    assert_ok(unsafe { vsr_assessment_joint_vertices(a, vertices.as_mut_ptr(), n, &mut n) });
    let want: Vec<u32> = r.joints.iter().map(|j| j.vertex).collect();
    assert_eq!(vertices, want);
    assert_ok(unsafe { vsr_assessment_stranded(a, null_mut(), 0, &mut n) });
    let mut stranded = vec![u32::MAX; n];
    assert_ok(unsafe { vsr_assessment_stranded(a, stranded.as_mut_ptr(), n, &mut n) });
    assert_eq!(stranded, r.stranded);
    let (mut excess, mut vertex) = (f64::NAN, 7);
    assert_ok(unsafe { vsr_assessment_worst_joint(a, &mut excess, &mut vertex) });
    assert_eq!(excess.to_bits(), r.worst_joint.0.to_bits());
    assert_eq!(vertex, r.worst_joint.1.unwrap_or(VSR_NO_VERTEX));
}

/// The C name of a Rust termination, for comparison.
trait OfTest {
    fn of_test(t: &Termination) -> VsrTermination;
}

impl OfTest for VsrTermination {
    fn of_test(t: &Termination) -> VsrTermination {
        match t {
            Termination::Converged => VsrTermination::Converged,
            Termination::MaxIterations => VsrTermination::MaxIterations,
            Termination::Stalled { .. } => VsrTermination::Stalled,
            Termination::Infeasible { .. } => VsrTermination::Infeasible,
            Termination::NumericalError { .. } => VsrTermination::NumericalError,
            Termination::Cancelled => VsrTermination::Cancelled,
            _ => VsrTermination::Blocked,
        }
    }
}

/// The certificate recomputed from the copied-out arrays alone: vertical and horizontal
/// equilibrium, q ≥ 0, heights within the bounds, and the thrust.
fn check_certificate(a: *const VsrAssessment, anchored: &[u32]) {
    let pos = rows3(&doubles(a, vsr_assessment_positions));
    let (q, p) = (
        doubles(a, vsr_assessment_force_densities),
        doubles(a, vsr_assessment_loads),
    );
    let (lo, hi) = (
        doubles(a, vsr_assessment_lower),
        doubles(a, vsr_assessment_upper),
    );
    let mut n = 0;
    assert_ok(unsafe { vsr_assessment_edges(a, null_mut(), 0, &mut n) });
    let mut edges = vec![0u32; n];
    assert_ok(unsafe { vsr_assessment_edges(a, edges.as_mut_ptr(), n, &mut n) });
    let mut fixed = vec![false; pos.len()];
    anchored.iter().for_each(|&v| fixed[v as usize] = true);
    let mut r = p.iter().map(|x| -x).collect::<Vec<f64>>();
    let mut h = vec![[0.0; 2]; pos.len()];
    let mut thrust = vec![[0.0; 2]; pos.len()];
    for (e, &qe) in edges.chunks_exact(2).zip(&q) {
        assert!(qe >= 0.0, "tension {qe}");
        let (i, j) = (e[0] as usize, e[1] as usize);
        for (a, b) in [(i, j), (j, i)] {
            r[a] += qe * (pos[a][2] - pos[b][2]);
            for d in 0..2 {
                h[a][d] += qe * (pos[a][d] - pos[b][d]);
                if fixed[a] && !fixed[b] {
                    thrust[a][d] += qe * (pos[a][d] - pos[b][d]);
                }
            }
        }
    }
    let free: Vec<usize> = (0..pos.len()).filter(|&v| !fixed[v]).collect();
    let mean = free.iter().map(|&v| p[v]).sum::<f64>() / free.len() as f64;
    for &v in &free {
        assert!(r[v].abs() < 1e-6 * mean, "vertex {v}: residual {}", r[v]);
        assert!(
            h[v][0].hypot(h[v][1]) < 1e-9 * mean,
            "vertex {v}: horizontal"
        );
    }
    for (v, z) in pos.iter().map(|p| p[2]).enumerate() {
        assert!(
            z >= lo[v] - 1e-9 && z <= hi[v] + 1e-9,
            "vertex {v}: {z} outside"
        );
    }
    let total: f64 = anchored
        .iter()
        .map(|&a| thrust[a as usize][0].hypot(thrust[a as usize][1]))
        .sum();
    let mut f = [0.0; 4];
    let [f0, f1, f2, f3] = &mut f;
    assert_ok(unsafe { vsr_assessment_figures(a, f0, f1, f2, f3) });
    assert!(
        (total - f[2]).abs() <= 1e-9 * f[2],
        "thrust {total} vs {}",
        f[2]
    );
}

#[test]
fn thickness_envelopes_assess_as_the_rust_api_does() {
    let d = Dome::new(3, 12);
    let mesh = d.create();
    let rust = rust_mesh(&d);
    let n_faces = d.n_triangles();
    let per_face: Vec<f64> = (0..n_faces).map(|f| 0.08 + 0.04 * (f % 3) as f64).collect();
    let cases: [(Vec<f64>, Thickness, Objective); 3] = [
        (vec![0.1], Thickness::Uniform(0.1), Objective::Fit),
        (vec![0.1], Thickness::Uniform(0.1), Objective::MinThickness),
        (
            per_face.clone(),
            Thickness::PerFace(per_face),
            Objective::MinThrust,
        ),
    ];
    for (values, thickness, objective) in cases {
        let e = envelope_of(mesh, &values);
        let s = assess_settings();
        assert_ok(unsafe {
            vsr_assess_settings_set_objective(s, VsrObjective::of_test(objective) as u32)
        });
        let a = run(mesh, e, s);
        let env = Envelope::from_thickness(&rust, &thickness).unwrap();
        assert_eq!(
            bits(&envelope_doubles(e, vsr_envelope_lower)),
            bits(&env.lower)
        );
        assert_eq!(
            bits(&envelope_doubles(e, vsr_envelope_upper)),
            bits(&env.upper)
        );
        assert_eq!(
            bits(&envelope_doubles(e, vsr_envelope_face_thickness)),
            bits(&env.face_thickness)
        );
        let settings = AssessSettings::default().with_objective(objective);
        let r = assess(&Problem::new(rust.clone()), &env, &settings, None).unwrap();
        assert!(r.feasible, "{objective:?}");
        assert_eq!(
            r.joints.len(),
            d.anchored.len(),
            "a joint at every free support"
        );
        assert_same(a, &r);
        check_certificate(a, &d.anchored);
        let mut o = VsrObjective::MaxLoad;
        assert_ok(unsafe { vsr_assessment_objective(a, &mut o) });
        assert_eq!(o, VsrObjective::of_test(objective));
        unsafe {
            vsr_assessment_destroy(a);
            vsr_assess_settings_destroy(s);
            vsr_envelope_destroy(e);
        }
    }
    unsafe { vsr_mesh_destroy(mesh) };
}

/// A square anchored at three corners has a free corner at the fourth: the C assessment
/// refuses it at once and lists that vertex as stranded, as the Rust one does.
#[test]
fn a_stranded_vertex_is_listed_as_the_rust_api_lists_it() {
    let d = Dome {
        positions: vec![
            0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.5, 0.5, 0.3,
        ],
        triangles: vec![0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4],
        anchored: vec![0, 1, 2],
    };
    let mesh = d.create();
    let e = envelope_of(mesh, &[1.0]);
    let s = assess_settings();
    let a = run(mesh, e, s);
    let rust = rust_mesh(&d);
    let env = Envelope::from_thickness(&rust, &Thickness::Uniform(1.0)).unwrap();
    let r = assess(&Problem::new(rust), &env, &AssessSettings::default(), None).unwrap();
    assert!(matches!(r.termination, Termination::Infeasible { .. }));
    assert_eq!(r.stranded, [3]);
    assert_same(a, &r);
    unsafe {
        vsr_assessment_destroy(a);
        vsr_assess_settings_destroy(s);
        vsr_envelope_destroy(e);
        vsr_mesh_destroy(mesh);
    }
}

trait ObjectiveOf {
    fn of_test(o: Objective) -> VsrObjective;
}

impl ObjectiveOf for VsrObjective {
    fn of_test(o: Objective) -> VsrObjective {
        match o {
            Objective::Fit => VsrObjective::Fit,
            Objective::MinThickness => VsrObjective::MinThickness,
            Objective::MinThrust => VsrObjective::MinThrust,
            Objective::MaxThrust => VsrObjective::MaxThrust,
            _ => VsrObjective::MaxLoad,
        }
    }
}

/// Positions and triangles, flat.
type Flat = (Vec<f64>, Vec<u32>);

/// The dome `d` shifted by `dz`, on a finer ring triangulation of its own, as flat arrays.
fn shifted(dz: f64, scale: f64) -> Flat {
    let d = Dome::new(6, 24);
    let p = d
        .positions
        .chunks_exact(3)
        .flat_map(|p| [p[0] * scale, p[1] * scale, p[2] + dz]);
    (p.collect(), d.triangles)
}

unsafe fn from_surfaces(
    mesh: *const VsrMesh,
    lower: &Flat,
    upper: &Flat,
    out: *mut *mut VsrEnvelope,
) -> VsrStatus {
    unsafe {
        vsr_envelope_from_surfaces(
            mesh,
            lower.0.as_ptr(),
            lower.0.len() / 3,
            lower.1.as_ptr(),
            lower.1.len() / 3,
            upper.0.as_ptr(),
            upper.0.len() / 3,
            upper.1.as_ptr(),
            upper.1.len() / 3,
            out,
        )
    }
}

#[test]
fn surface_envelopes_and_max_load_assess_as_the_rust_api_does() {
    let d = Dome::new(3, 12);
    let mesh = d.create();
    let rust = rust_mesh(&d);
    let (lower, upper) = (shifted(-0.05, 1.05), shifted(0.05, 1.05));
    let mut e = null_mut();
    assert_ok(unsafe { from_surfaces(mesh, &lower, &upper, &mut e) });
    let faces = |t: &[u32]| {
        t.chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect::<Vec<_>>()
    };
    let env = Envelope::from_surfaces(
        &rust,
        (&rows3(&lower.0), &faces(&lower.1)),
        (&rows3(&upper.0), &faces(&upper.1)),
    )
    .unwrap();
    let mut pattern = vec![0.0; d.n_vertices()];
    pattern[0] = 1.0;
    let s = assess_settings();
    unsafe {
        assert_ok(vsr_assess_settings_set_objective(
            s,
            VsrObjective::MaxLoad as u32,
        ));
        assert_ok(vsr_assess_settings_set_load_pattern(
            s,
            pattern.as_ptr(),
            pattern.len(),
        ));
        assert_ok(vsr_assess_settings_set_unit_weight(s, 2.0));
        assert_ok(vsr_assess_settings_set_max_iterations(s, 60));
    }
    let a = run(mesh, e, s);
    let settings = AssessSettings::default()
        .with_objective(Objective::MaxLoad)
        .with_load_pattern(pattern)
        .with_unit_weight(2.0)
        .with_max_iterations(60);
    let r = assess(&Problem::new(rust), &env, &settings, None).unwrap();
    assert!(r.feasible && r.load_factor > 0.0);
    assert_same(a, &r);
    check_certificate(a, &d.anchored);
    unsafe {
        vsr_assessment_destroy(a);
        vsr_assess_settings_destroy(s);
        vsr_envelope_destroy(e);
        vsr_mesh_destroy(mesh);
    }
}

#[test]
fn envelopes_reject_hostile_input_and_leave_out_untouched() {
    let d = Dome::new(3, 12);
    let mesh = d.create();
    let t = [0.1];
    let bad_count = [0.1; 5];
    let cases: [(*const VsrMesh, *const f64, usize, S, &str); 7] = [
        (null(), t.as_ptr(), 1, S::NullPointer, "mesh"),
        (mesh, null(), 1, S::NullPointer, "thickness"),
        (mesh, t.as_ptr(), 0, S::InvalidArgument, "n_thickness"),
        (
            mesh,
            bad_count.as_ptr(),
            5,
            S::InvalidArgument,
            "n_thickness",
        ),
        (mesh, [f64::NAN].as_ptr(), 1, S::NonFinite, "thickness"),
        (mesh, [0.0].as_ptr(), 1, S::InvalidArgument, "thickness"),
        (mesh, [-1.0].as_ptr(), 1, S::InvalidArgument, "thickness"),
    ];
    for (m, p, n, status, name) in cases {
        let mut out = sentinel();
        assert_failed(
            unsafe { vsr_envelope_from_thickness(m, p, n, &mut out) },
            status,
            name,
        );
        assert_eq!(out, sentinel());
    }
    let s = unsafe { vsr_envelope_from_thickness(mesh, t.as_ptr(), 1, null_mut()) };
    assert_failed(s, S::NullPointer, "out");
    // A per-face thickness of 0 names its face.
    let mut faces = vec![0.1; d.n_triangles()];
    faces[7] = 0.0;
    let mut out = sentinel();
    let s = unsafe { vsr_envelope_from_thickness(mesh, faces.as_ptr(), faces.len(), &mut out) };
    assert_failed(s, S::InvalidArgument, "thickness");
    assert!(last_error().contains("face 7"), "{}", last_error());

    let (lower, upper) = (shifted(-0.05, 1.05), shifted(0.05, 1.05));
    let mut nan = lower.clone();
    nan.0[4] = f64::NAN;
    let mut far = lower.clone();
    far.1[5] = 10_000;
    let small = shifted(0.05, 0.5);
    let surface_cases: [(&Flat, &Flat, S, &str, &str); 5] = [
        (&nan, &upper, S::NonFinite, "intrados", "vertex 1"),
        (
            &far,
            &upper,
            S::IndexOutOfRange,
            "intrados_triangles",
            "triangle 1",
        ),
        (
            &upper,
            &lower,
            S::InvalidArgument,
            "intrados",
            "lies above the extrados",
        ),
        (
            &lower,
            &small,
            S::InvalidArgument,
            "extrados",
            "does not cover vertex",
        ),
        (
            &lower,
            &(vec![], vec![]),
            S::InvalidArgument,
            "extrados",
            "does not cover vertex",
        ),
    ];
    for (lo, hi, status, name, detail) in surface_cases {
        let mut out = sentinel();
        assert_failed(
            unsafe { from_surfaces(mesh, lo, hi, &mut out) },
            status,
            name,
        );
        assert!(last_error().contains(detail), "{}", last_error());
        assert_eq!(out, sentinel());
    }
    let mut out = sentinel();
    let (p, tri) = (lower.0.as_ptr(), lower.1.as_ptr());
    let (up, ut) = (upper.0.as_ptr(), upper.1.as_ptr());
    let (nv, nt) = (lower.0.len() / 3, lower.1.len() / 3);
    let hostile: [(*const f64, usize, *const u32, usize, S, &str); 4] = [
        (null(), nv, tri, nt, S::NullPointer, "intrados_positions"),
        (p, nv, null(), nt, S::NullPointer, "intrados_triangles"),
        (
            p,
            usize::MAX,
            tri,
            nt,
            S::LengthOverflow,
            "intrados_positions",
        ),
        (
            p,
            nv,
            tri,
            usize::MAX / 2,
            S::LengthOverflow,
            "intrados_triangles",
        ),
    ];
    for (p, nv, t, nt, status, name) in hostile {
        let s = unsafe { vsr_envelope_from_surfaces(mesh, p, nv, t, nt, up, nv, ut, nt, &mut out) };
        assert_failed(s, status, name);
        assert_eq!(out, sentinel());
    }
    // Getters.
    let e = envelope_of(mesh, &t);
    let mut short = [0.0; 3];
    let mut needed = 0;
    let s = unsafe { vsr_envelope_lower(e, short.as_mut_ptr(), 3, &mut needed) };
    assert_failed(s, S::BufferTooSmall, "len");
    assert_eq!((needed, short), (d.n_vertices(), [0.0; 3]));
    let s = unsafe { vsr_envelope_upper(null(), short.as_mut_ptr(), 3, &mut needed) };
    assert_failed(s, S::NullPointer, "envelope");
    unsafe {
        vsr_envelope_destroy(e);
        vsr_envelope_destroy(null_mut());
        vsr_mesh_destroy(mesh);
    }
}

#[test]
fn assess_settings_setters_reject_bad_values_and_keep_the_previous_ones() {
    let s = assess_settings();
    type Call = Box<dyn Fn(*mut VsrAssessSettings) -> VsrStatus>;
    let inf = [f64::INFINITY];
    let cases: Vec<(Call, S, &str)> = vec![
        (
            Box::new(|s| unsafe { vsr_assess_settings_set_objective(s, 5) }),
            S::InvalidEnum,
            "objective",
        ),
        (
            Box::new(|s| unsafe { vsr_assess_settings_set_fixed_supports(s, 2) }),
            S::InvalidArgument,
            "fixed",
        ),
        (
            Box::new(|s| unsafe { vsr_assess_settings_set_unit_weight(s, -1.0) }),
            S::InvalidArgument,
            "unit_weight",
        ),
        (
            Box::new(|s| unsafe { vsr_assess_settings_set_unit_weight(s, f64::NAN) }),
            S::NonFinite,
            "unit_weight",
        ),
        (
            Box::new(|s| unsafe { vsr_assess_settings_set_load_rule(s, 3) }),
            S::InvalidEnum,
            "rule",
        ),
        (
            Box::new(|s| unsafe { vsr_assess_settings_set_load_pattern(s, null(), 4) }),
            S::NullPointer,
            "loads",
        ),
        (
            Box::new(move |s| unsafe { vsr_assess_settings_set_load_pattern(s, inf.as_ptr(), 1) }),
            S::NonFinite,
            "loads",
        ),
        (
            Box::new(|s| unsafe { vsr_assess_settings_set_q_min(s, -1.0, 0) }),
            S::InvalidArgument,
            "value",
        ),
        (
            Box::new(|s| unsafe { vsr_assess_settings_set_q_min(s, 0.0, 2) }),
            S::InvalidEnum,
            "kind",
        ),
        (
            Box::new(|s| unsafe { vsr_assess_settings_set_tolerance(s, 1.5) }),
            S::InvalidArgument,
            "tolerance",
        ),
        (
            Box::new(|s| unsafe { vsr_assess_settings_set_max_iterations(s, 0) }),
            S::InvalidArgument,
            "max_iterations",
        ),
        (
            Box::new(|_| unsafe { vsr_assess_settings_set_objective(null_mut(), 0) }),
            S::NullPointer,
            "settings",
        ),
    ];
    for (call, status, name) in cases {
        assert_failed(call(s), status, name);
    }
    assert_failed(
        unsafe { vsr_assess_settings_set_objective(s, 5) },
        S::InvalidEnum,
        "objective",
    );
    assert!(
        last_error().contains("VSR_OBJECTIVE_MAX_LOAD (4)"),
        "{}",
        last_error()
    );
    // The settings kept their defaults: a fit of the dome gives the Rust default's answer.
    let d = Dome::new(3, 12);
    let mesh = d.create();
    let e = envelope_of(mesh, &[0.1]);
    let a = run(mesh, e, s);
    let rust = rust_mesh(&d);
    let env = Envelope::from_thickness(&rust, &Thickness::Uniform(0.1)).unwrap();
    let r = assess(&Problem::new(rust), &env, &AssessSettings::default(), None).unwrap();
    assert_same(a, &r);
    unsafe {
        vsr_assessment_destroy(a);
        vsr_envelope_destroy(e);
        vsr_mesh_destroy(mesh);
        vsr_assess_settings_destroy(s);
        vsr_assess_settings_destroy(null_mut());
    }
}

#[test]
fn assess_rejects_null_handles_and_mismatched_input() {
    let d = Dome::new(3, 12);
    let mesh = d.create();
    let other = Dome::new(2, 8).create();
    let e = envelope_of(mesh, &[0.1]);
    let e_other = envelope_of(other, &[0.1]);
    let s = assess_settings();
    let cases: [(
        *const VsrMesh,
        *const VsrEnvelope,
        *const VsrAssessSettings,
        S,
        &str,
    ); 4] = [
        (null(), e, s, S::NullPointer, "mesh"),
        (mesh, null(), s, S::NullPointer, "envelope"),
        (mesh, e, null(), S::NullPointer, "settings"),
        (mesh, e_other, s, S::InvalidArgument, "envelope"),
    ];
    for (m, e, s, status, name) in cases {
        let mut out = sentinel();
        assert_failed(unsafe { vsr_assess(m, e, s, &mut out) }, status, name);
        assert_eq!(out, sentinel());
    }
    assert_failed(
        unsafe { vsr_assess(mesh, e, s, null_mut()) },
        S::NullPointer,
        "out",
    );
    // max-load without a pattern, and a pattern of the wrong length.
    unsafe {
        assert_ok(vsr_assess_settings_set_objective(
            s,
            VsrObjective::MaxLoad as u32,
        ));
        let mut out = sentinel();
        assert_failed(
            vsr_assess(mesh, e, s, &mut out),
            S::InvalidArgument,
            "load_pattern",
        );
        assert_ok(vsr_assess_settings_set_load_pattern(
            s,
            [1.0, 2.0].as_ptr(),
            2,
        ));
        assert_failed(
            vsr_assess(mesh, e, s, &mut out),
            S::InvalidArgument,
            "load_pattern",
        );
        assert!(last_error().contains("has 2 entries"), "{}", last_error());
        assert_eq!(out, sentinel());
    }
    unsafe {
        vsr_assess_settings_destroy(s);
        vsr_envelope_destroy(e);
        vsr_envelope_destroy(e_other);
        vsr_mesh_destroy(mesh);
        vsr_mesh_destroy(other);
    }
}

#[test]
fn assessment_getters_check_pointers_and_buffers() {
    let d = Dome::new(3, 12);
    let mesh = d.create();
    let e = envelope_of(mesh, &[0.1]);
    let s = assess_settings();
    let a = run(mesh, e, s);
    let mut x = [7.0f64; 4];
    let (mut u, mut t, mut i, mut w) = (7u32, VsrTermination::Blocked, 7usize, 7u32);
    unsafe {
        let [x0, x1, x2, x3] = &mut x;
        assert_failed(
            vsr_assessment_figures(a, x0, x1, null_mut(), x3),
            S::NullPointer,
            "thrust_horizontal",
        );
        assert_failed(
            vsr_assessment_figures(null(), x0, x1, x2, x3),
            S::NullPointer,
            "assessment",
        );
        assert_failed(
            vsr_assessment_outcome(a, &mut u, &mut t, &mut i, null_mut()),
            S::NullPointer,
            "seconds",
        );
        assert_failed(
            vsr_assessment_certificate(a, x0, x1, x2, &mut w, null_mut()),
            S::NullPointer,
            "worst_residual_vertex",
        );
        assert_failed(
            vsr_assessment_objective(a, null_mut()),
            S::NullPointer,
            "out",
        );
        assert_failed(
            vsr_assessment_worst_joint(a, x0, null_mut()),
            S::NullPointer,
            "vertex",
        );
        assert_failed(
            vsr_assessment_unbounded(a, null_mut()),
            S::NullPointer,
            "unbounded",
        );
    }
    assert_eq!(
        (x, u, t, i, w),
        ([7.0; 4], 7, VsrTermination::Blocked, 7, 7)
    );
    let mut short = [0.5; 10];
    let mut needed = 0;
    let s2 = unsafe { vsr_assessment_positions(a, short.as_mut_ptr(), 10, &mut needed) };
    assert_failed(s2, S::BufferTooSmall, "len");
    assert_eq!((needed, short), (3 * d.n_vertices(), [0.5; 10]));
    let s2 = unsafe { vsr_assessment_loads(a, null_mut(), 5, &mut needed) };
    assert_failed(s2, S::NullPointer, "out");
    let mut text = vec![0 as std::ffi::c_char; 200];
    assert_ok(unsafe {
        vsr_assessment_termination_message(a, text.as_mut_ptr(), 200, &mut needed)
    });
    let message = unsafe { CStr::from_ptr(text.as_ptr()) }.to_str().unwrap();
    assert!(message.starts_with("converged"), "{message}");
    assert_eq!(needed, message.len() + 1);
    unsafe {
        vsr_assessment_destroy(a);
        vsr_assessment_destroy(null_mut());
        vsr_assess_settings_destroy(s);
        vsr_envelope_destroy(e);
        vsr_mesh_destroy(mesh);
    }
}

unsafe extern "C" fn count_then_cancel(
    user: *mut c_void,
    step: usize,
    infeasibility: f64,
) -> c_int {
    let seen = unsafe { &mut *(user as *mut Vec<(usize, f64)>) };
    seen.push((step, infeasibility));
    c_int::from(seen.len() >= 3)
}

#[test]
fn the_progress_callback_sees_each_step_and_can_cancel() {
    let d = Dome::new(3, 12);
    let mesh = d.create();
    let e = envelope_of(mesh, &[0.1]);
    let s = assess_settings();
    let mut seen: Vec<(usize, f64)> = Vec::new();
    unsafe {
        assert_ok(vsr_assess_settings_set_objective(
            s,
            VsrObjective::MinThrust as u32,
        ));
        let user = &mut seen as *mut Vec<(usize, f64)> as *mut c_void;
        assert_ok(vsr_assess_settings_set_progress(
            s,
            Some(count_then_cancel),
            user,
        ));
    }
    let a = run(mesh, e, s);
    assert_eq!(seen.iter().map(|s| s.0).collect::<Vec<_>>(), [1, 2, 3]);
    assert!(seen.iter().all(|s| s.1.is_finite() && s.1 >= 0.0));
    let (mut f, mut t, mut i, mut sec) = (0, VsrTermination::Converged, 0, 0.0);
    assert_ok(unsafe { vsr_assessment_outcome(a, &mut f, &mut t, &mut i, &mut sec) });
    // The callback sees the start's steps too (the first certified surface of fit's
    // search), numbered with the main search's as one sequence: three steps in all.
    assert_eq!(t, VsrTermination::Cancelled);
    assert_eq!(i, 3);
    unsafe {
        vsr_assessment_destroy(a);
        vsr_assess_settings_destroy(s);
        vsr_envelope_destroy(e);
        vsr_mesh_destroy(mesh);
    }
}

/// The family of the family tests: a middle surface tilted away from the dome by 0.15 t x,
/// so that it does not stand at every thickness.
fn tilted_bounds(d: &Dome, t: f64) -> (Vec<f64>, Vec<f64>) {
    (d.positions.chunks_exact(3))
        .map(|p| (p[2] - 0.5 * t, p[2] + t * (0.5 + 0.3 * p[0])))
        .unzip()
}

unsafe extern "C" fn tilted_family(
    user: *mut c_void,
    t: f64,
    lower: *mut f64,
    upper: *mut f64,
    n: usize,
) -> c_int {
    // SAFETY: `user` is the test's Dome; lower and upper hold n values.
    let d = unsafe { &*(user as *const Dome) };
    let (lo, hi) = tilted_bounds(d, t);
    assert_eq!(n, lo.len());
    unsafe {
        std::ptr::copy_nonoverlapping(lo.as_ptr(), lower, n);
        std::ptr::copy_nonoverlapping(hi.as_ptr(), upper, n);
    }
    0
}

unsafe extern "C" fn refusing_family(
    _: *mut c_void,
    _: f64,
    _: *mut f64,
    _: *mut f64,
    _: usize,
) -> c_int {
    7
}

#[test]
fn the_least_thickness_of_a_family_is_the_rust_api_s() {
    let d = Dome::new(3, 12);
    let mesh = d.create();
    let s = assess_settings();
    let user = &d as *const Dome as *mut c_void;
    let (mut a, mut t, mut converged) = (null_mut(), f64::NAN, 9);
    assert_ok(unsafe {
        vsr_min_thickness_of_family(
            mesh,
            Some(tilted_family),
            user,
            0.1,
            1e-3,
            s,
            &mut a,
            &mut t,
            &mut converged,
        )
    });
    let rust_mesh = rust_mesh(&d);
    let member = |t: f64| {
        let (lo, hi) = tilted_bounds(&d, t);
        Envelope::from_bounds(&rust_mesh, lo, hi, &Thickness::Uniform(t))
    };
    let problem = Problem::new(rust_mesh.clone());
    let want =
        voussoir::min_thickness_of_family(&problem, member, 0.1, 1e-3, &AssessSettings::default())
            .unwrap();
    assert_eq!(t.to_bits(), want.thickness.to_bits());
    assert_eq!(converged, c_int::from(want.converged));
    assert!(t > 0.0 && want.result.feasible);
    assert_same(a, &want.result);
    check_certificate(a, &d.anchored);
    unsafe { vsr_assessment_destroy(a) };

    type Family = VsrEnvelopeAtFn;
    let cases: [(Family, f64, f64, S, &str); 4] = [
        (None, 0.1, 1e-3, S::NullPointer, "envelope_at"),
        (
            Some(refusing_family),
            0.1,
            1e-3,
            S::InvalidArgument,
            "envelope_at",
        ),
        (
            Some(tilted_family),
            -1.0,
            1e-3,
            S::InvalidArgument,
            "thickness",
        ),
        (
            Some(tilted_family),
            0.1,
            0.0,
            S::InvalidArgument,
            "scale_tolerance",
        ),
    ];
    for (family, t0, tol, status, name) in cases {
        let (mut a, mut t, mut converged) = (sentinel(), 42.0, 42);
        let got = unsafe {
            vsr_min_thickness_of_family(
                mesh,
                family,
                user,
                t0,
                tol,
                s,
                &mut a,
                &mut t,
                &mut converged,
            )
        };
        assert_failed(got, status, name);
        assert!(
            a == sentinel() && t == 42.0 && converged == 42,
            "outputs written"
        );
    }
    unsafe {
        vsr_assess_settings_destroy(s);
        vsr_mesh_destroy(mesh);
    }
}

/// The C envelope's springing joints, read back and run through `vsr_assess`, against the
/// Rust `Envelope::with_springing`: defaults copied out, a narrow joint, and no joint.
#[test]
fn springing_joints_set_in_c_assess_as_the_rust_api_does() {
    let d = Dome::new(3, 12);
    let mesh = d.create();
    let rust = Problem::new(rust_mesh(&d));
    let env = Envelope::from_thickness(&rust.mesh, &Thickness::Uniform(0.1)).unwrap();
    let e = envelope_of(mesh, &[0.1]);
    assert_eq!(
        bits(&envelope_doubles(e, vsr_envelope_springing)),
        bits(&env.springing)
    );
    assert_eq!(
        bits(&envelope_doubles(e, vsr_envelope_reach)),
        bits(&env.reach)
    );
    let s = assess_settings();
    let objective = VsrObjective::MaxThrust as u32;
    assert_ok(unsafe { vsr_assess_settings_set_objective(s, objective) });
    let settings = AssessSettings::default().with_objective(Objective::MaxThrust);
    let default = assess(&rust, &env, &settings, None).unwrap();
    let narrow: Vec<f64> = env.reach.iter().map(|b| 0.2 * b).collect();
    let none = vec![f64::INFINITY; env.reach.len()];
    let mut thrusts = Vec::new();
    // Without a joint, the plane (0.01 below the middle surface) only bounds the support.
    let lowered: Vec<f64> = env.springing.iter().map(|z| z - 0.01).collect();
    for (springing, reach) in [(env.springing.clone(), narrow), (lowered, none)] {
        assert_ok(unsafe {
            vsr_envelope_set_springing(
                e,
                springing.as_ptr(),
                springing.len(),
                reach.as_ptr(),
                reach.len(),
            )
        });
        assert_eq!(
            bits(&envelope_doubles(e, vsr_envelope_springing)),
            bits(&springing)
        );
        assert_eq!(bits(&envelope_doubles(e, vsr_envelope_reach)), bits(&reach));
        let a = run(mesh, e, s);
        let joints = env.clone().with_springing(springing, reach).unwrap();
        let r = assess(&rust, &joints, &settings, None).unwrap();
        assert!(r.feasible);
        assert_same(a, &r);
        check_certificate(a, &d.anchored);
        thrusts.push(r.thrust_horizontal);
        unsafe { vsr_assessment_destroy(a) };
    }
    // A narrow joint holds the greatest thrust below the default joint's; without a joint
    // the reaction may lean further, above it.
    let most = default.thrust_horizontal;
    assert!(thrusts[0] < most * (1.0 - 1e-3), "{thrusts:?} vs {most}");
    assert!(thrusts[1] > most * (1.0 + 1e-3), "{thrusts:?} vs {most}");
    unsafe {
        vsr_assess_settings_destroy(s);
        vsr_envelope_destroy(e);
        vsr_mesh_destroy(mesh);
    }
}

/// Bad springing joints get the right status and a message naming the argument and the
/// vertex; the envelope keeps its joints.
#[test]
fn bad_springing_joints_are_named_and_leave_the_envelope_unchanged() {
    let d = Dome::new(3, 12);
    let mesh = d.create();
    let e = envelope_of(mesh, &[0.1]);
    let (springing, reach) = (
        envelope_doubles(e, vsr_envelope_springing),
        envelope_doubles(e, vsr_envelope_reach),
    );
    let n = springing.len();
    let upper = envelope_doubles(e, vsr_envelope_upper);
    let with = |k: usize, v: f64, of: &[f64]| {
        let mut out = of.to_vec();
        out[k] = v;
        out
    };
    let cases: [(Vec<f64>, Vec<f64>, &str, &str); 6] = [
        (
            springing[..n - 1].to_vec(),
            reach.clone(),
            "springing",
            "entries",
        ),
        (
            springing.clone(),
            reach[..n - 1].to_vec(),
            "reach",
            "entries",
        ),
        (
            with(4, f64::NAN, &springing),
            reach.clone(),
            "springing",
            "vertex 4",
        ),
        (
            with(5, upper[5] + 0.01, &springing),
            reach.clone(),
            "springing",
            "vertex 5",
        ),
        (
            springing.clone(),
            with(6, -0.1, &reach),
            "reach",
            "vertex 6",
        ),
        (
            springing.clone(),
            with(7, f64::NAN, &reach),
            "reach",
            "vertex 7",
        ),
    ];
    for (s, r, name, what) in cases {
        let status =
            unsafe { vsr_envelope_set_springing(e, s.as_ptr(), s.len(), r.as_ptr(), r.len()) };
        assert_failed(status, S::InvalidArgument, name);
        assert!(last_error().contains(what), "{}", last_error());
        assert_eq!(
            bits(&envelope_doubles(e, vsr_envelope_springing)),
            bits(&springing)
        );
        assert_eq!(bits(&envelope_doubles(e, vsr_envelope_reach)), bits(&reach));
    }
    let status =
        unsafe { vsr_envelope_set_springing(null_mut(), springing.as_ptr(), n, reach.as_ptr(), n) };
    assert_failed(status, S::NullPointer, "envelope");
    let status = unsafe { vsr_envelope_set_springing(e, null(), n, reach.as_ptr(), n) };
    assert_failed(status, S::NullPointer, "springing");
    unsafe {
        vsr_envelope_destroy(e);
        vsr_mesh_destroy(mesh);
    }
}
