//! The certificate that the greatest thrust or the largest load factor has no bound
//! (docs/method.md §16.4): force densities q ≥ 0 that, scaled by every s ≥ s₀, carry the
//! loads inside the envelope. With q scaled by s (and, for the load factor, λ = s λ₀) the
//! surface is z(s) = z∞ + w / s, with K z∞ = λ₀ p_live (0 for the thrust) over the held
//! supports and K w = p_dead (K = L_q on the non-anchored vertices): exactly in equilibrium
//! for every s while the thrust s T, or λ, grows without bound; every constraint is affine
//! in 1/s, so it holds on the whole ray once it holds at both ends.

use super::model::{other_end, Model, State};
use super::Objective;
use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Conj, MatMut, Side};

/// A height may pass its bound by this much (frame units: 1e-9 of the plan diagonal, the
/// certificate's own allowance).
const BOUND_SLACK: f64 = 2e-9;
/// The limit's joint inequality holds to rounding: this fraction of b Σ q_e times the
/// envelope's height scale.
const ROUNDING: f64 = 1e-12;

/// A state of a ray of certified surfaces along `state`'s force densities (and load factor),
/// at s = max(s₀, `at_least`), s₀ ≥ 1 where the ray starts: q (and λ) scaled by s with
/// heights z∞ + w / s, the supports
/// at `state`'s heights or, for those with a springing joint, on their springing planes.
/// None where the analysis is neither the greatest thrust nor the largest load, or no such
/// ray starts.
pub(super) fn ray_start(model: &Model, state: &State, at_least: f64) -> Option<State> {
    let live = match model.objective {
        Objective::MaxThrust => 0.0,
        Objective::MaxLoad if state.t > 0.0 => state.t,
        _ => return None,
    };
    let grows = live > 0.0 || model.thrust(&state.q) > 0.0;
    if !grows || !scalable(model, &state.q) {
        return None;
    }
    let limit_load = |v: usize| live * model.live[v];
    let solver = Laplacian::new(model, &state.q)?;
    let zero = vec![0.0; state.z.len()];
    let w = solver.solve(model, &state.q, &zero, |v| model.dead[v])?;
    let mut supports = state.z.clone();
    for joint in &model.joints {
        supports[joint.support as usize] = joint.springing;
    }
    let start = [state.z.as_slice(), &supports]
        .into_iter()
        .find_map(|held| {
            let limit = solver.solve(model, &state.q, held, limit_load)?;
            let s0 = envelope_start(model, &limit, &w)?
                .max(joints_start(model, &state.q, &limit, &w, limit_load)?)
                .max(1.0)
                .max(at_least);
            Some(State {
                y: state.y.iter().map(|y| s0 * y).collect(),
                q: state.q.iter().map(|q| s0 * q).collect(),
                z: (limit.iter().zip(&w)).map(|(z, w)| z + w / s0).collect(),
                t: if live > 0.0 { s0 * live } else { state.t },
            })
        });
    start
}

/// Scaling q keeps it within its bounds and horizontal balance without external forces
/// (a homogeneous system).
fn scalable(model: &Model, q: &[f64]) -> bool {
    let no_external = (model.stress.external.iter()).all(|f| f[0] == 0.0 && f[1] == 0.0);
    let bounds_ok = (model.stress.bounds.iter().zip(q)).all(|(b, &q)| match b {
        None => true,
        Some((lo, hi)) => q >= 0.0 && q >= *lo && (q == 0.0 || hi.is_infinite()),
    });
    no_external && bounds_ok && q.iter().any(|&q| q > 0.0)
}

/// K = L_q on the non-anchored vertices, factorised.
struct Laplacian {
    /// Row of each vertex (None at supports and unreferenced vertices).
    row: Vec<Option<usize>>,
    llt: Llt<usize, f64>,
}

