//! The stress QP of docs/method.md §8, shared by the reduced and the edge-based formulations
//! (§9): both give q = S y for their own unknowns y, and differ only in S and in which vertices
//! need explicit horizontal balance rows.
//!
//!   minimise    ‖r‖² + ε Σ_e (l_e q_e)² + μ Σ_(a,b) (l_a q_a − l_b q_b)²
//!   subject to  r = G S y − p             (vertical residuals, lifted: keeps the KKT sparse)
//!               H S y − τ ν = −P          (horizontal balance rows)
//!               lower ≤ S y ≤ upper on active edges,  τ ≥ 0

use super::ipm;
use super::sparse::{Csr, Triplets};
use super::StressStatus;

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, SupportedConeT};

/// Everything the QP needs, in frame (nondimensional) units.
pub struct QpInput<'a> {
    /// q (one entry per mesh edge) = s · y.
    pub s: &'a Csr,
    /// Edge end points.
    pub edges: &'a [[u32; 2]],
    /// Plan length per edge (for the regulariser).
    pub length: &'a [f64],
    /// Plan positions and heights per vertex.
    pub u: &'a [[f64; 2]],
    pub z: &'a [f64],
    /// Vertices whose vertical residual is minimised, and their loads.
    pub residual_vertices: &'a [u32],
    pub load: &'a [f64],
    /// Vertices with hard horizontal balance, their external force P and fixed normal push.
    pub balance_vertices: &'a [u32],
    pub external: &'a [[f64; 2]],
    /// Per vertex: Some(normal) when an optimised τ ≥ 0 acts along −normal at that vertex.
    pub tau_normal: &'a [Option<[f64; 2]>],
    /// Per edge: None for an edge without force, else (lower, upper) bounds on q.
    pub bounds: &'a [Option<(f64, f64)>],
    pub regularisation: f64,
    /// Centre q̂ of the regulariser ε Σ l_e² (q_e − q̂_e)² (per edge); None: q̂ = 0.
    pub prior: Option<&'a [f64]>,
    /// Pairs of edges whose dual lengths l q are pulled together, and the weight μ.
    pub smoothing_pairs: &'a [[usize; 2]],
    pub smoothing: f64,
    /// Lift the force densities as variables (q − S y = 0, simple bounds on q). Needed when S
    /// is not a selection: bounds on combinations S y make degenerate problems (straight free
    /// edges force q = 0, so no strictly feasible point) numerically fragile.
    pub lift_forces: bool,
}

/// What the solver returned.
pub struct QpOutput {
    pub y: Vec<f64>,
    /// Optimised τ per vertex (0 where none).
    pub tau: Vec<f64>,
    pub status: StressStatus,
    pub iterations: u32,
    /// Solved to coarse optimality (`ipm::Tolerances::for_form_finding` beyond 20k unknowns).
    pub coarse: bool,
    /// Solved to a looser relative gap than the tolerances' (`solve_native`'s `inexact`).
    pub inexact: bool,
}

/// One row l_a force_a − l_b force_b per smoothing pair (columns may repeat; they add up).
pub(super) fn smoothing_rows<'a>(
    inp: &'a QpInput,
    force: &'a Csr,
) -> impl Iterator<Item = Vec<(usize, f64)>> + 'a {
    inp.smoothing_pairs.iter().map(move |&[a, b]| {
        let (la, lb) = (inp.length[a], inp.length[b]);
        force
            .row(a)
            .map(|(c, v)| (c, la * v))
            .chain(force.row(b).map(|(c, v)| (c, -lb * v)))
            .collect()
    })
}

/// Per vertex, the column of its optimised τ (numbered from `first`, in vertex order), and
/// how many there are.
pub(super) fn tau_columns(inp: &QpInput, first: usize) -> (Vec<Option<usize>>, usize) {
    let mut tau_col = vec![None; inp.u.len()];
    let mut n_tau = 0;
    for (v, nrm) in inp.tau_normal.iter().enumerate() {
        if nrm.is_some() {
            tau_col[v] = Some(first + n_tau);
            n_tau += 1;
        }
    }
    (tau_col, n_tau)
}

