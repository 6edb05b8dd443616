//! docs/method.md §14 items 3, 4 and 5: the reduced optimum equals the edge-based (VHWP12)
//! optimum, a 45° cap stands from the stress step alone while a hemisphere does not, and the
//! answer is invariant under rigid motions and scales with uniform scaling.

mod common;
use common::{holed_disk, load_model, polar_cap, MODELS};
use voussoir::generate;
use voussoir::*;

/// Plain compression (q ≥ 0, and q_min on interior edges only where a test sets it): the
/// setting most of these tests are about; the default q_min is 0.05 p̄/L₀ on all edges.
fn plain_compression() -> StressSettings {
    StressSettings::default()
        .with_q_min(QBound::Absolute(0.0))
        .with_q_min_scope(EdgeScope::Interior)
}

fn solve(problem: &Problem, settings: &StressSettings, formulation: Formulation) -> StressResult {
    let s = settings.clone().with_formulation(formulation);
    analyse(problem, &s).unwrap()
}

/// Both formulations reach the same optimum: same objective and same residual vector (both are
/// unique at the optimum, unlike q when ‖r‖² is flat), each a valid compressive stress.
fn assert_same_optimum(
    label: &str,
    problem: &Problem,
    settings: &StressSettings,
) -> (StressResult, StressResult) {
    let red = solve(problem, settings, Formulation::Reduced);
    let edge = solve(problem, settings, Formulation::EdgeBased);
    assert_same_results(label, problem, red, edge)
}

/// Two results of the same problem are the same optimum (see [`assert_same_optimum`]).
fn assert_same_results(
    label: &str,
    problem: &Problem,
    red: StressResult,
    edge: StressResult,
) -> (StressResult, StressResult) {
    assert!(
        red.status.is_solved() && edge.status.is_solved(),
        "{label}: {:?} / {:?}",
        red.status,
        edge.status
    );
    let mesh = &problem.mesh;
    let free: Vec<usize> = (0..mesh.positions().len())
        .filter(|&v| mesh.is_non_anchored(v))
        .collect();
    let p_bar = free.iter().map(|&v| red.loads[v]).sum::<f64>() / free.len() as f64;
    let scale = free.iter().map(|&v| red.loads[v].powi(2)).sum::<f64>();
    assert!(
        (red.objective - edge.objective).abs() <= 1e-6 * edge.objective + 1e-9 * scale,
        "{label}: objective reduced {:e} vs edge-based {:e}",
        red.objective,
        edge.objective
    );
    // ‖r‖² is strongly convex: ‖r_red − r_edge‖² ≤ |f_red − f*| + |f_edge − f*| ≤ 2e-6 f*, so
    // equal objectives to 1e-6 force residual vectors equal to ~1.5e-3 √f*.
    let dr = free
        .iter()
        .map(|&v| (red.residuals[v] - edge.residuals[v]).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(
        dr <= 1.5e-3 * edge.objective.sqrt() + 1e-6 * p_bar,
        "{label}: residual vectors differ by {dr:e} (objective {:e}, p̄ {p_bar:e})",
        edge.objective
    );
    let (lo, hi) = mesh
        .positions()
        .iter()
        .fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        });
    let natural_q = p_bar / ((hi[0] - lo[0]).hypot(hi[1] - lo[1]) / 2.0);
    for (name, r) in [("reduced", &red), ("edge-based", &edge)] {
        let q_scale = r
            .force_densities
            .iter()
            .fold(natural_q, |m, q| m.max(q.abs()));
        let min_q = r
            .force_densities
            .iter()
            .fold(f64::INFINITY, |m, q| m.min(*q));
        assert!(
            min_q >= -1e-7 * q_scale,
            "{label} {name}: tension {min_q:e} (largest |q| {q_scale:e})"
        );
        let h = free
            .iter()
            .map(|&v| {
                r.horizontal_imbalance[v][0]
                    .abs()
                    .max(r.horizontal_imbalance[v][1].abs())
            })
            .fold(0.0, f64::max);
        assert!(
            h <= 1e-6 * p_bar,
            "{label} {name}: horizontal imbalance {:e} p̄",
            h / p_bar
        );
    }
    println!(
        "{label}: V={} objective {:.6e} / {:.6e}, eps_inf {:.3e} / {:.3e}, {:.3}s / {:.3}s",
        mesh.positions().len(),
        red.objective,
        edge.objective,
        red.eps_inf,
        edge.eps_inf,
        red.seconds,
        edge.seconds
    );
    (red, edge)
}

#[test]
fn cap_of_45_degrees_stands_from_the_stress_step_alone_and_hemisphere_does_not() {
    let problem = Problem::new(polar_cap(12, std::f64::consts::FRAC_PI_4));
    let r = analyse(&problem, &plain_compression()).unwrap();
    assert_eq!(r.status, StressStatus::Solved);
    assert!(r.eps_inf < 1e-6, "45° cap: eps_inf {:e}", r.eps_inf);
    let hemi = Problem::new(polar_cap(12, std::f64::consts::FRAC_PI_2));
    let r = analyse(&hemi, &plain_compression()).unwrap();
    assert!(r.eps_inf > 1e-2, "hemisphere: eps_inf {:e}", r.eps_inf);
}

