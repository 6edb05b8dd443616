//! One step of the sequential QP (docs/method.md §16.3): the objective's model, the
//! convexified Hessian of the Lagrangian and a proximal term; the vertical residuals
//! linearised with elastic slacks e⁺, e⁻ priced at ν (the exact ℓ1 penalty), and every
//! linear constraint exact: q = S y, horizontal balance, force-density bounds, the envelope
//! and, for the least thrust, a second-order cone per support. Solved by clarabel, in units
//! of ν.

use super::model::{other_end, Model, State};
use super::Objective;
use crate::stress::sparse::Triplets;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

/// Columns of the step's unknowns.
pub(super) struct Layout {
    n_y: usize,
    /// Column of dq_e per edge with force.
    q_col: Vec<Option<usize>>,
    /// Column of dz_v per vertex whose height is an unknown.
    z_col: Vec<Option<usize>>,
    /// Column of the objective's scalar step.
    t_col: Option<usize>,
    /// First columns of e⁺ and e⁻ (one per residual vertex).
    e_plus: usize,
    e_minus: usize,
    /// First column of the joints' slacks (one per springing joint).
    j_start: usize,
    /// First column of the thrust bounds h_a (least thrust), one per support.
    h_start: usize,
    n: usize,
    /// Residual row per vertex (None at anchored and unreferenced vertices).
    row_of: Vec<Option<usize>>,
}

impl Layout {
    pub fn new(model: &Model) -> Layout {
        let n_y = model.stress.s().ncols;
        let mut n = n_y;
        let mut next = |take: bool| {
            take.then(|| {
                n += 1;
                n - 1
            })
        };
        let q_col: Vec<Option<usize>> = (model.stress.bounds.iter())
            .map(|b| next(b.is_some()))
            .collect();
        let z_col: Vec<Option<usize>> = model.variable.iter().map(|&v| next(v)).collect();
        let t_col = next(matches!(
            model.objective,
            Objective::MinThickness | Objective::MaxLoad
        ));
        let n_r = model.residual.len();
        let e_plus = n;
        let e_minus = n + n_r;
        let j_start = n + 2 * n_r;
        let h_start = j_start + model.joints.len();
        let n_h = if model.objective == Objective::MinThrust {
            model.supports.len()
        } else {
            0
        };
        let mut row_of = vec![None; model.variable.len()];
        for (k, &v) in model.residual.iter().enumerate() {
            row_of[v as usize] = Some(k);
        }
        Layout {
            row_of,
            n_y,
            q_col,
            z_col,
            t_col,
            e_plus,
            e_minus,
            j_start,
            h_start,
            n: h_start + n_h,
        }
    }
}

/// A step's inputs: the proximal weight ρ, the penalty ν and, for a second-order correction,
/// the second-order terms of a trial step.
pub(super) struct StepInput<'a> {
    /// ρ on the force densities and on the heights (and the scalar).
    pub rho: f64,
    pub rho_z: f64,
    pub nu: f64,
    pub correction: Option<&'a Correction>,
    /// Multipliers μ of the residual rows for the Hessian of the Lagrangian (none: no
    /// curvature but the proximal term).
    pub multipliers: Option<&'a [f64]>,
    /// The last accepted step's dq and dz (per edge, per vertex): its ratio per edge sets
    /// the convexification's balance α_e.
    pub direction: Option<(&'a [f64], &'a [f64])>,
}

/// A step and its model's figures.
pub(super) struct Step {
    pub dy: Vec<f64>,
    /// Per edge (0 where no force).
    pub dq: Vec<f64>,
    /// Per vertex (0 where the height is fixed).
    pub dz: Vec<f64>,
    pub dt: f64,
    /// Σ (e⁺ + e⁻) + Σ e_joint: the linearised ℓ1 infeasibility after the step.
    pub slack: f64,
    /// The objective's model at the step.
    pub model_objective: f64,
    /// Multipliers μ of the residual rows (|μ| ≤ ν); none when the QP stopped short of
    /// optimality.
    pub multipliers: Option<Vec<f64>>,
    /// The largest multiplier of a joint's cone (0 without joints or multipliers).
    pub joint_multiplier: f64,
    /// ½ dᵀ B d of the convexified Hessian of the Lagrangian (0 without multipliers).
    pub curvature: f64,
}