impl Laplacian {
    /// None where K is singular (a vertex the stress does not tie to a support).
    fn new(model: &Model, q: &[f64]) -> Option<Laplacian> {
        let mut row = vec![None; model.middle.len()];
        for (k, &v) in model.residual.iter().enumerate() {
            row[v as usize] = Some(k);
        }
        let edges = &model.problem.mesh.edges;
        let mut triplets = Vec::new();
        for (k, &i) in model.residual.iter().enumerate() {
            let i = i as usize;
            let mut diagonal = 0.0;
            for &e in &model.incident[i] {
                diagonal += q[e as usize];
                if let Some(c) = row[other_end(edges[e as usize].v, i)].filter(|&c| c < k) {
                    triplets.push(Triplet::new(k, c, -q[e as usize]));
                }
            }
            triplets.push(Triplet::new(k, k, diagonal));
        }
        let m = model.residual.len();
        let matrix = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &triplets).ok()?;
        let symbolic = SymbolicLlt::try_new(matrix.symbolic(), Side::Lower).ok()?;
        let llt = Llt::try_new_with_symbolic(symbolic, matrix.as_ref(), Side::Lower).ok()?;
        Some(Laplacian { row, llt })
    }

    /// Heights per vertex with K z = `load` at the non-anchored vertices, the supports at
    /// `supports`' heights.
    fn solve(
        &self,
        model: &Model,
        q: &[f64],
        supports: &[f64],
        load: impl Fn(usize) -> f64,
    ) -> Option<Vec<f64>> {
        let edges = &model.problem.mesh.edges;
        let mut rhs: Vec<f64> = (model.residual.iter())
            .map(|&i| {
                let i = i as usize;
                let held: f64 = (model.incident[i].iter())
                    .filter_map(|&e| {
                        let j = other_end(edges[e as usize].v, i);
                        self.row[j].is_none().then(|| q[e as usize] * supports[j])
                    })
                    .sum();
                load(i) + held
            })
            .collect();
        let m = rhs.len();
        let view = MatMut::from_column_major_slice_mut(&mut rhs, m, 1);
        self.llt.solve_in_place_with_conj(Conj::No, view);
        let mut z = supports.to_vec();
        for (k, &v) in model.residual.iter().enumerate() {
            z[v as usize] = rhs[k];
        }
        let solved = z.iter().all(|x| x.is_finite()) && balanced(model, q, &z, load);
        solved.then_some(z)
    }
}

/// K z = load at every non-anchored vertex to 1e-10 of the terms' size: a K near singular
/// (a region the stress barely ties to a support) yields no certificate.
fn balanced(model: &Model, q: &[f64], z: &[f64], load: impl Fn(usize) -> f64) -> bool {
    let edges = &model.problem.mesh.edges;
    model.residual.iter().all(|&i| {
        let i = i as usize;
        let (mut sum, mut size) = (-load(i), load(i).abs());
        for &e in &model.incident[i] {
            let j = other_end(edges[e as usize].v, i);
            let q = q[e as usize];
            sum += q * (z[i] - z[j]);
            size += q * (z[i].abs() + z[j].abs());
        }
        sum.abs() <= 1e-10 * size
    })
}

/// The least s from which z∞ + w / s lies within the envelope at every non-anchored vertex
/// (the supports keep their heights); None where z∞ itself (s → ∞) lies outside.
fn envelope_start(model: &Model, limit: &[f64], w: &[f64]) -> Option<f64> {
    let outside = |v: usize| {
        let (m, h) = (model.middle[v], model.half[v]);
        (limit[v] - m).abs() > h + BOUND_SLACK
    };
    let referenced = model.supports.iter().chain(&model.residual);
    if referenced.map(|&v| v as usize).any(outside) {
        return None;
    }
    let mut start: f64 = 0.0;
    for &v in &model.residual {
        let v = v as usize;
        if w[v] == 0.0 {
            continue;
        }
        // Half the allowance: the start keeps the other half against rounding.
        let (m, h, slack) = (model.middle[v], model.half[v], 0.5 * BOUND_SLACK);
        let room = if w[v] > 0.0 {
            m + h + slack - limit[v]
        } else {
            limit[v] - (m - h - slack)
        };
        if room <= 0.0 {
            return None;
        }
        start = start.max(w[v].abs() / room);
    }
    Some(start)
}