#[test]
fn reduced_equals_edge_based_on_generated_meshes() {
    let base = plain_compression();
    // Anchored rim, dome that does not quite stand (hemisphere-like rise).
    let hemi = Problem::new(polar_cap(10, 1.3));
    assert_same_optimum("anchored rim", &hemi, &base);
    // q_min > 0 on interior edges.
    let qmin = base.clone().with_q_min(QBound::Relative(0.05));
    assert_same_optimum("anchored rim, q_min", &hemi, &qmin);
    // With τ on free vertices a hole can take a net force: only affine jumps match VHWP12.
    let base = base.with_holes(HoleMode::Affine);
    // Free edges: only an arc of the rim is anchored; τ optimised and τ = 0.
    let arc = Problem::new(holed_disk(3, 0.01, |u, outer| outer && u[1] < -0.3));
    assert_same_optimum("free rim arc, tau optimised", &arc, &base);
    assert_same_optimum(
        "free rim arc, tau zero",
        &arc,
        &base.clone().with_tau(TauMode::Zero),
    );
    // A free hole (its loop has no support).
    let free_hole = Problem::new(holed_disk(4, 0.01, |_, outer| outer));
    assert_same_optimum("free hole", &free_hole, &base);
    // An anchored off-centre hole: a supported ring can take a net force and torque.
    let anchored = Problem::new(holed_disk(5, 0.01, |u, outer| {
        outer || (u[0] - 0.3).hypot(u[1] - 0.1) < 0.26
    }));
    let (red, _) = assert_same_optimum("anchored hole (affine jumps)", &anchored, &base);
    let constant = analyse(&anchored, &base.clone().with_holes(HoleMode::Constant)).unwrap();
    // Both may be zero to rounding (this hole can stand either way): compared down to that.
    let rounding = 1e-12 * red.loads.iter().map(|p| p * p).sum::<f64>();
    assert!(
        constant.objective >= red.objective * (1.0 - 1e-6) - rounding,
        "constant jumps cannot beat affine ones: {:e} < {:e}",
        constant.objective,
        red.objective
    );
    // Prescribed τ on the free arc, and an upper bound.
    let tau = Problem::new(holed_disk(3, 0.01, |u, outer| outer && u[1] < -0.3))
        .with_prescribed_tau(vec![0.002; arc.mesh.positions().len()])
        .unwrap();
    assert_same_optimum(
        "prescribed tau",
        &tau,
        &base.clone().with_tau(TauMode::Prescribed),
    );
    assert_same_optimum(
        "q_max",
        &hemi,
        &base.clone().with_q_max(Some(QBound::Relative(1.0))),
    );
}

#[test]
fn reduced_equals_edge_based_on_every_real_model() {
    let settings = plain_compression().with_holes(HoleMode::Affine);
    for name in MODELS {
        let Some(mesh) = load_model(name) else { return };
        assert_same_optimum(name, &Problem::new(mesh), &settings);
    }
}

/// With default settings the reduced stress step of every shared model with holes reaches the
/// edge-based optimum: the default hole jumps are affine (constant ones miss it where hole rings
/// are anchored or loaded by τ, as on four_holes).
#[test]
fn default_stress_step_of_holed_models_is_the_edge_based_optimum() {
    let mut holed = Vec::new();
    for name in MODELS {
        let Some(mesh) = load_model(name) else { return };
        if mesh.holes().count() == 0 {
            continue;
        }
        assert_same_optimum(name, &Problem::new(mesh), &StressSettings::default());
        holed.push(name);
    }
    for name in ["four_holes", "hex", "cheese"] {
        assert!(holed.contains(&name), "{name} has holes");
    }
}

/// The structured interior-point solver reaches the optimum of clarabel (the reference) on
/// every real model, in both formulations, with plain compression and with the form-finding
/// bound q_min, and answers itself (four_holes' reduced QPs, with free holes of 4–6
/// vertices, depend on the Airy gauge being spread over the mesh).
#[test]
fn native_solver_equals_clarabel_on_every_real_model() {
    let plain = plain_compression();
    let q_min = StressSettings::default()
        .with_q_min(QBound::Relative(0.05))
        .with_q_min_scope(EdgeScope::All);
    for name in MODELS {
        let Some(mesh) = load_model(name) else { return };
        let problem = Problem::new(mesh);
        for (formulation, base) in [
            (Formulation::Reduced, &plain),
            (Formulation::EdgeBased, &plain),
            (Formulation::Reduced, &q_min),
        ] {
            let with = |solver| {
                base.clone()
                    .with_solver(solver)
                    .with_formulation(formulation)
            };
            let native = analyse(&problem, &with(QpSolver::Native)).unwrap();
            let reference = analyse(&problem, &with(QpSolver::Clarabel)).unwrap();
            assert_eq!(reference.solver, QpSolver::Clarabel);
            let label = format!("{name} {formulation:?} q_min {:?}", base.q_min);
            assert_eq!(native.solver, QpSolver::Native, "{label}: fell back");
            assert_eq!(native.formulation, formulation, "{label}");
            assert_same_results(&label, &problem, native, reference);
        }
    }
}