/// Per vertex, its incident edges that carry a force (those with bounds).
pub(super) fn incident_edges(inp: &QpInput) -> Vec<Vec<usize>> {
    let mut incident: Vec<Vec<usize>> = vec![Vec::new(); inp.u.len()];
    for (e, ev) in inp.edges.iter().enumerate() {
        if inp.bounds[e].is_some() {
            incident[ev[0] as usize].push(e);
            incident[ev[1] as usize].push(e);
        }
    }
    incident
}

/// The end of edge `e` that is not `v`.
pub(super) fn other_end(inp: &QpInput, e: usize, v: usize) -> usize {
    let ev = inp.edges[e];
    if ev[0] as usize == v {
        ev[1] as usize
    } else {
        ev[0] as usize
    }
}

/// The selection of lifted force-density variables (columns after y) per edge with a force.
fn lifted_selection(inp: &QpInput) -> Csr {
    let n_y = inp.s.ncols;
    let mut sel = Csr::new(n_y + inp.bounds.iter().flatten().count());
    let mut c = n_y;
    for b in inp.bounds {
        sel.push_row(if b.is_some() {
            vec![(c, 1.0)]
        } else {
            Vec::new()
        });
        c += b.is_some() as usize;
    }
    sel
}

/// The variables of clarabel's QP: the map `force` from them to q, and the columns of τ and
/// of the residuals r after it.
struct ClarabelColumns<'a> {
    force: &'a Csr,
    tau_col: Vec<Option<usize>>,
    r_start: usize,
    n: usize,
}

/// clarabel's objective ½ xᵀ P x with P = 2 (ε Sᵀ D S + μ Σ_pairs a aᵀ ⊕ 0 ⊕ I), upper
/// triangle (a: the smoothing row l_a S_a − l_b S_b).
fn clarabel_objective(inp: &QpInput, cols: &ClarabelColumns) -> Triplets {
    let force = cols.force;
    let mut p = Triplets::default();
    for e in 0..force.nrows() {
        let w = 2.0 * inp.regularisation * inp.length[e] * inp.length[e];
        for (c1, v1) in force.row(e) {
            for (c2, v2) in force.row(e) {
                if c1 <= c2 {
                    p.push(c1, c2, w * v1 * v2);
                }
            }
        }
    }
    if inp.smoothing > 0.0 {
        for row in smoothing_rows(inp, force) {
            for &(c1, v1) in &row {
                for &(c2, v2) in &row {
                    if c1 <= c2 {
                        p.push(c1, c2, 2.0 * inp.smoothing * v1 * v2);
                    }
                }
            }
        }
    }
    for k in 0..inp.residual_vertices.len() {
        p.push(cols.r_start + k, cols.r_start + k, 2.0);
    }
    p
}

/// clarabel's constraint rows A x + s = b, s in the cones, in the order the cones take them.
struct ClarabelRows {
    a: Triplets,
    b: Vec<f64>,
    /// Rows in the zero cone (the first ones); the others are non-negative.
    n_zero: usize,
}

impl ClarabelRows {
    fn count(&self) -> usize {
        self.b.len()
    }
}

/// The equality rows of clarabel's QP: vertical residuals, horizontal balance and, lifted,
/// q_e − S_e y = 0.
fn clarabel_equalities(inp: &QpInput, cols: &ClarabelColumns) -> ClarabelRows {
    let (force, tau_col, r_start) = (cols.force, &cols.tau_col, cols.r_start);
    let incident = incident_edges(inp);
    let mut a = Triplets::default();
    let mut b = Vec::new();
    let mut row = 0;
    // Vertical residuals: Σ_e (z_i − z_j) q_e − r_i = p_i.
    for (k, &i) in inp.residual_vertices.iter().enumerate() {
        for &e in &incident[i as usize] {
            let dz = inp.z[i as usize] - inp.z[other_end(inp, e, i as usize)];
            for (c, s) in force.row(e) {
                a.push(row, c, dz * s);
            }
        }
        a.push(row, r_start + k, -1.0);
        b.push(inp.load[i as usize]);
        row += 1;
    }
    // Horizontal balance: Σ_e (u_i − u_j) q_e − τ_i ν_i = −P_i.
    for &i in inp.balance_vertices {
        for d in 0..2 {
            for &e in &incident[i as usize] {
                let du = inp.u[i as usize][d] - inp.u[other_end(inp, e, i as usize)][d];
                for (c, s) in force.row(e) {
                    a.push(row, c, du * s);
                }
            }
            if let (Some(c), Some(nrm)) = (tau_col[i as usize], inp.tau_normal[i as usize]) {
                a.push(row, c, -nrm[d]);
            }
            b.push(-inp.external[i as usize][d]);
            row += 1;
        }
    }
    // Lifted forces: q_e − S_e y = 0.
    if inp.lift_forces {
        for e in 0..force.nrows() {
            for (c, v) in force.row(e) {
                a.push(row, c, v);
                for (c, s) in inp.s.row(e) {
                    a.push(row, c, -s);
                }
                b.push(0.0);
                row += 1;
            }
        }
    }
    ClarabelRows { a, b, n_zero: row }
}