/// The terms a step's linearisation leaves out of the constraints, all of second order (the
/// constraints are bilinear), evaluated on a trial step: Fletcher's second-order correction
/// solves the step again with them on the right-hand side.
pub(super) struct Correction {
    /// Per residual row: Σ dq_e (dz_i − dz_j).
    rows: Vec<f64>,
    /// Per springing joint, in the cone's units: the bound's term and the vector's two.
    joints: Vec<[f64; 3]>,
}

impl Correction {
    pub fn of(model: &Model, state: &State, step: &Step) -> Self {
        let edges = &model.problem.mesh.edges;
        let rows = (model.residual.iter())
            .map(|&i| {
                let i = i as usize;
                (model.incident[i].iter())
                    .map(|&e| {
                        let j = other_end(edges[e as usize].v, i);
                        step.dq[e as usize] * (step.dz[i] - step.dz[j])
                    })
                    .sum()
            })
            .collect();
        let joints = (0..model.joints.len())
            .map(|k| joint_terms(model, state, step, k))
            .collect();
        Correction { rows, joints }
    }
}

/// Joint k's second-order terms along `step` (`joint_cones`' products): σ b V gains
/// b (σ dV₂ + dσ (dV₁ + dV₂)) and w H gains dw dH, over the joint's unit, where dV₁ is V's
/// first-order change and dV₂ = Σ dq_e (dz_j − dz_a).
fn joint_terms(model: &Model, state: &State, step: &Step, k: usize) -> [f64; 3] {
    let joint = &model.joints[k];
    let (a, u) = (joint.support as usize, &model.stress.plan.u);
    let js = model.joint_state(state, k);
    let (mut dh, mut dv1, mut dv2) = ([0.0; 2], 0.0, 0.0);
    for &(e, j) in &joint.edges {
        let j = j as usize;
        for d in 0..2 {
            dh[d] += step.dq[e] * (u[a][d] - u[j][d]);
        }
        let rise = step.dz[j] - step.dz[a];
        dv1 += step.dq[e] * (state.z[j] - state.z[a]) + state.q[e] * rise;
        dv2 += step.dq[e] * rise;
    }
    let (dsigma, dw) = match model.objective {
        Objective::MinThickness => (step.dt, step.dz[a] + step.dt * model.springing_rate(k)),
        _ => (0.0, step.dz[a]),
    };
    let unit = joint.unit();
    [
        joint.reach * (js.scale * dv2 + dsigma * (dv1 + dv2)) / unit,
        dw * dh[0] / unit,
        dw * dh[1] / unit,
    ]
}

/// Rows A x + s = b in cone order: zero, non-negative, then second-order cones of size 3.
struct Rows {
    a: Triplets,
    b: Vec<f64>,
    n_zero: usize,
    n_nonneg: usize,
    n_soc: usize,
}

impl Rows {
    fn next(&self) -> usize {
        self.b.len()
    }
}

pub(super) fn solve_step(
    model: &Model,
    layout: &Layout,
    state: &State,
    input: &StepInput,
) -> Option<Step> {
    // The QP in units of ν: the slacks cost 1, so that its tolerances do not depend on
    // how dear the penalty has become (the step and the multipliers are the same).
    let unit = input.nu.max(1.0);
    let (mut p, c) = objective(model, layout, state, input, unit);
    let hessian = input
        .multipliers
        .map(|mu| lagrangian_hessian(model, layout, state, mu, input.direction));
    if let Some(h) = &hessian {
        for b in &h.blocks {
            b.push_into(&mut p);
        }
    }
    let mut rows = Rows {
        a: Triplets::default(),
        b: Vec::new(),
        n_zero: 0,
        n_nonneg: 0,
        n_soc: 0,
    };
    force_rows(model, layout, state, &mut rows);
    vertical_rows(model, layout, state, input.correction, &mut rows);
    horizontal_rows(model, layout, state, &mut rows);
    idle_rows(model, layout, state, &mut rows);
    rows.n_zero = rows.next();
    bound_rows(model, layout, state, &mut rows);
    rows.n_nonneg = rows.next() - rows.n_zero;
    thrust_cones(model, layout, state, &mut rows);
    let first_joint_row = rows.next();
    joint_cones(model, layout, state, input.correction, &mut rows);
    rows.n_soc = (rows.next() - rows.n_zero - rows.n_nonneg) / 3;
    let first_residual_row = layout.q_col.iter().flatten().count();
    p.v.iter_mut().for_each(|v| *v /= unit);
    let c: Vec<f64> = c.iter().map(|v| v / unit).collect();
    let (x, z) = run_clarabel(layout.n, p, &c, rows)?;
    let joint_multiplier = z.as_ref().map_or(0.0, |z| {
        (0..model.joints.len())
            .map(|k| z[first_joint_row + 3 * k].abs() * unit)
            .fold(0.0, f64::max)
    });
    let multipliers = z.map(|z| {
        (z[first_residual_row..first_residual_row + model.residual.len()].iter())
            .map(|m| m * unit)
            .collect()
    });
    let mut step = read_step(model, layout, state, &x);
    step.multipliers = multipliers;
    step.joint_multiplier = joint_multiplier;
    step.curvature = hessian.map_or(0.0, |h| h.curvature(&step));
    Some(step)
}

