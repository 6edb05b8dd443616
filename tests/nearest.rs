//! The nearest self-supporting shape: known-answer cases, perturbed shared models, and inputs
//! that cannot stand within the height limit. Nearness is measured here, from the returned
//! positions, not through the library.
//!
//! `VSR_SEEDS=N` runs N seeds per case instead of the default.

mod common;
use common::{load_model, plan_diagonal, recomputed_eps_inf, Rng, MODELS};
use voussoir::generate::{self, KnownPlan, Perturbation};
use voussoir::*;

fn seeds(default: u64) -> u64 {
    std::env::var("VSR_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Area-weighted RMS and largest height difference of the non-anchored vertices between two
/// position sets of `mesh` (plan area shares as weights).
fn difference(mesh: &Mesh, a: &[[f64; 3]], b: &[[f64; 3]]) -> (f64, f64) {
    let mut share = vec![0.0; a.len()];
    for f in mesh.faces() {
        let [p, q, r] = f.map(|v| mesh.positions()[v as usize]);
        let area = ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])).abs() / 6.0;
        f.iter().for_each(|&v| share[v as usize] += area);
    }
    let (mut sum, mut total, mut max) = (0.0, 0.0, 0.0f64);
    for v in (0..a.len()).filter(|&v| mesh.is_non_anchored(v)) {
        let d = a[v][2] - b[v][2];
        sum += share[v] * d * d;
        total += share[v];
        max = max.max(d.abs());
    }
    ((sum / total).sqrt(), max)
}

/// Every known-answer case converges and ends at least as near the input as its truth, a
/// self-supporting shape the input was made from; the largest change stays near the truth's.
#[test]
fn known_answer_cases_end_at_least_as_near_as_their_truth() {
    let settings = FormFindSettings::default();
    let mut max_ratios = Vec::new();
    for plan in KnownPlan::ALL {
        let truth = generate::self_supporting(plan, 400, &settings).unwrap();
        for kind in Perturbation::ALL {
            for seed in 0..seeds(2) {
                let input = generate::perturb(&truth, kind, seed);
                let problem = Problem::new(input.clone());
                let r = form_find(&problem, &settings, None).unwrap();
                let label = format!("{plan:?} {kind:?} seed {seed}");
                assert_eq!(r.termination, Termination::Converged, "{label}");
                assert!(
                    recomputed_eps_inf(&problem.mesh, &r) < 1e-6,
                    "{label}: not in equilibrium"
                );
                let (truth_rms, truth_max) =
                    difference(&input, truth.positions(), input.positions());
                let (rms, max) = difference(&input, &r.positions, input.positions());
                let (rms_ratio, max_ratio) = (rms / truth_rms, max / truth_max);
                println!(
                    "{label}: {} steps, RMS ratio {rms_ratio:.3}, max ratio {max_ratio:.3}",
                    r.iterations
                );
                assert!(rms_ratio <= 1.0, "{label}: RMS ratio {rms_ratio:.3}");
                assert!(
                    max_ratio <= 2.0,
                    "{label}: largest change ratio {max_ratio:.3}"
                );
                max_ratios.push(max_ratio);
            }
        }
    }
    let within = max_ratios.iter().filter(|&&m| m <= 1.25).count();
    assert!(
        within * 20 >= max_ratios.len() * 19,
        "largest change within 1.25 of the truth's in only {within} of {} cases",
        max_ratios.len()
    );
}

/// A larger case: the dented disk at about 2500 vertices.
#[test]
fn a_dent_in_a_large_disk_is_filled_no_further_than_the_truth() {
    let settings = FormFindSettings::default();
    let truth = generate::self_supporting(KnownPlan::Disk, 2500, &settings).unwrap();
    let input = generate::perturb(&truth, Perturbation::Dent, 3);
    let problem = Problem::new(input.clone());
    let r = form_find(&problem, &settings, None).unwrap();
    assert_eq!(r.termination, Termination::Converged);
    assert!(recomputed_eps_inf(&problem.mesh, &r) < 1e-6);
    let (truth_rms, _) = difference(&input, truth.positions(), input.positions());
    let (rms, _) = difference(&input, &r.positions, input.positions());
    assert!(
        rms <= truth_rms,
        "RMS {rms:e} against the truth's {truth_rms:e}"
    );
    // The library's own objective agrees with the one measured here.
    let diag = plan_diagonal(&input);
    assert!((r.rms_change - rms / diag).abs() <= 1e-12 + 1e-9 * rms / diag);
}

