//! A stress step's answer back in physical units: τ, Airy values, weights, hole jumps, and
//! the equilibrium recomputed from the force densities (the result's certificate).

use super::airy::AiryOperator;
use super::framed::loads_at;
use super::{StressResult, StressSettings, TauMode};
use crate::geometry::dual;
use crate::geometry::{Frame, Plan};
use crate::mesh::Mesh;
use crate::problem::Problem;

/// τ at each of the `n` vertices in physical units: the prescribed values, or the optimised
/// ones scaled back.
pub(super) fn physical_tau(
    problem: &Problem,
    settings: &StressSettings,
    tau_frame: &[f64],
    p_bar: f64,
    n: usize,
) -> Vec<f64> {
    let mesh = &problem.mesh;
    match settings.tau {
        TauMode::Prescribed => (0..n)
            .map(|v| {
                if mesh.is_free_boundary(v) {
                    problem.prescribed_tau[v]
                } else {
                    0.0
                }
            })
            .collect(),
        _ => tau_frame.iter().map(|t| t * p_bar).collect(),
    }
}

/// Airy values, hole jumps and force-diagram centres in frame units: from the reduced
/// operator when the answer has one, else integrated from the force densities.
pub(super) fn airy_and_centres(
    mesh: &Mesh,
    plan: &Plan,
    airy_op: Option<&AiryOperator>,
    y: &[f64],
    q_frame: &[f64],
) -> (Vec<f64>, Vec<[f64; 3]>, Vec<[f64; 2]>) {
    match airy_op {
        Some(op) => {
            let phi = op.airy_values(y);
            let holes = op.hole_periods(y);
            let centres = dual::centres_from_airy(mesh, plan, op, &phi, y);
            (phi, holes, centres)
        }
        None => {
            let centres = dual::centres_from_forces(mesh, plan, q_frame);
            let phi = dual::airy_from_centres(mesh, plan, &centres);
            (phi, Vec::new(), centres)
        }
    }
}

/// Vertex weights w = |u|² − 2φ (0 at unreferenced vertices).
pub(super) fn power_weights(mesh: &Mesh, positions: &[[f64; 3]], airy: &[f64]) -> Vec<f64> {
    (0..positions.len())
        .map(|v| {
            let p = positions[v];
            if mesh.referenced[v] {
                p[0] * p[0] + p[1] * p[1] - 2.0 * airy[v]
            } else {
                0.0
            }
        })
        .collect()
}

/// Hole jumps (c, a_x, a_y) from frame units to physical ones, about the physical origin.
pub(super) fn physical_hole_jumps(
    hole_frame: &[[f64; 3]],
    p_bar: f64,
    frame: &Frame,
) -> Vec<[f64; 3]> {
    let l0 = frame.scale;
    hole_frame
        .iter()
        .map(|m| {
            let a = [m[1] * p_bar, m[2] * p_bar];
            [
                p_bar * l0 * m[0] - a[0] * frame.centre[0] - a[1] * frame.centre[1],
                a[0],
                a[1],
            ]
        })
        .collect()
}

impl StressResult {
    /// The same force densities certified at new heights (plan unchanged): loads, residuals,
    /// ε∞ and objective are recomputed at `positions`.
    pub fn at_heights(
        &self,
        problem: &Problem,
        positions: &[[f64; 3]],
        settings: &StressSettings,
    ) -> StressResult {
        let mesh = &problem.mesh;
        let (load, free, p_bar) = loads_at(problem, positions, settings);
        let (residuals, horizontal_imbalance) = equilibrium(
            mesh,
            positions,
            &self.force_densities,
            &load,
            &self.external_horizontal,
        );
        let max_r = free
            .iter()
            .map(|&v| residuals[v as usize].abs())
            .fold(0.0, f64::max);
        StressResult {
            eps_inf: max_r / p_bar,
            objective: free.iter().map(|&v| residuals[v as usize].powi(2)).sum(),
            loads: load,
            residuals,
            horizontal_imbalance,
            ..self.clone()
        }
    }
}

/// Vertical residual and horizontal imbalance at every non-anchored vertex, recomputed from
/// positions, force densities, loads and external horizontal forces (zero elsewhere).
pub(crate) fn equilibrium(
    mesh: &Mesh,
    positions: &[[f64; 3]],
    q: &[f64],
    load: &[f64],
    external: &[[f64; 2]],
) -> (Vec<f64>, Vec<[f64; 2]>) {
    let n = positions.len();
    let mut r = vec![0.0; n];
    let mut h = vec![[0.0; 2]; n];
    for v in 0..n {
        if mesh.is_non_anchored(v) {
            r[v] = -load[v];
            h[v] = external[v];
        }
    }
    for (e, edge) in mesh.edges.iter().enumerate() {
        let [i, j] = edge.v.map(|v| v as usize);
        for (a, b) in [(i, j), (j, i)] {
            if mesh.is_non_anchored(a) {
                r[a] += q[e] * (positions[a][2] - positions[b][2]);
                h[a][0] += q[e] * (positions[a][0] - positions[b][0]);
                h[a][1] += q[e] * (positions[a][1] - positions[b][1]);
            }
        }
    }
    (r, h)
}