/// The Hessian of the Lagrangian Σ μ_i c_i, convexified edge by edge. Edge e = (i, j)
/// enters c_i and c_j bilinearly, so its exact second-order term is w dq_e (dz_i − dz_j)
/// with w = μ_i − μ_j (μ = 0 at supports), indefinite; adding |w| (α dq_e² + (dz_i −
/// dz_j)²/α)/2 makes it ½|w| (√α dq_e + sign(w) (dz_i − dz_j)/√α)², the least addition of
/// that form that is positive semidefinite. α balances the units of q and heights.
struct Hessian {
    blocks: Vec<EdgeBlock>,
}

/// α_e: |dd|/|dq| of the last step, where the addition equals the exact term's size along
/// it, kept within a factor 1e3 of the units' ratio `units`; `units` without a step.
fn balance(units: f64, last: Option<(f64, f64)>) -> f64 {
    match last {
        Some((dq, dd)) if dq != 0.0 && dd != 0.0 => {
            (dd / dq).abs().clamp(1e-3 * units, 1e3 * units)
        }
        _ => units,
    }
}

struct EdgeBlock {
    e: usize,
    q: usize,
    zi: Option<usize>,
    zj: Option<usize>,
    i: usize,
    j: usize,
    w: f64,
    alpha: f64,
}

impl EdgeBlock {
    fn push_into(&self, p: &mut Triplets) {
        let (w, a) = (self.w, self.alpha);
        p.push(self.q, self.q, w.abs() * a);
        for (z, sign) in [(self.zi, 1.0), (self.zj, -1.0)] {
            if let Some(z) = z {
                p.push(self.q.min(z), self.q.max(z), sign * w);
                p.push(z, z, w.abs() / a);
            }
        }
        if let (Some(zi), Some(zj)) = (self.zi, self.zj) {
            p.push(zi.min(zj), zi.max(zj), -w.abs() / a);
        }
    }
}

impl Hessian {
    /// ½ dᵀ B d at a step.
    fn curvature(&self, step: &Step) -> f64 {
        (self.blocks.iter())
            .map(|b| {
                let dq = step.dq[b.e];
                let dd = step.dz[b.i] - step.dz[b.j];
                b.w * dq * dd + 0.5 * b.w.abs() * (b.alpha * dq * dq + dd * dd / b.alpha)
            })
            .sum()
    }
}

fn lagrangian_hessian(
    model: &Model,
    layout: &Layout,
    state: &State,
    mu: &[f64],
    direction: Option<(&[f64], &[f64])>,
) -> Hessian {
    let edges = &model.problem.mesh.edges;
    let forced = || (layout.q_col.iter().enumerate()).filter_map(|(e, c)| c.map(|c| (e, c)));
    let count = forced().count().max(1) as f64;
    let dz = |e: usize| {
        let [i, j] = edges[e].v;
        (state.z[i as usize] - state.z[j as usize]).abs()
    };
    let mean_dz = forced().map(|(e, _)| dz(e)).sum::<f64>() / count;
    let mean_q = forced().map(|(e, _)| state.q[e].abs()).sum::<f64>() / count;
    let (floor_dz, floor_q) = (mean_dz.max(1e-12), mean_q.max(1e-12));
    let blocks = forced()
        .filter_map(|(e, q)| {
            let [i, j] = edges[e].v.map(|v| v as usize);
            let (zi, zj) = (layout.z_col[i], layout.z_col[j]);
            let mu_of = |v: usize| layout.row_of[v].map_or(0.0, |k| mu[k]);
            let w = mu_of(i) - mu_of(j);
            (w != 0.0 && (zi.is_some() || zj.is_some())).then(|| EdgeBlock {
                e,
                q,
                zi,
                zj,
                i,
                j,
                w,
                alpha: balance(
                    (dz(e) + floor_dz) / (state.q[e].abs() + floor_q),
                    direction.map(|(dq, dz)| (dq[e], dz[i] - dz[j])),
                ),
            })
        })
        .collect();
    Hessian { blocks }
}