/// Appends the inequality rows: q_e − lower ≥ 0, upper − q_e ≥ 0, τ ≥ 0.
fn clarabel_bounds(inp: &QpInput, cols: &ClarabelColumns, rows: &mut ClarabelRows) {
    let force = cols.force;
    let (a, b) = (&mut rows.a, &mut rows.b);
    let mut row = b.len();
    for (e, bound) in inp.bounds.iter().enumerate() {
        if let Some((lower, _)) = bound {
            for (c, s) in force.row(e) {
                a.push(row, c, -s);
            }
            b.push(-lower);
            row += 1;
        }
    }
    for (e, bound) in inp.bounds.iter().enumerate() {
        if let Some((_, upper)) = bound.filter(|(_, u)| u.is_finite()) {
            for (c, s) in force.row(e) {
                a.push(row, c, s);
            }
            b.push(upper);
            row += 1;
        }
    }
    for c in cols.tau_col.iter().flatten() {
        a.push(row, *c, -1.0);
        b.push(0.0);
        row += 1;
    }
}

/// Linear part of the regulariser around the prior: −2 ε l² q̂ on each q_e.
fn clarabel_linear_term(inp: &QpInput, cols: &ClarabelColumns) -> Vec<f64> {
    let mut q = vec![0.0; cols.n];
    if let Some(prior) = inp.prior {
        for (e, centre) in prior.iter().enumerate() {
            let w = -2.0 * inp.regularisation * inp.length[e] * inp.length[e] * centre;
            for (c, v) in cols.force.row(e) {
                q[c] += w * v;
            }
        }
    }
    q
}

/// The reference path: clarabel on the (optionally lifted) QP.
pub fn solve_clarabel(inp: &QpInput) -> QpOutput {
    let n_y = inp.s.ncols;
    let n_vertices = inp.u.len();
    // `force` maps the QP variables to q: S itself, or a selection of lifted q variables.
    let lifted = inp.lift_forces.then(|| lifted_selection(inp));
    let force = lifted.as_ref().unwrap_or(inp.s);
    let n_base = force.ncols;
    let (tau_col, n_tau) = tau_columns(inp, n_base);
    let r_start = n_base + n_tau;
    let cols = ClarabelColumns {
        force,
        tau_col,
        r_start,
        n: r_start + inp.residual_vertices.len(),
    };
    let n = cols.n;
    let p = clarabel_objective(inp, &cols);
    let mut rows = clarabel_equalities(inp, &cols);
    clarabel_bounds(inp, &cols, &mut rows);
    let row = rows.count();
    let pm = CscMatrix::new_from_triplets(n, n, p.i, p.j, p.v);
    let am = CscMatrix::new_from_triplets(row, n, rows.a.i, rows.a.j, rows.a.v);
    let q = clarabel_linear_term(inp, &cols);
    let cones = [
        SupportedConeT::ZeroConeT(rows.n_zero),
        SupportedConeT::NonnegativeConeT(row - rows.n_zero),
    ];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(200)
        // Tighter than the defaults (1e-8): the residual vector must be reproducible to ~1e-6
        // of the mean load, and the objective is often flat near its optimum.
        .tol_gap_abs(1e-11)
        .tol_gap_rel(1e-11)
        .tol_feas(1e-10)
        .build()
        .expect("static clarabel settings are valid");
    let mut solver = match DefaultSolver::new(&pm, &q, &am, &rows.b, &cones, settings) {
        Ok(s) => s,
        Err(_) => {
            return QpOutput {
                y: vec![0.0; n_y],
                tau: vec![0.0; n_vertices],
                status: StressStatus::NumericalError,
                iterations: 0,
                coarse: false,
                inexact: false,
            }
        }
    };
    solver.solve();
    let x = &solver.solution.x;
    let tau = cols
        .tau_col
        .iter()
        .map(|c| c.map_or(0.0, |c| x[c]))
        .collect();
    QpOutput {
        y: x[..n_y].to_vec(),
        tau,
        status: StressStatus::from_clarabel(solver.solution.status),
        iterations: solver.solution.iterations,
        coarse: false,
        inexact: false,
    }
}