/// The least s from which every joint holds: with the support's height fixed, w_a = z_a − s_a,
/// H(s) = s H̄ and V(s) = s V̄ + W (V̄ with the limit's load at the support, W with the dead
/// one), the joint w_a |H̄| − b V̄ ≤ b W / s; None where its limit (s → ∞) fails or a support
/// lies below its springing plane.
fn joints_start(
    model: &Model,
    q: &[f64],
    limit: &[f64],
    w: &[f64],
    limit_load: impl Fn(usize) -> f64,
) -> Option<f64> {
    let u = &model.stress.plan.u;
    let heights = (model.middle.iter().zip(&model.half))
        .map(|(m, h)| m.abs() + h)
        .filter(|x| x.is_finite())
        .fold(0.0, f64::max);
    let mut start: f64 = 0.0;
    for joint in &model.joints {
        let a = joint.support as usize;
        let lift = limit[a] - joint.springing;
        if lift < -BOUND_SLACK {
            return None;
        }
        let (mut h, mut v_bar, mut q_sum, mut v_rest) =
            ([0.0; 2], limit_load(a), 0.0, model.dead[a]);
        for &(e, j) in &joint.edges {
            let j = j as usize;
            for d in 0..2 {
                h[d] += q[e] * (u[a][d] - u[j][d]);
            }
            v_bar += q[e] * (limit[j] - limit[a]);
            q_sum += q[e];
            v_rest += q[e] * w[j];
        }
        let moment = lift.max(0.0) * h[0].hypot(h[1]);
        let limit = moment - joint.reach * v_bar;
        let rest = joint.reach * v_rest;
        if limit > ROUNDING * (moment + joint.reach * q_sum * heights) {
            return None;
        }
        if limit < 0.0 && rest < 0.0 {
            start = start.max(rest / limit);
        } else if limit >= 0.0 && rest < 0.0 {
            return None;
        }
    }
    Some(start)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assess::{AssessSettings, Envelope};
    use crate::{Mesh, Problem, Thickness};

    /// A free centre over six supports on the unit circle, all at height 0, the centre
    /// between `centre_lower` and 0.5, the supports between −0.1 and 0.1.
    fn fan_problem(centre_lower: f64) -> (Problem, Envelope) {
        let mut positions = vec![[0.0, 0.0, 0.2]];
        for k in 0..6 {
            let a = std::f64::consts::PI * k as f64 / 3.0;
            positions.push([a.cos(), a.sin(), 0.0]);
        }
        let faces: Vec<[u32; 3]> = (0..6u32).map(|k| [0, k + 1, (k + 1) % 6 + 1]).collect();
        let mesh = Mesh::new(positions, faces, &[1, 2, 3, 4, 5, 6]).unwrap();
        let mut lower = vec![-0.1; 7];
        let mut upper = vec![0.1; 7];
        (lower[0], upper[0]) = (centre_lower, 0.5);
        let envelope = Envelope::from_bounds(&mesh, lower, upper, &Thickness::Uniform(0.1));
        (Problem::new(mesh), envelope.unwrap())
    }

    /// The spokes' force density `q` (frame units), the rim's 0, the supports at 0.
    fn spokes(model: &Model, q: f64) -> State {
        let edges = &model.problem.mesh.edges;
        State {
            y: Vec::new(),
            q: (edges.iter())
                .map(|e| if e.v.contains(&0) { q } else { 0.0 })
                .collect(),
            z: vec![0.0; 7],
            t: 0.0,
        }
    }

    /// The centre hangs w = p / Σq above the supports' plane and rises to it as 1/s: the ray
    /// starts where it meets the centre's upper bound, or further where asked.
    #[test]
    fn the_ray_starts_where_its_binding_bound_allows() {
        let (problem, envelope) = fan_problem(-0.1);
        let settings = AssessSettings::default()
            .with_objective(Objective::MaxThrust)
            .with_fixed_supports(true);
        let model = Model::new(&problem, &envelope, &settings).unwrap();
        let top = model.middle[0] + model.half[0];
        // w = 2 × top: the ray starts at s₀ = 2 (to the half slack).
        let q = model.dead[0] / (6.0 * 2.0 * top);
        let state = spokes(&model, q);
        let scale = |s: &State| s.q.iter().fold(0.0f64, |a, &x| a.max(x)) / q;
        let start = ray_start(&model, &state, 1.0).unwrap();
        assert!((scale(&start) - 2.0).abs() < 1e-6, "{}", scale(&start));
        assert!(start.z[0] <= top + BOUND_SLACK && start.z[0] > top - 1e-6);
        let later = ray_start(&model, &state, 5.0).unwrap();
        assert!((scale(&later) - 5.0).abs() < 1e-12);
        // A centre whose lower bound lies above the supports: flat surfaces leave the
        // envelope, so no ray.
        let (problem, envelope) = fan_problem(0.05);
        let model = Model::new(&problem, &envelope, &settings).unwrap();
        assert!(ray_start(&model, &spokes(&model, q), 1.0).is_none());
        // Fit and the least thrust look for no ray.
        for objective in [Objective::Fit, Objective::MinThrust] {
            let settings = settings.clone().with_objective(objective);
            let model = Model::new(&problem, &envelope, &settings).unwrap();
            assert!(ray_start(&model, &spokes(&model, q), 1.0).is_none());
        }
    }
}