/// ½ dᵀ P d + cᵀ d: the proximal term ρ·unit (Σ dz² + Σ l² dq² + dt²), the objective's
/// model and the penalty ν Σ (e⁺ + e⁻). `unit` is the QP's (see `solve_step`): ρ weighs
/// the proximal term in it, so that a change of ν does not change how far a step may go.
fn objective(
    model: &Model,
    layout: &Layout,
    state: &State,
    input: &StepInput,
    unit: f64,
) -> (Triplets, Vec<f64>) {
    let mut p = Triplets::default();
    let mut c = vec![0.0; layout.n];
    let (rho, rho_z) = (input.rho * unit, input.rho_z * unit);
    for (e, col) in layout.q_col.iter().enumerate() {
        if let Some(col) = col {
            let l = model.stress.plan.length[e];
            p.push(*col, *col, 2.0 * rho * l * l);
        }
    }
    for (v, col) in layout.z_col.iter().enumerate() {
        if let Some(col) = col {
            let mut diag = 2.0 * rho_z;
            if model.objective == Objective::Fit {
                diag += 2.0 * model.area[v];
                c[*col] = 2.0 * model.area[v] * (state.z[v] - model.middle[v]);
            }
            p.push(*col, *col, diag);
        }
    }
    if let Some(t) = layout.t_col {
        p.push(t, t, 2.0 * rho_z);
        c[t] = if model.objective == Objective::MinThickness {
            1.0
        } else {
            -1.0
        };
    }
    for k in 0..model.residual.len() {
        c[layout.e_plus + k] = input.nu;
        c[layout.e_minus + k] = input.nu;
    }
    for k in 0..model.joints.len() {
        c[layout.j_start + k] = input.nu;
    }
    match model.objective {
        Objective::MinThrust => {
            for k in 0..model.supports.len() {
                c[layout.h_start + k] = 1.0 / model.total_load;
            }
        }
        Objective::MaxThrust => {
            for (col, g) in thrust_gradient(model, state) {
                c[layout.q_col[col].expect("support edges carry force")] -= g;
            }
        }
        _ => {}
    }
    (p, c)
}

/// ∂(thrust)/∂q_e per support edge e, thrust = Σ |H_a| / W; where H_a = 0 the direction of
/// the edges' plan vectors stands in for the unit reaction.
fn thrust_gradient(model: &Model, state: &State) -> Vec<(usize, f64)> {
    let r = model.reactions(&state.q);
    let u = &model.stress.plan.u;
    let mut fallback = vec![[0.0; 2]; u.len()];
    for &(_, a, j) in &model.support_edges {
        let (a, j) = (a as usize, j as usize);
        fallback[a] = [
            fallback[a][0] + u[a][0] - u[j][0],
            fallback[a][1] + u[a][1] - u[j][1],
        ];
    }
    (model.support_edges.iter())
        .map(|&(e, a, j)| {
            let (a, j) = (a as usize, j as usize);
            let dir = if r[a][0].hypot(r[a][1]) > 1e-12 {
                r[a]
            } else {
                fallback[a]
            };
            let len = dir[0].hypot(dir[1]).max(f64::MIN_POSITIVE);
            let g = (dir[0] * (u[a][0] - u[j][0]) + dir[1] * (u[a][1] - u[j][1])) / len;
            (e, g / model.total_load)
        })
        .collect()
}

/// dq_e − S_e dy = S_e y − q_e for every edge with force.
fn force_rows(model: &Model, layout: &Layout, state: &State, rows: &mut Rows) {
    let s = model.stress.s();
    for (e, col) in layout.q_col.iter().enumerate() {
        let Some(col) = col else { continue };
        let row = rows.next();
        rows.a.push(row, *col, 1.0);
        let mut sy = 0.0;
        for (c, v) in s.row(e) {
            rows.a.push(row, c, -v);
            sy += v * state.y[c];
        }
        rows.b.push(sy - state.q[e]);
    }
}