/// The same on generated meshes with free rims, holes and q_min.
#[test]
fn native_solver_equals_clarabel_on_generated_meshes() {
    let base = plain_compression();
    let qmin = base
        .clone()
        .with_q_min(QBound::Relative(0.05))
        .with_q_min_scope(EdgeScope::All);
    let cases = [
        ("cap, anchored rim", polar_cap(10, 1.2), base.clone()),
        ("cap, q_min", polar_cap(10, 1.2), qmin.clone()),
        (
            "holed disk, free hole",
            holed_disk(3, 0.004, |_, outer| outer),
            base.clone(),
        ),
        (
            "holed disk, free arc",
            holed_disk(4, 0.004, |u, outer| outer && u[1] > -0.3),
            qmin,
        ),
    ];
    for (label, mesh, settings) in cases {
        let problem = Problem::new(mesh);
        let with = |solver| settings.clone().with_solver(solver);
        let native = analyse(&problem, &with(QpSolver::Native)).unwrap();
        let reference = analyse(&problem, &with(QpSolver::Clarabel)).unwrap();
        assert_eq!(native.solver, QpSolver::Native, "{label}: fell back");
        assert_same_results(label, &problem, native, reference);
    }
}

/// Σ (d*_a − d*_b)² over pairs of interior edges sharing a face, d* = q × plan length:
/// recomputed here from the returned force densities.
fn dual_variation(problem: &Problem, q: &[f64]) -> f64 {
    let mesh = &problem.mesh;
    let x = mesh.positions();
    let dual = |e: u32| {
        let [a, b] = mesh.edges()[e as usize].v.map(|v| x[v as usize]);
        q[e as usize] * (a[0] - b[0]).hypot(a[1] - b[1])
    };
    let interior = |e: u32| !mesh.edges()[e as usize].is_boundary();
    let mut sum = 0.0;
    for f in mesh.faces() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            let (c, d) = (b, f[(k + 2) % 3]);
            let (e1, e2) = (
                mesh.edge_between(a, b).unwrap() as u32,
                mesh.edge_between(c, d).unwrap() as u32,
            );
            if interior(e1) && interior(e2) {
                sum += (dual(e1) - dual(e2)).powi(2);
            }
        }
    }
    sum
}

/// The dual-length smoothing penalty μ Σ (d*_a − d*_b)² / p̄²: every solver and formulation
/// reaches the same optimum of ‖r‖² + μ V (recomputed here), and the optimum trades residual
/// for a smoother force diagram.
#[test]
fn dual_length_smoothing_trades_residual_for_a_smoother_diagram() {
    let mut cases = vec![(
        "holed disk, free hole".to_string(),
        holed_disk(3, 0.004, |_, outer| outer),
    )];
    if let Some(mesh) = load_model("lilium") {
        cases.push(("lilium".to_string(), mesh));
    }
    let mu = 1.0;
    for (label, mesh) in cases {
        let problem = Problem::new(mesh);
        // Affine hole jumps: the reduced space then holds every balanced stress of a mesh with
        // free holes, as the edge-based one does.
        let base = plain_compression().with_holes(HoleMode::Affine);
        let plain = analyse(&problem, &base).unwrap();
        let smooth = |solver, formulation| {
            let s = base
                .clone()
                .with_dual_length_smoothing(mu)
                .with_solver(solver)
                .with_formulation(formulation);
            analyse(&problem, &s).unwrap()
        };
        let runs = [
            (
                "native reduced",
                smooth(QpSolver::Native, Formulation::Reduced),
            ),
            (
                "clarabel reduced",
                smooth(QpSolver::Clarabel, Formulation::Reduced),
            ),
            (
                "clarabel edge-based",
                smooth(QpSolver::Clarabel, Formulation::EdgeBased),
            ),
        ];
        let mesh = &problem.mesh;
        let free: Vec<usize> = (0..mesh.positions().len())
            .filter(|&v| mesh.is_non_anchored(v))
            .collect();
        let p_bar = free.iter().map(|&v| plain.loads[v]).sum::<f64>() / free.len() as f64;
        let total =
            |r: &StressResult| r.objective + mu * dual_variation(&problem, &r.force_densities);
        assert_eq!(runs[0].1.solver, QpSolver::Native, "{label}: fell back");
        let reference = total(&runs[2].1);
        // The plain optimum is feasible for the smoothed problem: no better than its optimum.
        assert!(
            reference <= total(&plain) * (1.0 + 1e-6),
            "{label}: not a minimum"
        );
        for (name, r) in &runs {
            assert!(r.status.is_solved(), "{label} {name}: {:?}", r.status);
            let j = total(r);
            assert!(
                (j - reference).abs() <= 1e-6 * reference + 1e-12 * p_bar * p_bar,
                "{label} {name}: objective {j:e} vs edge-based clarabel {reference:e}"
            );
        }
        let (v0, v1) = (
            dual_variation(&problem, &plain.force_densities),
            dual_variation(&problem, &runs[0].1.force_densities),
        );
        println!(
            "{label}: variation {v0:.3e} -> {v1:.3e}, residual {:.3e} -> {:.3e}",
            plain.objective, runs[0].1.objective
        );
        assert!(v1 < 0.5 * v0, "{label}: variation {v0:e} -> {v1:e}");
        assert!(runs[0].1.objective >= plain.objective * (1.0 - 1e-6));
    }
}

