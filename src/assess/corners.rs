//! Free corners (docs/method.md §16.3): a free boundary vertex whose edges all leave it into
//! one open half-plane of the plan. Compression cannot balance it horizontally unless every
//! edge at it carries nothing (Gordan's alternative: Σ q_e d_e = 0 with q ≥ 0 and every
//! d_e · c > 0 forces q = 0), and then nothing holds its load: no thrust surface exists in
//! any envelope, however thick. An assessment answers so before any search.

use super::model::{Model, Run};
use super::Objective;
use crate::solve::Termination;

/// How far beyond a half turn the widest gap between a vertex's edge directions must be
/// (radians) for it to count as a corner: a straight free edge, whose two edges are opposite
/// up to rounding, can carry its load as an arch along the edge.
const MARGIN: f64 = 1e-9;

/// The non-anchored vertices whose edges with force all leave them into one open half-plane
/// (only free boundary vertices can), in increasing order, where that proves the analysis
/// infeasible: the vertex's load exceeds what the certificate forgives (`tolerance` times
/// the mean load), no prescribed horizontal force acts there, and no live load of
/// `max-load`, whose factor may take either sign, could cancel its dead load.
pub(super) fn free_corners(model: &Model, tolerance: f64) -> Vec<u32> {
    let mut corners: Vec<u32> = (model.residual.iter().copied())
        .filter(|&v| unbalanced_load(model, v, tolerance) && is_corner(model, v))
        .collect();
    corners.sort_unstable();
    corners
}

fn unbalanced_load(model: &Model, v: u32, tolerance: f64) -> bool {
    let v = v as usize;
    let live = model.objective == Objective::MaxLoad && model.live[v] != 0.0;
    model.dead[v].abs() >= tolerance && !live && model.stress.external[v] == [0.0, 0.0]
}

fn is_corner(model: &Model, v: u32) -> bool {
    let vi = v as usize;
    let mesh = &model.problem.mesh;
    let u = &model.stress.plan.u;
    let mut angles: Vec<f64> = (model.incident[vi].iter())
        .filter(|&&e| model.stress.bounds[e as usize].is_some())
        .map(|&e| {
            let j = mesh.other_end(e as usize, v) as usize;
            (u[j][1] - u[vi][1]).atan2(u[j][0] - u[vi][0])
        })
        .collect();
    if angles.is_empty() {
        return true;
    }
    angles.sort_by(f64::total_cmp);
    let wrap = angles[0] + std::f64::consts::TAU - angles[angles.len() - 1];
    let widest = (angles.windows(2).map(|w| w[1] - w[0])).fold(wrap, f64::max);
    widest > std::f64::consts::PI + MARGIN
}

/// The answer where free corners exist: the middle surface without force (its residuals are
/// the loads), with the termination naming the corners.
pub(super) fn unbalanced(model: &Model, corners: &[u32]) -> Run {
    let state = model.start_state();
    let ids: Vec<String> = corners.iter().map(|v| v.to_string()).collect();
    let (which, is) = match corners.len() {
        1 => ("vertex", "is a free corner"),
        _ => ("vertices", "are free corners"),
    };
    let constraint = format!(
        "the supports: {which} {} {is} (every edge leaves the vertex on one side in plan), \
         which compression alone cannot balance in any envelope; anchor them",
        ids.join(", ")
    );
    Run {
        state,
        termination: Termination::Infeasible { constraint },
        iterations: 0,
        seconds: 0.0,
        unbounded: false,
    }
}