/// The linearised vertical residual with its elastic slacks:
/// Σ (z_i − z_j) dq_e + Σ q_e (dz_i − dz_j) − ∂p_i/∂t dt − e⁺ + e⁻ = −c_i (− correction).
fn vertical_rows(
    model: &Model,
    layout: &Layout,
    state: &State,
    correction: Option<&Correction>,
    rows: &mut Rows,
) {
    let c = model.residuals(state);
    let edges = &model.problem.mesh.edges;
    for (k, &i) in model.residual.iter().enumerate() {
        let i = i as usize;
        let row = rows.next();
        for &e in &model.incident[i] {
            let e = e as usize;
            let Some(qc) = layout.q_col[e] else { continue };
            let j = other_end(edges[e].v, i);
            rows.a.push(row, qc, state.z[i] - state.z[j]);
            if let Some(zc) = layout.z_col[i] {
                rows.a.push(row, zc, state.q[e]);
            }
            if let Some(zc) = layout.z_col[j] {
                rows.a.push(row, zc, -state.q[e]);
            }
        }
        if let (Some(t), Objective::MaxLoad) = (layout.t_col, model.objective) {
            rows.a.push(row, t, -model.live[i]);
        }
        rows.a.push(row, layout.e_plus + k, -1.0);
        rows.a.push(row, layout.e_minus + k, 1.0);
        rows.b.push(-c[k] - correction.map_or(0.0, |x| x.rows[k]));
    }
}

/// Horizontal balance at the free boundary vertices: Σ (u_v − u_j) dq_e = −(its imbalance).
fn horizontal_rows(model: &Model, layout: &Layout, state: &State, rows: &mut Rows) {
    let edges = &model.problem.mesh.edges;
    let u = &model.stress.plan.u;
    for &v in &model.stress.balance {
        let v = v as usize;
        for (d, &external) in model.stress.external[v].iter().enumerate() {
            let row = rows.next();
            let mut imbalance = external;
            for &e in &model.incident[v] {
                let e = e as usize;
                let Some(qc) = layout.q_col[e] else { continue };
                let du = u[v][d] - u[other_end(edges[e].v, v)][d];
                rows.a.push(row, qc, du);
                imbalance += state.q[e] * du;
            }
            rows.b.push(-imbalance);
        }
    }
}

/// q_e + dq_e = 0 on every edge that no compressive state in horizontal balance loads
/// (method.md §16.3) and whose bounds admit 0: its bound q_e ≥ 0 would hold as an equality
/// at every feasible point, leaving the interior-point solver no interior.
fn idle_rows(model: &Model, layout: &Layout, state: &State, rows: &mut Rows) {
    for (e, col) in layout.q_col.iter().enumerate() {
        if let (Some(col), true) = (col, pinned(model, e)) {
            let row = rows.next();
            rows.a.push(row, *col, 1.0);
            rows.b.push(-state.q[e]);
        }
    }
}

/// Whether edge `e` is held at zero force by an equation instead of its bounds.
fn pinned(model: &Model, e: usize) -> bool {
    let admits_zero = (model.stress.bounds[e]).is_some_and(|(lo, hi)| lo <= 0.0 && hi >= 0.0);
    !model.carries[e] && admits_zero
}

/// Force-density bounds, the envelope (scaled by s + ds for the least thickness), e± ≥ 0
/// and s ≥ 0, as rows A d ≤ b.
fn bound_rows(model: &Model, layout: &Layout, state: &State, rows: &mut Rows) {
    for (e, bound) in model.stress.bounds.iter().enumerate() {
        let (Some((lo, hi)), Some(col)) = (bound, layout.q_col[e]) else {
            continue;
        };
        if pinned(model, e) {
            continue;
        }
        let row = rows.next();
        rows.a.push(row, col, -1.0);
        rows.b.push(state.q[e] - lo);
        if hi.is_finite() {
            let row = rows.next();
            rows.a.push(row, col, 1.0);
            rows.b.push(hi - state.q[e]);
        }
    }
    let thickness = model.objective == Objective::MinThickness;
    let s = model.scale(state);
    let mesh = &model.problem.mesh;
    for v in (0..state.z.len()).filter(|&v| mesh.referenced[v]) {
        let zc = layout.z_col[v];
        if zc.is_none() && !thickness {
            continue;
        }
        let (m, h, z) = (model.middle[v], model.half[v], state.z[v]);
        for (sign, b) in [(-1.0, z - m + s * h), (1.0, m + s * h - z)] {
            let row = rows.next();
            if let Some(zc) = zc {
                rows.a.push(row, zc, sign);
            }
            if let (true, Some(t)) = (thickness, layout.t_col) {
                rows.a.push(row, t, -h);
            }
            rows.b.push(b);
        }
    }
    for k in 0..2 * model.residual.len() + model.joints.len() {
        let row = rows.next();
        rows.a.push(row, layout.e_plus + k, -1.0);
        rows.b.push(0.0);
    }
    springing_rows(model, layout, state, rows);
    if let (true, Some(t)) = (thickness, layout.t_col) {
        let row = rows.next();
        rows.a.push(row, t, -1.0);
        rows.b.push(state.t);
    }
}