/// The native QP's objective ½ xᵀ P x + cᵀ x + constant, P = Σ_k w_k a_kᵀ a_k with the rows
/// a_k of `quad` and weights w_k: ‖B y − p‖² with B = G S (one row per residual vertex),
/// ε Σ l² (S_e y − q̂_e)² and the smoothing rows μ (l_a S_a y − l_b S_b y)².
struct NativeObjective {
    quad: Csr,
    weight: Vec<f64>,
    c: Vec<f64>,
    constant: f64,
}

fn native_objective(inp: &QpInput, incident: &[Vec<usize>], n: usize) -> NativeObjective {
    let mut quad = Csr::new(n);
    let mut weight = Vec::new();
    let mut c = vec![0.0; n];
    let mut constant = 0.0;
    for &i in inp.residual_vertices {
        let i = i as usize;
        let mut row = Vec::new();
        for &e in &incident[i] {
            let dz = inp.z[i] - inp.z[other_end(inp, e, i)];
            row.extend(inp.s.row(e).map(|(col, v)| (col, dz * v)));
        }
        quad.push_row(row);
        weight.push(2.0);
        let p = inp.load[i];
        let r = quad.nrows() - 1;
        for (col, v) in quad.row(r) {
            c[col] -= 2.0 * p * v;
        }
        constant += p * p;
    }
    if inp.regularisation > 0.0 {
        for (e, bound) in inp.bounds.iter().enumerate() {
            if bound.is_none() {
                continue;
            }
            let w = inp.regularisation * inp.length[e] * inp.length[e];
            quad.push_row(inp.s.row(e).collect());
            weight.push(2.0 * w);
            if let Some(prior) = inp.prior {
                for (col, v) in inp.s.row(e) {
                    c[col] -= 2.0 * w * prior[e] * v;
                }
                constant += w * prior[e] * prior[e];
            }
        }
    }
    if inp.smoothing > 0.0 {
        for row in smoothing_rows(inp, inp.s) {
            quad.push_row(row);
            weight.push(2.0 * inp.smoothing);
        }
    }
    NativeObjective {
        quad,
        weight,
        c,
        constant,
    }
}

/// Horizontal balance rows of the native QP: Σ_e (u_i − u_j) S_e y − τ_i ν_i = −P_i.
pub(super) fn native_balance_rows(
    inp: &QpInput,
    incident: &[Vec<usize>],
    tau_col: &[Option<usize>],
    n: usize,
) -> (Csr, Vec<f64>) {
    let mut eq = Csr::new(n);
    let mut f = Vec::new();
    for &i in inp.balance_vertices {
        let i = i as usize;
        for d in 0..2 {
            let mut row = Vec::new();
            for &e in &incident[i] {
                let du = inp.u[i][d] - inp.u[other_end(inp, e, i)][d];
                row.extend(inp.s.row(e).map(|(col, v)| (col, du * v)));
            }
            if let (Some(col), Some(nrm)) = (tau_col[i], inp.tau_normal[i]) {
                row.push((col, -nrm[d]));
            }
            eq.push_row(row);
            f.push(-inp.external[i][d]);
        }
    }
    (eq, f)
}

