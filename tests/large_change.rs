//! Inputs that need large height changes (docs/method.md §13.1): flat plates on three or four
//! corner supports and vaults with a tall, nearly vertical wall strip, several seeds. With the
//! default height limit a standing shape exists and the nearest method converges; with a tight
//! limit it ends `Blocked` within its step budget, naming the region that cannot stand (the
//! wall) and answering its best state. On every path the answer stays within the limit.

mod common;
use common::{largest_change, recomputed_eps_inf, Rng};
use std::f64::consts::FRAC_PI_2;
use voussoir::generate;
use voussoir::*;

/// The square [−1, 1]² with about 400 vertices lifted by `height`, anchored where `anchor`.
fn square(height: impl Fn([f64; 2]) -> f64, anchor: impl Fn([f64; 2], bool) -> bool) -> Mesh {
    let n = 400;
    let k = ((n as f64).sqrt() * 0.9) as usize;
    let domain = generate::Domain {
        outer: generate::rectangle(-1.0, -1.0, 1.0, 1.0, k, k),
        holes: vec![],
    };
    let (p, t) = generate::triangulate(&domain, 1.6 * 4.0 / (2.0 * n as f64)).unwrap();
    generate::lift(&p, &t, height, anchor).unwrap()
}

/// A nearly flat plate (seeded waves of `noise`) on the outer boundary within 0.15 of its
/// first `corners` corners, free elsewhere.
fn plate(corners: usize, seed: u64, noise: f64) -> Mesh {
    let mut rng = Rng::new(seed);
    let (a, b, c) = (
        rng.uniform(-1.0, 1.0),
        rng.uniform(-1.0, 1.0),
        rng.uniform(0.0, 6.0),
    );
    let at = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
    square(
        |u| noise * (a * u[0] + b * u[1] + c).sin(),
        |u, outer| {
            outer
                && at[..corners]
                    .iter()
                    .any(|q| (u[0] - q[0]).hypot(u[1] - q[1]) < 0.15)
        },
    )
}

/// A vault over the square, rim anchored, with a wall of height `wall` rising over a strip of
/// width about 0.06 at a seeded x0; returns the mesh and x0.
fn walled(wall: f64, seed: u64) -> (Mesh, f64) {
    let x0 = Rng::new(seed).uniform(-0.3, 0.3);
    let mesh = square(
        |u| {
            let across = (FRAC_PI_2 * u[1]).cos();
            let step = (1.0 + ((u[0] - x0) / 0.03).tanh()) / 2.0;
            0.4 * (FRAC_PI_2 * u[0]).cos() * across + wall * step * across
        },
        |_, outer| outer,
    );
    (mesh, x0)
}

/// Form-finds `mesh` with `limit` and `budget` and checks what every answer must satisfy;
/// returns the result.
fn run(case: &str, mesh: Mesh, limit: f64, budget: usize) -> FormFindResult {
    let settings = FormFindSettings::default()
        .with_max_height_change(limit)
        .with_max_iterations(budget);
    let problem = Problem::new(mesh);
    let r = form_find(&problem, &settings, None).unwrap();
    let mesh = &problem.mesh;
    let moved = largest_change(mesh, &r.positions);
    assert!(moved <= limit * (1.0 + 1e-9), "{case}: moved {moved}");
    assert!(r.iterations <= budget, "{case}: {} steps", r.iterations);
    let eps = recomputed_eps_inf(mesh, &r);
    assert!(
        (eps - r.stress.eps_inf).abs() <= 1e-9 + 1e-6 * eps,
        "{case}: {eps:e}"
    );
    match &r.termination {
        Termination::Converged => assert!(eps < 1e-6, "{case}: ε∞ {eps:e}"),
        Termination::Blocked { vertices, .. } | Termination::Stalled { vertices } => {
            assert_eq!(r.stress.eps_inf, lowest(&r), "{case}: not the best state");
            assert!(!vertices.is_empty(), "{case}: no region named");
            assert!(vertices.iter().all(|&v| mesh.is_non_anchored(v as usize)));
        }
        Termination::MaxIterations => {
            assert_eq!(r.stress.eps_inf, lowest(&r), "{case}: not the best state")
        }
        other => panic!("{case}: {other:?}"),
    }
    r
}

fn lowest(r: &FormFindResult) -> f64 {
    r.history.iter().copied().fold(f64::INFINITY, f64::min)
}

#[test]
fn plates_on_few_corners_converge_within_the_limit() {
    for corners in [3, 4] {
        for seed in 0..3 {
            for noise in [0.0, 0.02] {
                let case = format!("plate on {corners} corners, seed {seed}, noise {noise}");
                let r = run(&case, plate(corners, seed, noise), 1.0, 100);
                assert_eq!(r.termination, Termination::Converged, "{case}");
            }
        }
    }
}

#[test]
fn tall_walls_converge_or_end_blocked_at_the_wall() {
    for wall in [1.5, 4.0] {
        for seed in 0..3 {
            let (mesh, x0) = walled(wall, seed);
            let case = format!("wall {wall}, seed {seed}");
            let r = run(&case, mesh.clone(), 1.0, 100);
            assert_eq!(r.termination, Termination::Converged, "{case}");
            for (limit, budget) in [(0.1, 100), (0.02, 100), (0.1, 30)] {
                let case = format!("{case}, limit {limit}, {budget} steps");
                let r = run(&case, mesh.clone(), limit, budget);
                let Termination::Blocked { vertices, .. } = &r.termination else {
                    panic!("{case}: {:?}", r.termination);
                };
                // The region named runs along the wall, not one vertex of it.
                let at_wall = vertices
                    .iter()
                    .filter(|&&v| (mesh.positions()[v as usize][0] - x0).abs() < 0.1)
                    .count();
                assert!(at_wall >= 5, "{case}: {vertices:?}");
            }
            // Ten steps leave the paper's loop two (a quarter of the budget): its answer,
            // a stress step's own where it balances best, is the best state (`run`).
            let r = run(&format!("{case}, limit 0.02, 10 steps"), mesh, 0.02, 10);
            assert!(r.stress.eps_inf > 1e-6, "{case}: {:?}", r.termination);
        }
    }
}