#[test]
fn rigid_motions_and_uniform_scaling_give_the_scaled_answer() {
    let mesh = holed_disk(7, 0.01, |u, outer| outer && u[0] < 0.5);
    let base = Problem::new(mesh.clone());
    let reference = analyse(&base, &plain_compression()).unwrap();
    let (angle, scale, shift) = (0.7f64, 3.5, [12.0, -4.0, 2.5]);
    let moved: Vec<[f64; 3]> = mesh
        .positions()
        .iter()
        .map(|p| {
            let (c, s) = (angle.cos(), angle.sin());
            [
                scale * (c * p[0] - s * p[1]) + shift[0],
                scale * (s * p[0] + c * p[1]) + shift[1],
                scale * p[2] + shift[2],
            ]
        })
        .collect();
    let anchored: Vec<u32> = (0..mesh.positions().len() as u32)
        .filter(|&v| mesh.anchored()[v as usize])
        .collect();
    let moved = Problem::new(Mesh::new(moved, mesh.faces().to_vec(), &anchored).unwrap());
    let r = analyse(&moved, &plain_compression()).unwrap();
    // Loads scale with area (s²), force densities with s, residuals with s², ε∞ not at all.
    let p_scale = reference.loads.iter().fold(0.0f64, |m, x| m.max(*x));
    for v in 0..mesh.positions().len() {
        assert!(
            (r.loads[v] - scale * scale * reference.loads[v]).abs()
                <= 1e-12 * scale * scale * p_scale
        );
        assert!(
            (r.residuals[v] - scale * scale * reference.residuals[v]).abs()
                <= 1e-6 * scale * scale * p_scale
        );
    }
    assert!((r.eps_inf - reference.eps_inf).abs() <= 1e-6 * reference.eps_inf.max(1e-3));
    let q_scale = reference
        .force_densities
        .iter()
        .fold(0.0f64, |m, q| m.max(*q));
    let dq = r
        .force_densities
        .iter()
        .zip(&reference.force_densities)
        .map(|(a, b)| (a - scale * b).abs())
        .fold(0.0, f64::max);
    assert!(
        dq <= 1e-4 * scale * q_scale,
        "force densities differ by {:e} of the largest",
        dq / (scale * q_scale)
    );
}

#[test]
fn invalid_settings_are_rejected_by_name() {
    let problem = Problem::new(polar_cap(3, 0.5));
    for (settings, name) in [
        (
            StressSettings::default().with_q_min(QBound::Absolute(f64::NAN)),
            "q_min",
        ),
        (
            StressSettings::default().with_q_min(QBound::Relative(-1.0)),
            "q_min",
        ),
        (
            StressSettings::default().with_q_max(Some(QBound::Absolute(0.0))),
            "q_max",
        ),
        (
            StressSettings::default()
                .with_q_min(QBound::Absolute(2.0))
                .with_q_max(Some(QBound::Absolute(1.0))),
            "q_max",
        ),
        (
            StressSettings::default().with_regularisation(f64::INFINITY),
            "regularisation",
        ),
        (
            StressSettings::default().with_dual_length_smoothing(-1.0),
            "dual_length_smoothing",
        ),
    ] {
        match analyse(&problem, &settings) {
            Err(Error::InvalidArgument { name: n, .. }) => assert_eq!(n, name),
            other => panic!(
                "{name}: expected InvalidArgument, got {:?}",
                other.map(|r| r.status)
            ),
        }
    }
}

/// The native QP's starting point measures every inequality row's slack in the caller's units
/// (all force densities): in the unit-norm scaling a free hole's rim edges, whose force
/// densities are their own unknowns, would start ~1/ℓ² below their optimum and cost a dozen
/// short steps on this 3.9k-vertex disk.
#[test]
fn native_qp_is_not_slowed_by_a_free_hole_rim() {
    let problem = Problem::new(holed_disk(7, 0.0006, |_, outer| outer));
    let r = analyse(&problem, &plain_compression()).unwrap();
    assert_eq!(r.solver, QpSolver::Native);
    assert!(r.iterations <= 19, "{} QP iterations", r.iterations);
}

/// Both formulations bound the same force densities, so the native QP starts them from the
/// same point, built in one unit of force density (`qp::START_UNIT`): they then follow the
/// same central path and take about as many iterations (with the median row scale as the
/// unit, the edge-based start would pull every force density far harder towards its bound).
#[test]
fn both_formulations_start_alike_and_take_about_as_many_iterations() {
    let problem = Problem::new(holed_disk(3, 0.004, |_, outer| outer));
    let (red, edge) = assert_same_native_optimum("holed disk", &problem);
    assert!(
        edge.iterations <= red.iterations + 5,
        "reduced {} against edge-based {} QP iterations",
        red.iterations,
        edge.iterations
    );
}