/// Inequality rows of the native QP: S_e y ≥ lower, −S_e y ≥ −upper, τ ≥ 0, with their right
/// sides and the row of each edge's lower bound (`usize::MAX` for edges without one).
fn native_bound_rows(
    inp: &QpInput,
    tau_col: &[Option<usize>],
    n: usize,
) -> (Csr, Vec<f64>, Vec<usize>) {
    crate::interrupt::poll();
    let mut ineq = Csr::new(n);
    let mut h = Vec::new();
    let mut lower_row = vec![usize::MAX; inp.edges.len()];
    for (e, bound) in inp.bounds.iter().enumerate() {
        if let Some((lower, upper)) = bound {
            lower_row[e] = ineq.nrows();
            ineq.push_row(inp.s.row(e).collect());
            h.push(*lower);
            if upper.is_finite() {
                ineq.push_row(inp.s.row(e).map(|(col, v)| (col, -v)).collect());
                h.push(-upper);
            }
        }
    }
    for col in tau_col.iter().flatten() {
        ineq.push_row(vec![(*col, 1.0)]);
        h.push(0.0);
    }
    (ineq, h, lower_row)
}

/// The fast path: the structured interior-point method of `ipm.rs` on x = (y, τ), with the
/// residuals eliminated (‖G S y − p‖² expands into rows of the Hessian) so that the Newton
/// matrix lives in y space. `lift_forces` does not apply. `cache`: see `ipm::solve`;
/// `coarse`: solve to `ipm::Tolerances::for_form_finding` (coarse beyond 20k unknowns);
/// `inexact`: a relative gap to stop at where it is looser than the tolerances' (see
/// `ipm::Tolerances::inexact`); `stall_exit`: a stall ends the iterations (another native
/// attempt with the same optimum follows).
pub fn solve_native(
    inp: &QpInput,
    cache: &mut ipm::PatternCache,
    (coarse, inexact): (bool, Option<f64>),
    stall_exit: bool,
) -> QpOutput {
    let n = inp.s.ncols + inp.tau_normal.iter().flatten().count();
    let tol = if coarse {
        ipm::Tolerances::for_form_finding(n)
    } else {
        ipm::Tolerances::for_size(n)
    };
    let tol = if stall_exit {
        tol.with_stall_exit()
    } else {
        tol
    };
    let (tol, loosened) = match inexact {
        Some(gap) if gap > tol.gap_rel => (tol.inexact(gap), true),
        _ => (tol, false),
    };
    let mut out = solve_native_with(inp, cache, &tol);
    out.coarse = coarse && ipm::fallback_is_costly(n);
    out.inexact = loosened && out.status == StressStatus::Solved;
    out
}

/// `solve_native` with the tolerances `tol`.
pub fn solve_native_with(
    inp: &QpInput,
    cache: &mut ipm::PatternCache,
    tol: &ipm::Tolerances,
) -> QpOutput {
    crate::interrupt::poll();
    let n_y = inp.s.ncols;
    let (tau_col, n_tau) = tau_columns(inp, n_y);
    let n = n_y + n_tau;
    let incident = incident_edges(inp);
    let objective = native_objective(inp, &incident, n);
    let (eq, f) = native_balance_rows(inp, &incident, &tau_col, n);
    let (ineq, h, lower_row) = native_bound_rows(inp, &tau_col, n);
    let groups = balanced_stars(inp, &incident, &lower_row);
    let positions = unknown_positions(inp, &tau_col, n);
    let out = ipm::solve(
        &ipm::Qp {
            quad: &objective.quad,
            quad_weight: &objective.weight,
            c: &objective.c,
            constant: objective.constant,
            eq: &eq,
            f: &f,
            ineq: &ineq,
            h: &h,
            groups: &groups,
            positions: Some(&positions),
            slack_unit: Some(slack_unit(inp)),
        },
        tol,
        cache,
    );
    let tau = tau_col
        .iter()
        .map(|col| col.map_or(0.0, |col| out.x[col]))
        .collect();
    QpOutput {
        y: out.x[..n_y].to_vec(),
        tau,
        status: match out.status {
            ipm::IpmStatus::Solved => StressStatus::Solved,
            ipm::IpmStatus::AlmostSolved => StressStatus::AlmostSolved,
            ipm::IpmStatus::MaxIterations => StressStatus::MaxIterations,
            ipm::IpmStatus::NumericalError => StressStatus::NumericalError,
        },
        iterations: out.iterations,
        coarse: false,
        inexact: false,
    }
}