/// Smooth random bumps on the shared models: every run converges or stops with an honest
/// status, never moves a height by more than the plan diagonal, and never returns a state
/// less balanced than the input.
#[test]
fn perturbed_shared_models_never_blow_up() {
    for name in MODELS {
        let Some(mesh) = load_model(name) else { return };
        let diag = plan_diagonal(&mesh);
        let rise = mesh
            .positions()
            .iter()
            .map(|p| p[2])
            .fold(f64::NEG_INFINITY, f64::max)
            - mesh
                .positions()
                .iter()
                .map(|p| p[2])
                .fold(f64::INFINITY, f64::min);
        for seed in 0..seeds(1) {
            let mut rng = Rng::new(seed * 31 + name.len() as u64);
            let bumps: Vec<([f64; 3], f64)> = (0..6)
                .map(|_| {
                    let v = &mesh.positions()
                        [(rng.next_u64() % mesh.positions().len() as u64) as usize];
                    (*v, rng.uniform(-0.15, 0.15) * rise)
                })
                .collect();
            let mut z: Vec<f64> = mesh.positions().iter().map(|p| p[2]).collect();
            for (v, p) in mesh.positions().iter().enumerate() {
                if mesh.is_non_anchored(v) {
                    for (c, a) in &bumps {
                        let d2 = (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2);
                        z[v] += a * (-d2 / (2.0 * (0.1 * diag).powi(2))).exp();
                    }
                }
            }
            let input = mesh.clone().with_heights(&z).unwrap();
            let problem = Problem::new(input.clone());
            let before = analyse(&problem, &FormFindSettings::default().stress).unwrap();
            let r = form_find(&problem, &FormFindSettings::default(), None).unwrap();
            let (_, max) = difference(&input, &r.positions, input.positions());
            let label = format!("{name} seed {seed}");
            println!(
                "{label}: {:?} in {} steps, largest change {:.4} diagonals",
                r.termination,
                r.iterations,
                max / diag
            );
            assert!(max <= diag * (1.0 + 1e-9), "{label}: moved {max}");
            assert!(
                r.stress.eps_inf <= before.eps_inf,
                "{label}: worse than the input"
            );
            assert!(
                matches!(
                    r.termination,
                    Termination::Converged
                        | Termination::Stalled { .. }
                        | Termination::Blocked { .. }
                ),
                "{label}: {:?}",
                r.termination
            );
        }
    }
}

/// A q_max that holds the forces far below what the loads need: the shape would have to rise
/// by many diagonals to stand, or cannot stand at all as steeper faces weigh more. The loop
/// says that q_max blocks, stays within the height limit and returns a state no less balanced
/// than the input.
#[test]
fn a_blocking_q_max_is_named_and_the_shape_stays_within_the_limit() {
    let Some(mesh) = load_model("three_pillar") else {
        return;
    };
    let diag = plan_diagonal(&mesh);
    let problem = Problem::new(mesh.clone());
    let mut settings = FormFindSettings::default();
    settings.stress.q_min = QBound::Absolute(0.0);
    settings.stress.q_max = Some(QBound::Absolute(1e-2));
    let before = analyse(&problem, &settings.stress).unwrap();
    let r = form_find(&problem, &settings, None).unwrap();
    let (_, max) = difference(&mesh, &r.positions, mesh.positions());
    assert!(max <= diag * (1.0 + 1e-9), "moved {max}");
    assert!(r.stress.eps_inf <= before.eps_inf);
    match &r.termination {
        Termination::Blocked { vertices, hint } => {
            assert!(!vertices.is_empty());
            assert!(hint.contains("q_max"), "{hint}");
        }
        other => panic!("expected q_max to block, got {other:?}"),
    }
}
