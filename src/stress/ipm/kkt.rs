//! The KKT residuals of an iterate, with the sizes of their terms, and the test of whether the
//! iterations still make progress.

use super::pattern::Normal;
use super::{abs_mul_t, abs_row_norm, dot, inf_norm, mul_t, Qp, Tolerances};

/// When `Kkt::near` holds, so that polishing may guess the active set: residuals within this
/// many times the tolerance, relative gap below `POLISH_GAP`.
const POLISH_FEAS: f64 = 1e3;
const POLISH_GAP: f64 = 1e-5;

/// The residuals of the KKT conditions at a point, each with the size of the terms that make
/// it up (a backward error: at the optimum E x ≈ f is often 0 while its terms are not).
pub(super) struct Kkt {
    pub(super) r_d: Vec<f64>,
    pub(super) r_e: Vec<f64>,
    pub(super) r_i: Vec<f64>,
    pub(super) gap: f64,
    pub(super) objective: f64,
    pub(super) dual_scale: f64,
    /// The rounding floor of the dual residual: `DUAL_ROUNDING` ulps of its largest sum of
    /// term sizes.
    pub(super) dual_floor: f64,
    pub(super) eq_scale: f64,
    pub(super) ineq_scale: f64,
}

impl Kkt {
    pub(super) fn new(
        qp: &Qp,
        normal: &Normal,
        x: &[f64],
        lambda: &[f64],
        s: &[f64],
        z: &[f64],
    ) -> Kkt {
        let n = x.len();
        let px = normal.mul_p(x);
        let et_l = mul_t(qp.eq, lambda, n);
        let gt_z = mul_t(qp.ineq, z, n);
        let r_d = (0..n)
            .map(|i| px[i] + qp.c[i] - et_l[i] - gt_z[i])
            .collect();
        let r_e = qp.eq.mul(x).iter().zip(qp.f).map(|(a, b)| a - b).collect();
        let gx = qp.ineq.mul(x);
        let r_i = (0..s.len()).map(|i| gx[i] - qp.h[i] - s[i]).collect();
        Kkt {
            r_d,
            r_e,
            r_i,
            gap: dot(s, z),
            objective: 0.5 * dot(x, &px) + dot(qp.c, x) + qp.constant,
            dual_scale: 1.0
                + inf_norm(qp.c)
                    .max(inf_norm(&px))
                    .max(inf_norm(&gt_z))
                    .max(inf_norm(&et_l)),
            dual_floor: DUAL_ROUNDING
                * f64::EPSILON
                * inf_norm(
                    &normal
                        .mul_p_abs(x)
                        .iter()
                        .zip(abs_mul_t(qp.eq, lambda, n))
                        .zip(abs_mul_t(qp.ineq, z, n))
                        .zip(qp.c)
                        .map(|(((p, e), g), c)| p + e + g + c.abs())
                        .collect::<Vec<f64>>(),
                ),
            eq_scale: 1.0 + inf_norm(qp.f).max(abs_row_norm(qp.eq, x)),
            ineq_scale: 1.0 + inf_norm(qp.h).max(abs_row_norm(qp.ineq, x)),
        }
    }

    pub(super) fn feasible(&self, tol: &Tolerances, k: f64) -> bool {
        inf_norm(&self.r_d) <= k * (tol.dual_feas * self.dual_scale).max(self.dual_floor)
            && inf_norm(&self.r_e) <= k * tol.feas * self.eq_scale
            && inf_norm(&self.r_i) <= k * tol.feas * self.ineq_scale
    }

    /// How many times their tolerances the residuals (the largest of the three) and the gap
    /// are.
    pub(super) fn excess(&self, tol: &Tolerances) -> [f64; 2] {
        let residuals = (inf_norm(&self.r_d)
            / (tol.dual_feas * self.dual_scale).max(self.dual_floor))
        .max(inf_norm(&self.r_e) / (tol.feas * self.eq_scale))
        .max(inf_norm(&self.r_i) / (tol.feas * self.ineq_scale));
        [
            residuals,
            self.gap / (tol.gap_abs + tol.gap_rel * self.objective.abs()),
        ]
    }

    /// Meets the tolerances relaxed k times.
    pub(super) fn within(&self, tol: &Tolerances, k: f64) -> bool {
        self.feasible(tol, k) && self.gap <= k * (tol.gap_abs + tol.gap_rel * self.objective.abs())
    }

    /// Close enough to the optimum for the active set to be guessed.
    pub(super) fn near(&self, tol: &Tolerances) -> bool {
        self.feasible(tol, POLISH_FEAS) && self.gap <= POLISH_GAP * (1.0 + self.objective.abs())
    }
}

/// The dual residual is accepted within this many ulps of the largest sum of absolute terms
/// in a row of P x + c − Eᵀλ − Gᵀz: below that it is rounding, because weights and Airy values
/// can be 10⁶–10⁷ in the scaled unknowns while P x is O(1), and where the optimum is flat the
/// iterates drift along it with the solves' rounding (100 ulps is still a backward error of
/// about 2e-14).
pub(super) const DUAL_ROUNDING: f64 = 100.0;

/// Iterations without progress after which `Progress` declares a stall.
pub(super) const STALL_WINDOW: u32 = 10;

/// Whether the iterations still make progress: the residuals halving or the gap falling
/// tenfold (against where they stood at the last such progress) within `STALL_WINDOW`
/// iterations. A stall is an exit where `Tolerances::stall_exits` says so: beyond 20k unknowns
/// (`fallback_is_costly`: the caller then keeps the answer at hand), because there iterations
/// whose directions have gone inexact can crawl to the iteration limit without improving the
/// answer, and in form finding where another native attempt with the same optimum follows.
pub(super) struct Progress {
    pub(super) reference: [f64; 2],
    pub(super) since: u32,
}

impl Progress {
    pub(super) fn new() -> Progress {
        Progress {
            reference: [f64::INFINITY; 2],
            since: 0,
        }
    }

    /// Records an iterate's `Kkt::excess`; true once it has made no progress for
    /// `STALL_WINDOW` iterations.
    pub(super) fn stalled(&mut self, iteration: u32, [residuals, gap]: [f64; 2]) -> bool {
        let [r, g] = self.reference;
        if residuals < 0.5 * r || gap < 0.1 * g {
            self.reference = [r.min(residuals), g.min(gap)];
            self.since = iteration;
        }
        iteration - self.since >= STALL_WINDOW
    }
}