/// The interior-point start's slack unit, in multiples of the median ℓ_e² over the edges with
/// a bound (`slack_unit`): the start's constraint term is then (START_UNIT × median ℓ²)² Σ
/// (q − bound)² / `START_PENALTY`, one common factor, alike in both formulations, which bound
/// the same force densities. The median row scale (`ipm::caller_units`'s default) would make
/// the start depend on the unknowns, and start the edge-based formulation's force densities
/// far nearer their bounds than the reduced one's.
const START_UNIT: f64 = 10.0;

/// The QP's slack unit for the interior-point start: `START_UNIT` times the median ℓ_e² of
/// the edges with a bound, the same in both formulations.
fn slack_unit(inp: &QpInput) -> f64 {
    let l2: Vec<f64> = (0..inp.edges.len())
        .filter(|&e| inp.bounds[e].is_some())
        .map(|e| inp.length[e] * inp.length[e])
        .collect();
    START_UNIT * super::upper_median(l2).unwrap_or(1.0)
}

/// The plan position of each unknown of `solve_native`: for y, the mean of the midpoints of
/// the edges whose force density it enters; for τ, its vertex. (For the nested-dissection
/// ordering of large QPs: only nearness matters.)
fn unknown_positions(inp: &QpInput, tau_col: &[Option<usize>], n: usize) -> Vec<[f64; 2]> {
    let mut sum = vec![[0.0; 2]; n];
    let mut count = vec![0usize; n];
    for (e, ev) in inp.edges.iter().enumerate() {
        let [a, b] = ev.map(|v| inp.u[v as usize]);
        for (col, _) in inp.s.row(e) {
            sum[col] = [sum[col][0] + a[0] + b[0], sum[col][1] + a[1] + b[1]];
            count[col] += 2;
        }
    }
    for (v, col) in tau_col.iter().enumerate() {
        if let Some(col) = *col {
            (sum[col], count[col]) = (inp.u[v], 1);
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &k)| s.map(|s| s / k.max(1) as f64))
        .collect()
}

/// The lower-bound rows of the edges around each vertex where Σ_e (u_i − u_j) S_e = 0 holds
/// identically, with the edge vectors as coefficients (see `ipm::RowGroups`): every interior
/// vertex in reduced coordinates, none in the edge-based formulation (checked numerically,
/// not assumed: the identity must hold to rounding in every column).
fn balanced_stars(inp: &QpInput, incident: &[Vec<usize>], lower_row: &[usize]) -> ipm::RowGroups {
    let mut groups = ipm::RowGroups {
        start: vec![0],
        ..Default::default()
    };
    // u_i − u_j for the edge e = ij.
    let from = |i: usize, e: usize| {
        let [a, b] = inp.edges[e];
        let j = if a as usize == i { b } else { a } as usize;
        [inp.u[i][0] - inp.u[j][0], inp.u[i][1] - inp.u[j][1]]
    };
    // Per column: the two sums and the size of their terms, over the columns touched.
    let mut sum = vec![[0.0f64; 3]; inp.s.ncols];
    let mut touched = Vec::new();
    for (i, edges) in incident.iter().enumerate() {
        if edges.len() < 3 {
            continue;
        }
        touched.clear();
        for &e in edges {
            let d = from(i, e);
            for (col, v) in inp.s.row(e) {
                if sum[col][2] == 0.0 {
                    touched.push(col);
                }
                sum[col][0] += d[0] * v;
                sum[col][1] += d[1] * v;
                sum[col][2] += (d[0].abs() + d[1].abs()) * v.abs();
            }
        }
        let balanced = touched
            .iter()
            .all(|&col| sum[col][0].abs().max(sum[col][1].abs()) <= 1e-9 * sum[col][2]);
        for &col in &touched {
            sum[col] = [0.0; 3];
        }
        if balanced {
            for &e in edges {
                groups.row.push(lower_row[e]);
                groups.coef.push(from(i, e));
            }
            groups.start.push(groups.row.len());
        }
    }
    groups
}
