//! A converged form finding certifies forces within their bounds: every force density at
//! least q_min (relative: 0.05 p̄ / L₀), recomputed here from the outputs alone. The stress
//! QPs answered from the previous step's active set once let rows 3 % below q_min pass as
//! solved on four_holes with τ = 0, where the Airy values are large beside the bounds.

mod common;
use common::{models_dir, read_shared};
use voussoir::{form_find, FormFindSettings, HoleMode, TauMode, Termination};

/// The least force density over its bound q_min = 0.05 p̄ / L₀ of the edges with force (not
/// both ends anchored), p̄ the mean load of the non-anchored vertices and L₀ half the plan
/// bounding-box diagonal of the answer.
fn least_over_floor(problem: &voussoir::Problem, r: &voussoir::FormFindResult) -> (f64, usize) {
    let mesh = &problem.mesh;
    let anchored = mesh.anchored();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &r.positions {
        for d in 0..2 {
            (lo[d], hi[d]) = (lo[d].min(p[d]), hi[d].max(p[d]));
        }
    }
    let l0 = (hi[0] - lo[0]).hypot(hi[1] - lo[1]) / 2.0;
    let free: Vec<f64> = (0..anchored.len())
        .filter(|&v| !anchored[v])
        .map(|v| r.stress.loads[v])
        .collect();
    let p_bar = free.iter().sum::<f64>() / free.len() as f64;
    let q_min = 0.05 * p_bar / l0;
    (mesh
        .edges()
        .iter()
        .zip(&r.stress.force_densities)
        .enumerate())
    .filter(|(_, (e, _))| !e.v.iter().all(|&v| anchored[v as usize]))
    .map(|(k, (_, &q))| (q / q_min, k))
    .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a })
}

#[test]
fn converged_answers_keep_every_force_density_above_q_min() {
    let Some(dir) = models_dir() else { return };
    for name in ["four_holes", "cheese", "dome_with_doors"] {
        let problem = read_shared(&dir, name).unwrap();
        for (tau, holes) in [
            (TauMode::Zero, HoleMode::Affine),
            (TauMode::Zero, HoleMode::Constant),
            (TauMode::Optimized, HoleMode::Affine),
        ] {
            let mut settings = FormFindSettings::default();
            settings.stress.tau = tau;
            settings.stress.holes = holes;
            let r = form_find(&problem, &settings, None).unwrap();
            let case = format!("{name}, {tau:?}, {holes:?}: {:?}", r.termination);
            if r.termination != Termination::Converged {
                continue;
            }
            let (least, edge) = least_over_floor(&problem, &r);
            assert!(least >= 1.0 - 1e-6, "{case}: edge {edge} at {least} q_min");
        }
    }
}