/// The least thrust: h_a ≥ |H_a + dH_a| per support, a second-order cone of size 3.
fn thrust_cones(model: &Model, layout: &Layout, state: &State, rows: &mut Rows) {
    if model.objective != Objective::MinThrust {
        return;
    }
    let r = model.reactions(&state.q);
    let u = &model.stress.plan.u;
    let mut first_row = vec![usize::MAX; u.len()];
    for (k, &a) in model.supports.iter().enumerate() {
        let row = rows.next();
        first_row[a as usize] = row;
        rows.a.push(row, layout.h_start + k, -1.0);
        rows.b.push(0.0);
        rows.b.push(r[a as usize][0]);
        rows.b.push(r[a as usize][1]);
    }
    for &(e, a, j) in &model.support_edges {
        let (a, j) = (a as usize, j as usize);
        let col = layout.q_col[e].expect("support edges carry force");
        for (d, (ua, uj)) in u[a].iter().zip(&u[j]).enumerate() {
            rows.a.push(first_row[a] + 1 + d, col, -(ua - uj));
        }
    }
}

/// z_a + dz_a ≥ m − (σ + dσ)(m − s) at each joint: the support on or above its springing
/// plane.
fn springing_rows(model: &Model, layout: &Layout, state: &State, rows: &mut Rows) {
    let thickness = model.objective == Objective::MinThickness;
    for (k, joint) in model.joints.iter().enumerate() {
        let Some(zc) = layout.z_col[joint.support as usize] else {
            continue;
        };
        let w = model.joint_state(state, k).w;
        let row = rows.next();
        rows.a.push(row, zc, -1.0);
        if let (true, Some(t)) = (thickness, layout.t_col) {
            rows.a.push(row, t, -model.springing_rate(k));
        }
        rows.b.push(w);
    }
}

/// The springing joints, linearised: (w + dw)·(H + dH)/u as the cone's vector and
/// ((σ + dσ)(V + dV) b + e)/u as its bound, u the joint's unit (the bilinear products to
/// first order): ‖w H + w dH + dw H‖ ≤ σ b V + σ b dV + b V dσ + u e, e ≥ 0 priced at ν;
/// with a correction, its second-order terms added.
fn joint_cones(
    model: &Model,
    layout: &Layout,
    state: &State,
    correction: Option<&Correction>,
    rows: &mut Rows,
) {
    let u = &model.stress.plan.u;
    for (k, joint) in model.joints.iter().enumerate() {
        let a = joint.support as usize;
        let js = model.joint_state(state, k);
        let (unit, b) = (joint.unit(), joint.reach);
        let second = correction.map_or([0.0; 3], |c| c.joints[k]);
        let first = rows.next();
        // Bound: s0 = σbV/u + σb dV/u + bV dσ/u + e; rows hold −coefficients.
        rows.b.push(js.scale * b * js.v / unit + second[0]);
        rows.b.push(js.w * js.h[0] / unit + second[1]);
        rows.b.push(js.w * js.h[1] / unit + second[2]);
        rows.a.push(first, layout.j_start + k, -1.0);
        let vb = js.scale * b / unit;
        for &(e, j) in &joint.edges {
            let j = j as usize;
            let Some(qc) = layout.q_col[e] else { continue };
            rows.a.push(first, qc, -vb * (state.z[j] - state.z[a]));
            if let Some(zc) = layout.z_col[j] {
                rows.a.push(first, zc, -vb * state.q[e]);
            }
            for (d, (ua, uj)) in u[a].iter().zip(&u[j]).enumerate() {
                rows.a.push(first + 1 + d, qc, -js.w * (ua - uj) / unit);
            }
        }
        let dv_dza: f64 = joint.edges.iter().map(|&(e, _)| -state.q[e]).sum();
        if let Some(zc) = layout.z_col[a] {
            rows.a.push(first, zc, -vb * dv_dza);
            for d in 0..2 {
                rows.a.push(first + 1 + d, zc, -js.h[d] / unit);
            }
        }
        match (model.objective, layout.t_col) {
            (Objective::MaxLoad, Some(t)) => rows.a.push(first, t, -vb * model.live[a]),
            (Objective::MinThickness, Some(t)) => {
                rows.a.push(first, t, -b * js.v / unit);
                let dw = model.springing_rate(k);
                for d in 0..2 {
                    rows.a.push(first + 1 + d, t, -dw * js.h[d] / unit);
                }
            }
            _ => {}
        }
    }
}