/// Beyond 20k unknowns the equality rows weigh less (`DELTA_EQ_LARGE`), so that the factor's
/// rounding does not hold the dual residual of the edge-based step on this 7k-vertex dome
/// (21k unknowns, two equality rows per free vertex) above its tolerance.
#[test]
fn the_edge_based_step_solves_a_seven_thousand_vertex_dome() {
    let mesh = generate::dome_with_hole(7200).unwrap();
    // The edge-based unknowns: a force density per edge that can carry one, a τ per free rim
    // vertex.
    let forces = (mesh.edges().iter())
        .filter(|e| !e.is_boundary() || e.v.iter().any(|&v| !mesh.anchored()[v as usize]))
        .count();
    let taus = (0..mesh.positions().len())
        .filter(|&v| mesh.is_free_boundary(v))
        .count();
    assert!(forces + taus > 20_000, "{forces} + {taus} unknowns");
    assert_same_native_optimum("7k dome with a hole", &Problem::new(mesh));
}

/// [`assert_same_optimum`] with affine hole jumps (so that both formulations have the same
/// feasible forces), each answered by the native solver and `Solved`.
fn assert_same_native_optimum(label: &str, problem: &Problem) -> (StressResult, StressResult) {
    let settings = plain_compression().with_holes(HoleMode::Affine);
    let (red, edge) = assert_same_optimum(label, problem, &settings);
    for r in [&red, &edge] {
        assert_eq!(
            (r.solver, r.status),
            (QpSolver::Native, StressStatus::Solved),
            "{label}"
        );
    }
    (red, edge)
}

/// The mesh's positions with every height multiplied by `factor`.
fn heights_scaled(mesh: &Mesh, factor: f64) -> Vec<[f64; 3]> {
    mesh.positions()
        .iter()
        .map(|p| [p[0], p[1], factor * p[2]])
        .collect()
}

/// One cache across stress steps gives the answers of fresh ones: reused for a moved shape of
/// the same mesh (the solve then starts from the previous step's active set), replaced when
/// the structure changes (an upper bound adds rows, another mesh), and reused after that.
/// The reduced operator it keeps is rebuilt whenever the plan, the supports or the hole mode
/// change (a moved plan keeps the normal matrix's structure).
#[test]
fn a_stress_cache_reused_or_replaced_gives_the_same_answers() {
    let dome = Problem::new(polar_cap(10, 1.3));
    let lowered = heights_scaled(&dome.mesh, 0.8);
    let stretched: Vec<[f64; 3]> = (dome.mesh.positions().iter())
        .map(|p| [1.3 * p[0], p[1] - 0.2 * p[0] * p[0], p[2]])
        .collect();
    let arc = Problem::new(holed_disk(3, 0.01, |u, outer| outer && u[1] < -0.3));
    let other_arc = Problem::new(holed_disk(3, 0.01, |u, outer| outer && u[0] < 0.3));
    assert_eq!(arc.mesh.faces(), other_arc.mesh.faces());
    assert_ne!(arc.mesh.anchored(), other_arc.mesh.anchored());
    let plain = plain_compression()
        .with_solver(QpSolver::Native)
        .with_q_min(QBound::Relative(0.05));
    let bounded = plain.clone().with_q_max(Some(QBound::Relative(1.0)));
    let constant = plain.clone().with_holes(HoleMode::Constant);
    let steps = [
        (&dome, dome.mesh.positions(), &plain),
        (&dome, &lowered[..], &plain),
        (&dome, &lowered, &bounded),
        (&arc, arc.mesh.positions(), &plain),
        (&dome, dome.mesh.positions(), &plain),
        (&dome, &lowered, &plain),
        (&dome, &stretched, &plain),
        (&arc, arc.mesh.positions(), &plain),
        (&other_arc, other_arc.mesh.positions(), &plain),
        (&other_arc, other_arc.mesh.positions(), &constant),
    ];
    let mut cache = internals::StressCache::default();
    for (k, &(problem, positions, settings)) in steps.iter().enumerate() {
        let cached =
            internals::analyse_cached(problem, positions, settings, None, &mut cache).unwrap();
        let fresh =
            internals::analyse_cached(problem, positions, settings, None, &mut Default::default())
                .unwrap();
        assert_eq!(cached.solver, QpSolver::Native, "step {k}");
        assert_same_results(&format!("step {k}"), problem, cached, fresh);
    }
}

/// A shape moved a little keeps nearly the same active bounds: started from the previous
/// step's active set, the solve reaches the optimum by active-set corrections alone, without
/// an interior-point iteration, and it is the optimum a cold solve finds.
#[test]
fn a_slightly_moved_shape_is_solved_from_the_previous_active_set() {
    let dome = Problem::new(polar_cap(10, 1.3));
    let settings = plain_compression()
        .with_solver(QpSolver::Native)
        .with_q_min(QBound::Relative(0.05));
    let mut cache = internals::StressCache::default();
    let first =
        internals::analyse_cached(&dome, dome.mesh.positions(), &settings, None, &mut cache)
            .unwrap();
    assert!(first.iterations > 0);
    let raised = heights_scaled(&dome.mesh, 1.01);
    let warm = internals::analyse_cached(&dome, &raised, &settings, None, &mut cache).unwrap();
    let cold = internals::analyse_cached(&dome, &raised, &settings, None, &mut Default::default())
        .unwrap();
    assert_eq!(warm.solver, QpSolver::Native);
    assert_eq!(warm.iterations, 0, "cold: {} iterations", cold.iterations);
    assert!(cold.iterations > 0);
    assert_same_results("warm vs cold", &dome, warm, cold);
}

/// Form finding's cache solves QPs beyond 20k unknowns to coarse optimality (relative gap
/// 1e-3) with the bounds held as tightly as ever, in fewer iterations than an exact solve;
/// below 20k unknowns it changes nothing.
#[test]
fn form_findings_cache_solves_only_large_qps_coarsely() {
    let settings = FormFindSettings::default().stress;
    let small = Problem::new(polar_cap(10, 1.3));
    let mut cache = internals::StressCache::for_form_finding();
    let cached =
        internals::analyse_cached(&small, small.mesh.positions(), &settings, None, &mut cache)
            .unwrap();
    let fresh = analyse(&small, &settings).unwrap();
    assert_eq!(cached.iterations, fresh.iterations);
    assert_eq!(cached.objective, fresh.objective);
    // Small QPs try the last active set even far from balance: the same QP again is solved
    // from it, without interior-point iterations.
    cache.far_from_balance(true);
    let again =
        internals::analyse_cached(&small, small.mesh.positions(), &settings, None, &mut cache)
            .unwrap();
    assert_eq!((again.status, again.iterations), (StressStatus::Solved, 0));

    let large = Problem::new(generate::cap_dome(0.8, 13_500).unwrap());
    assert!(large.mesh.positions().len() > 20_000);
    let mut cache = internals::StressCache::for_form_finding();
    let coarse =
        internals::analyse_cached(&large, large.mesh.positions(), &settings, None, &mut cache)
            .unwrap();
    let exact = analyse(&large, &settings).unwrap();
    for r in [&coarse, &exact] {
        assert_eq!(
            (r.status, r.solver),
            (StressStatus::Solved, QpSolver::Native)
        );
    }
    assert!(
        coarse.iterations < exact.iterations,
        "coarse {} iterations, exact {}",
        coarse.iterations,
        exact.iterations
    );
    let scale = coarse.loads.iter().map(|p| p * p).sum::<f64>();
    assert!(
        coarse.objective >= exact.objective - 1e-9 * scale
            && coarse.objective <= exact.objective * (1.0 + 1e-3) + 1e-9 * scale,
        "objective coarse {:e}, exact {:e}",
        coarse.objective,
        exact.objective
    );
    // The same compression: each answer's least force density (q_min binds), relative to the
    // median, over the edges with a bound (not both ends anchored).
    let mesh = &large.mesh;
    let bounded: Vec<usize> = (0..mesh.edges().len())
        .filter(|&e| {
            mesh.edges()[e]
                .v
                .iter()
                .any(|&v| !mesh.anchored()[v as usize])
        })
        .collect();
    let lowest = |r: &StressResult| {
        let mut q: Vec<f64> = bounded.iter().map(|&e| r.force_densities[e]).collect();
        q.sort_by(f64::total_cmp);
        q[0] / q[q.len() / 2]
    };
    eprintln!(
        "V={}: coarse {} iterations, objective {:e}, lowest q/median {:e}; exact {}, {:e}, {:e}",
        large.mesh.positions().len(),
        coarse.iterations,
        coarse.objective,
        lowest(&coarse),
        exact.iterations,
        exact.objective,
        lowest(&exact)
    );
    assert!(
        lowest(&exact) > 0.0 && lowest(&coarse) >= (1.0 - 1e-2) * lowest(&exact),
        "lowest q / median: coarse {:e}, exact {:e}",
        lowest(&coarse),
        lowest(&exact)
    );
}