/// The largest primal residual of a QP stopped short of optimality whose step is tried.
const PRIMAL_SLACK: f64 = 1e-8;

/// The QP's solution and, when it was solved, its multipliers.
type Solution = (Vec<f64>, Option<Vec<f64>>);

fn run_clarabel(n: usize, p: Triplets, c: &[f64], rows: Rows) -> Option<Solution> {
    let m = rows.b.len();
    let pm = CscMatrix::new_from_triplets(n, n, p.i, p.j, p.v);
    let am = CscMatrix::new_from_triplets(m, n, rows.a.i, rows.a.j, rows.a.v);
    let mut cones = vec![
        SupportedConeT::ZeroConeT(rows.n_zero),
        SupportedConeT::NonnegativeConeT(rows.n_nonneg),
    ];
    cones.extend((0..rows.n_soc).map(|_| SupportedConeT::SecondOrderConeT(3)));
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(200)
        .tol_gap_abs(1e-10)
        .tol_gap_rel(1e-10)
        .tol_feas(1e-10)
        .build()
        .expect("static clarabel settings are valid");
    let mut solver = DefaultSolver::new(&pm, c, &am, &rows.b, &cones, settings).ok()?;
    solver.solve();
    let solution = &solver.solution;
    if std::env::var_os("VSR_ASSESS_TRACE").is_some() {
        eprintln!(
            "qp {:?} {} it {:.3}s rprim {:.1e}",
            solution.status, solution.iterations, solution.solve_time, solution.r_prim
        );
    }
    match solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {
            Some((solution.x.clone(), Some(solution.z.clone())))
        }
        // An interior point that stopped short of optimality but meets the constraints
        // is still a candidate step: the merit test judges it; its multipliers are not
        // used.
        SolverStatus::InsufficientProgress | SolverStatus::MaxIterations
            if solution.r_prim <= PRIMAL_SLACK && solution.x.iter().all(|x| x.is_finite()) =>
        {
            Some((solution.x.clone(), None))
        }
        _ => None,
    }
}

fn read_step(model: &Model, layout: &Layout, state: &State, x: &[f64]) -> Step {
    let dq: Vec<f64> = (layout.q_col.iter())
        .map(|c| c.map_or(0.0, |c| x[c]))
        .collect();
    let dz: Vec<f64> = (layout.z_col.iter())
        .map(|c| c.map_or(0.0, |c| x[c]))
        .collect();
    let dt = layout.t_col.map_or(0.0, |c| x[c]);
    let n_r = model.residual.len();
    let slack = (0..n_r)
        .map(|k| x[layout.e_plus + k].max(0.0) + x[layout.e_minus + k].max(0.0))
        .sum::<f64>()
        + (0..model.joints.len())
            .map(|k| x[layout.j_start + k].max(0.0))
            .sum::<f64>();
    let model_objective = match model.objective {
        Objective::Fit => (0..dz.len())
            .filter(|&v| model.variable[v])
            .map(|v| model.area[v] * (state.z[v] + dz[v] - model.middle[v]).powi(2))
            .sum(),
        Objective::MinThickness => state.t + dt,
        Objective::MinThrust => {
            (0..model.supports.len())
                .map(|k| x[layout.h_start + k])
                .sum::<f64>()
                / model.total_load
        }
        Objective::MaxThrust => {
            let g: f64 = (thrust_gradient(model, state).iter())
                .map(|&(e, g)| g * dq[e])
                .sum();
            -(model.thrust(&state.q) + g)
        }
        Objective::MaxLoad => -(state.t + dt),
    };
    Step {
        dy: x[..layout.n_y].to_vec(),
        dq,
        dz,
        dt,
        slack,
        model_objective,
        multipliers: None,
        joint_multiplier: 0.0,
        curvature: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assess::{AssessSettings, Envelope};
    use crate::{Mesh, Problem, Thickness};

    /// A free centre over six free supports on the unit circle: every support has a joint.
    fn fan() -> (Problem, Envelope) {
        let mut positions = vec![[0.0, 0.0, 0.5]];
        for k in 0..6 {
            let a = std::f64::consts::PI * k as f64 / 3.0;
            positions.push([a.cos(), a.sin(), 0.1 * k as f64]);
        }
        let faces: Vec<[u32; 3]> = (0..6u32).map(|k| [0, k + 1, (k + 1) % 6 + 1]).collect();
        let mesh = Mesh::new(positions, faces, &[1, 2, 3, 4, 5, 6]).unwrap();
        let envelope = Envelope::from_thickness(&mesh, &Thickness::Uniform(0.2)).unwrap();
        (Problem::new(mesh), envelope)
    }

    /// The constraints the correction completes: the residuals, then per joint its cone's
    /// bound and vector (`joint_cones`' units).
    fn constraints(model: &Model, state: &State) -> Vec<f64> {
        let mut values = model.residuals(state);
        for (k, joint) in model.joints.iter().enumerate() {
            let js = model.joint_state(state, k);
            let unit = joint.unit();
            values.push(js.scale * joint.reach * js.v / unit);
            values.extend(js.h.map(|h| js.w * h / unit));
        }
        values
    }

    fn along(state: &State, step: &Step, s: f64) -> State {
        let moved = |x: &[f64], dx: &[f64]| x.iter().zip(dx).map(|(x, d)| x + s * d).collect();
        State {
            y: Vec::new(),
            q: moved(&state.q, &step.dq),
            z: moved(&state.z, &step.dz),
            t: state.t + s * step.dt,
        }
    }

    /// The correction is what the linearisation leaves out: c(x + d) − c(x) − c'(x) d, with
    /// c'(x) d by central differences (exact but for rounding: c is a polynomial of degree
    /// at most three along d, whose cubic term the differences see as ε² times it).
    #[test]
    fn the_correction_is_the_constraints_remainder_along_the_step() {
        let (problem, envelope) = fan();
        for objective in [Objective::Fit, Objective::MinThickness, Objective::MaxLoad] {
            let settings = AssessSettings::default()
                .with_objective(objective)
                .with_load_pattern(vec![1.0; 7]);
            let model = Model::new(&problem, &envelope, &settings).unwrap();
            assert_eq!(model.joints.len(), 6, "{objective:?}");
            let wave = |k: usize, a: f64| 1.0 + a * ((k as f64) * 1.7).sin();
            let n_edges = model.problem.mesh.edges.len();
            let state = State {
                y: Vec::new(),
                q: (0..n_edges).map(|e| wave(e, 0.5)).collect(),
                z: (0..7)
                    .map(|v| model.middle[v] + 0.01 * wave(v, 1.0))
                    .collect(),
                t: 0.8,
            };
            let step = Step {
                dy: Vec::new(),
                dq: (0..n_edges).map(|e| 0.3 * wave(e + 3, 1.0)).collect(),
                dz: (0..7).map(|v| 0.05 * wave(v + 5, 1.0)).collect(),
                dt: 0.1,
                slack: 0.0,
                model_objective: 0.0,
                multipliers: None,
                joint_multiplier: 0.0,
                curvature: 0.0,
            };
            let correction = Correction::of(&model, &state, &step);
            let mut expected = correction.rows.clone();
            expected.extend(correction.joints.iter().flatten());
            let eps = 1e-5;
            let at = |s: f64| constraints(&model, &along(&state, &step, s));
            let (start, end, ahead, behind) = (at(0.0), at(1.0), at(eps), at(-eps));
            for (k, want) in expected.iter().enumerate() {
                let linear = (ahead[k] - behind[k]) / (2.0 * eps);
                let remainder = end[k] - start[k] - linear;
                assert!(
                    (remainder - want).abs() <= 1e-7 * (1.0 + want.abs()),
                    "{objective:?}, value {k}: remainder {remainder}, correction {want}"
                );
            }
            // The step is far from small: the terms are not negligible.
            assert!(expected.iter().any(|c| c.abs() > 1e-3), "{expected:?}");
        }
    }
}