/// The Airy function's jump around every hole, continued from face to face around the hole
/// with the force densities alone (the reciprocal diagram: crossing edge a→b from its left to
/// its right face, the gradient changes by −q J(b − a), J the quarter turn), as (c, a_x, a_y)
/// with M(u) = c + a·u, counter-clockwise around the hole. Independent of the solver's cuts.
fn airy_periods(mesh: &Mesh, q: &[f64]) -> Vec<[f64; 3]> {
    let u = |v: u32| {
        let p = mesh.positions()[v as usize];
        [p[0], p[1]]
    };
    let face_of_boundary_edge = |a: u32, b: u32| {
        let e = &mesh.edges()[mesh.edge_between(a, b).expect("loop edge")];
        e.left.or(e.right).expect("boundary edge has a face").face
    };
    let centroid = |t: u32| {
        let f = mesh.faces()[t as usize].map(u);
        [0, 1].map(|d| (f[0][d] + f[1][d] + f[2][d]) / 3.0)
    };
    let mut periods = Vec::new();
    for lp in mesh.loops().iter().filter(|l| !l.is_outer) {
        let vs = &lp.vertices;
        let k = vs.len();
        let mut face = face_of_boundary_edge(vs[k - 1], vs[0]);
        let start = centroid(face);
        let (mut point, mut grad, mut phi) = (start, [0.0; 2], 0.0);
        let mut path = vec![start];
        for i in 0..k {
            // Around vs[i]'s fan from the face of its incoming loop edge to that of its outgoing one.
            let (v, last) = (vs[i], face_of_boundary_edge(vs[i], vs[(i + 1) % k]));
            let mut came = mesh
                .edge_between(vs[(i + k - 1) % k], v)
                .expect("loop edge");
            while face != last {
                let e = mesh.faces()[face as usize]
                    .iter()
                    .filter(|&&x| x != v)
                    .map(|&x| mesh.edge_between(v, x).expect("face edge"))
                    .find(|&e| e != came)
                    .expect("fan edge");
                let edge = &mesh.edges()[e];
                let [a, b] = edge.v.map(u);
                let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
                phi += grad[0] * (m[0] - point[0]) + grad[1] * (m[1] - point[1]);
                let (l, r) = (edge.left.expect("interior"), edge.right.expect("interior"));
                let sign = if l.face == face { -1.0 } else { 1.0 };
                let jd = [-(b[1] - a[1]), b[0] - a[0]];
                grad = [0, 1].map(|d| grad[d] + sign * q[e] * jd[d]);
                face = if l.face == face { r.face } else { l.face };
                (point, came) = (m, e);
                path.push(m);
            }
        }
        phi += grad[0] * (start[0] - point[0]) + grad[1] * (start[1] - point[1]);
        // Shoelace area of the path: negative when it ran clockwise around the hole.
        let area: f64 = (0..path.len())
            .map(|i| {
                let (p, n) = (path[i], path[(i + 1) % path.len()]);
                p[0] * n[1] - n[0] * p[1]
            })
            .sum();
        let s = area.signum();
        let a = [s * grad[0], s * grad[1]];
        periods.push([s * phi - a[0] * start[0] - a[1] * start[1], a[0], a[1]]);
    }
    periods
}

/// The hole coefficients are the jumps of the Airy function around each hole, whichever way
/// the solver cut the domain: checked against the jumps integrated from the force densities
/// alone, on a disk with three anchored-rim holes in a row (the middle hole's cut ends on a
/// neighbouring hole), with constant and affine jumps, and on the cheese model (39 holes).
#[test]
fn hole_coefficients_are_the_airy_jumps_integrated_from_the_force_densities() {
    let holes = [-0.5, 0.0, 0.5].map(|x| generate::circle([x, 0.0], 0.12, 12));
    let domain = generate::Domain {
        outer: generate::circle([0.0, 0.0], 1.0, 48),
        holes: holes.to_vec(),
    };
    let (p, t) = generate::triangulate(&domain, 0.004).unwrap();
    let row = generate::lift(
        &p,
        &t,
        |u| generate::spherical_cap(1.0, 0.7, u[0].hypot(u[1])),
        |u, outer| outer || (u[1] > 0.05 && u[0].abs() < 0.7 && u[0].hypot(u[1]) < 0.9),
    )
    .unwrap();
    // The side holes are nearer the rim than the middle one, and nearer the middle one than
    // the rim: the cuts chain rim ← side ← middle ← other side.
    let cuts = voussoir::internals::cut_holes(&row).unwrap();
    assert!(
        cuts.iter().any(|c| c
            .ends_at_hole
            .is_some_and(|h| cuts[h].ends_at_hole.is_some())),
        "a cut ends on a hole whose cut ends on a hole"
    );
    let mut cases = vec![
        ("three holes, constant", row.clone(), HoleMode::Constant),
        ("three holes, affine", row, HoleMode::Affine),
        ("ringed hole, affine", ringed_hole(), HoleMode::Affine),
    ];
    if let Some(cheese) = load_model("cheese") {
        cases.push(("cheese, constant", cheese.clone(), HoleMode::Constant));
        cases.push(("cheese, affine", cheese, HoleMode::Affine));
    }
    for (label, mesh, holes) in cases {
        let problem = Problem::new(mesh);
        let settings = plain_compression().with_holes(holes);
        let r = analyse(&problem, &settings).unwrap();
        assert!(r.status.is_solved(), "{label}: {:?}", r.status);
        let expected = airy_periods(&problem.mesh, &r.force_densities);
        assert_eq!(expected.len(), r.hole_coefficients.len(), "{label}");
        // q = S y holds exactly, so the integrated jumps equal the returned ones to rounding:
        // c scales as q L², a as q L (L the mesh's plan diameter).
        let q_max = r.force_densities.iter().fold(0.0f64, |m, q| m.max(q.abs()));
        let (lo, hi) = problem.mesh.positions().iter().fold(
            ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
            |(lo, hi), p| {
                (
                    [lo[0].min(p[0]), lo[1].min(p[1])],
                    [hi[0].max(p[0]), hi[1].max(p[1])],
                )
            },
        );
        let diam = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
        let tol = 1e-9 * q_max * diam;
        let mut largest = 0.0f64;
        for (h, (got, want)) in r.hole_coefficients.iter().zip(&expected).enumerate() {
            largest = largest.max(want[0].abs());
            assert!(
                (got[0] - want[0]).abs() <= tol * diam
                    && (got[1] - want[1]).abs() <= tol
                    && (got[2] - want[2]).abs() <= tol,
                "{label}, hole {h}: returned {got:?}, integrated {want:?}"
            );
        }
        assert!(
            largest > 1e-5 * q_max * diam * diam,
            "{label}: the holes carry stress"
        );
        if holes == HoleMode::Affine {
            let a = expected.iter().fold(0.0f64, |m, p| m.max(p[1].hypot(p[2])));
            assert!(
                a > 1e-5 * q_max * diam,
                "{label}: a net force through a hole"
            );
        }
        // The jump across each cut is that around its hole plus those across the cuts ending
        // on its loop: where the cuts nest, it differs from the returned coefficients.
        let cuts = voussoir::internals::cut_holes(&problem.mesh).unwrap();
        let mut across = expected.clone();
        for _ in 0..cuts.len() {
            across = (0..cuts.len())
                .map(|h| {
                    cuts.iter()
                        .enumerate()
                        .fold(expected[h], |mut j, (c, cut)| {
                            if cut.ends_at_hole == Some(h) {
                                (0..3).for_each(|d| j[d] += across[c][d]);
                            }
                            j
                        })
                })
                .collect();
        }
        let nested = (0..cuts.len())
            .map(|h| (across[h][0] - expected[h][0]).abs())
            .fold(0.0, f64::max);
        assert!(
            nested > 1e-5 * q_max * diam * diam,
            "{label}: the cuts' jumps differ from the holes'"
        );
    }
}

/// A hole ringed by other holes, with no interior vertex between them, so that no path of
/// interior vertices leads from it to the outer loop: an 8 × 8 grid of vertices whose central
/// cell and seven cells around it are holes; the outer loop and the ring holes are anchored.
fn ringed_hole() -> Mesh {
    let holes = [
        [3, 3],
        [2, 1],
        [4, 1],
        [5, 3],
        [5, 5],
        [3, 5],
        [1, 5],
        [1, 3],
    ];
    let id = |x: u32, y: u32| y * 8 + x;
    let mut faces = Vec::new();
    for y in 0..7 {
        for x in 0..7 {
            if holes.contains(&[x, y]) {
                continue;
            }
            let [a, b, c, d] = [id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)];
            faces.extend([[a, b, c], [a, c, d]]);
        }
    }
    let positions: Vec<[f64; 3]> = (0..64)
        .map(|v| {
            let u = [(v % 8) as f64 / 3.5 - 1.0, (v / 8) as f64 / 3.5 - 1.0];
            [u[0], u[1], 1.0 - 0.3 * (u[0] * u[0] + u[1] * u[1])]
        })
        .collect();
    let ring_hole_corner = |x: u32, y: u32| {
        holes[1..]
            .iter()
            .any(|h| (h[0]..=h[0] + 1).contains(&x) && (h[1]..=h[1] + 1).contains(&y))
    };
    let anchored: Vec<u32> = (0..64)
        .filter(|&v| {
            let (x, y) = (v % 8, v / 8);
            x == 0 || y == 0 || x == 7 || y == 7 || ring_hole_corner(x, y)
        })
        .collect();
    Mesh::new(positions, faces, &anchored).unwrap()
}

/// The ringed hole is cut through the ring (its cut ends on a ring hole), and the reduced
/// optimum with affine jumps is the edge-based one.
#[test]
fn a_hole_ringed_by_holes_is_cut_through_the_ring() {
    let mesh = ringed_hole();
    assert_eq!(mesh.loops().iter().filter(|l| !l.is_outer).count(), 8);
    let centre_loop = mesh
        .loops()
        .iter()
        .position(|l| l.vertices.contains(&(3 * 8 + 3)))
        .unwrap();
    // No interior vertex next to the central hole: a cut to the outer loop alone would fail.
    for &v in &mesh.loops()[centre_loop].vertices {
        assert!(mesh.neighbours(v).all(|w| mesh.on_boundary()[w as usize]));
    }
    let cuts = voussoir::internals::cut_holes(&mesh).unwrap();
    let centre = cuts
        .iter()
        .find(|c| c.loop_index == centre_loop)
        .expect("the central hole's cut");
    assert_eq!(centre.path.len(), 2, "one edge to a ring hole");
    assert!(centre.ends_at_hole.is_some());
    let settings = plain_compression().with_holes(HoleMode::Affine);
    assert_same_optimum("ringed hole", &Problem::new(mesh), &settings);
}

/// A shape that stands is judged to stand: known self-supporting vaults (form-found to
/// ε∞ < 1e-6 and certified by their own forces) analysed afresh with the default settings give
/// ε∞ < 1e-6. The regulariser that makes q unique must not bias the residual past that, also
/// on finer meshes, where the equilibrium operator is worse conditioned.
#[test]
fn known_self_supporting_vaults_are_found_to_stand() {
    use generate::KnownPlan;
    for plan in [KnownPlan::Disk, KnownPlan::Square, KnownPlan::Oculus] {
        let truth = generate::self_supporting(plan, 1500, &FormFindSettings::default()).unwrap();
        let r = analyse(&Problem::new(truth), &StressSettings::default()).unwrap();
        assert_eq!(r.status, StressStatus::Solved, "{plan:?}");
        assert!(r.eps_inf < 1e-6, "{plan:?}: eps_inf {:e}", r.eps_inf);
    }
}
