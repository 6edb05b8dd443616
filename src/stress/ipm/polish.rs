//! Polishing: the optimum for a guessed active set, solved for directly from an iterate or
//! from the previous form-finding step's answer, with the guess corrected where it was wrong.

use super::kkt::Kkt;
use super::newton::{FactorSpace, Newton, REGULARISATION};
use super::pattern::Normal;
use super::{mul_t, Qp, Tolerances};
use crate::stress::sparse::Csr;

/// The iterate polishing starts from (its slacks only enter through the active-set guess).
#[derive(Clone, Copy)]
pub(super) struct Point<'a> {
    pub(super) x: &'a [f64],
    pub(super) lambda: &'a [f64],
    pub(super) z: &'a [f64],
}

/// How many wrong rows `polish` corrects, and for how many rounds (rows the step violates
/// join the active set, rows whose multiplier comes out negative leave it).
#[derive(Clone, Copy)]
pub(super) enum Corrections {
    /// From an iterate's guess: a few rows, up to `POLISH_ROUNDS` times; more wrong rows
    /// than a share 1 / `POLISH_CORRECTABLE` of the active ones mean dependent active rows
    /// or an early guess, which further rounds would only chase.
    Few,
    /// From the previous form-finding step's active set (a primal–dual active-set method):
    /// every wrong row, up to `WARM_ROUNDS` times, while their number at least halves each
    /// round, because between late steps tens to hundreds of rows change, and a count that
    /// stops halving marks an early step where the attempt only costs factorisations.
    AllWhileFewer,
}
pub(super) const POLISH_ROUNDS: usize = 3;
pub(super) const POLISH_CORRECTABLE: usize = 200;
/// An iterate's guess may always have this many rows corrected, and `HOPELESS` counts at
/// least this many as correctable.
pub(super) const MIN_CORRECTABLE: usize = 3;
pub(super) const WARM_ROUNDS: usize = 8;

/// The optimum `polish` reached: x, its active set, and the multipliers of the equality rows
/// and of the inequality rows (0 on inactive ones), which a later QP may start from.
pub(super) struct Polished {
    pub(super) x: Vec<f64>,
    pub(super) active: Vec<bool>,
    pub(super) lambda: Vec<f64>,
    pub(super) z: Vec<f64>,
}

impl Polished {
    fn of(step: PolishStep, active: Vec<bool>) -> Polished {
        let z = step.multiplier.iter().map(|v| v.max(0.0)).collect();
        Polished {
            x: step.x,
            active,
            lambda: step.lambda,
            z,
        }
    }
}

/// Why `polish` did not reach the optimum, which decides when it is worth another attempt
/// (each costs a factorisation and several solves).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum PolishFailure {
    /// The guess had more wrong rows than a round may correct, or kept finding new ones:
    /// attempted again at the next iteration, because one more iteration usually settles it and,
    /// where the gap stalls at its rounding floor, a later guess is the way out.
    EarlyGuess,
    /// No row was wrong, yet the step missed the tolerances (or its solve failed), also when
    /// solved again without the rows that wholly active groups imply: the active set is right but
    /// the factor cannot resolve it that finely: attempted again only once the gap has fallen by
    /// `INEXACT_RETRY`, since the next iteration's guess would fail the same way.
    Inexact,
}

/// After an `Inexact` failure, the factor by which the gap must fall before the next attempt,
/// so that hopeless attempts do not cost a factorisation every iteration.
pub(super) const INEXACT_RETRY: f64 = 1e-2;

/// A polishing round is given up before its refinement when the unrefined step is wrong in
/// more than this many times the rows the round may correct, counted as at least
/// `MIN_CORRECTABLE` (an unrefined step may show a wrong row that refinement removes), since
/// refining a step that far off costs solves and cannot save the guess. A step from a factor
/// that refinement would have found unsound is judged the same way, as an early guess.
pub(super) const HOPELESS: usize = 4;

/// The optimum for the active set `guess` (see `active_guess`: inequalities with z > s held
/// as equalities, the others dropped), accepted only if it meets every KKT condition: the
/// inactive inequalities hold and the active ones have non-negative multipliers. It is a
/// Newton step from the iterate, so it corrects the iterate's multipliers rather than
/// computing new ones: when the active rows are dependent any combination would balance,
/// and a fresh one need not be non-negative.
///
/// A guess with wrong rows is corrected as `corrections` says. An iterate's plain guess goes
/// wrong on degenerate rows (s and z both tending to 0): on the generated
/// groin vault one row with s = 7e-4, z = 2e-8 was violated by 1e-2 at every attempt, and
/// the gap needed five more iterations to close.
pub(super) fn polish(
    qp: &Qp,
    normal: &Normal,
    cons: &Csr,
    point: &Point,
    (guess, corrections): (&[bool], Corrections),
    tol: &Tolerances,
    space: &mut FactorSpace,
) -> Result<Polished, PolishFailure> {
    let m = guess.len();
    let mut active = guess.to_vec();
    let from = PolishFrom::new(qp, normal, point);
    let rounds = match corrections {
        Corrections::Few => POLISH_ROUNDS,
        Corrections::AllWhileFewer => WARM_ROUNDS,
    };
    let mut last_wrong = usize::MAX;
    // The answer is the point with the active rows on their bounds: their computed slack
    // (rounding of differences of large Airy values) is an inequality residual, held to its
    // tolerance, not complementarity, because counted in the gap it would keep right active
    // sets from being accepted.
    let kkt_of = |step: &PolishStep, active: &[bool]| {
        let s_new: Vec<f64> = (step.slack.iter().zip(active))
            .map(|(&s, &a)| if a { 0.0 } else { s.max(0.0) })
            .collect();
        let z_new: Vec<f64> = step.multiplier.iter().map(|v| v.max(0.0)).collect();
        Kkt::new(qp, normal, &step.x, &step.lambda, &s_new, &z_new)
    };
    // An inactive row is violated beyond its own bound's tolerance, not the residuals'
    // global scale, which large Airy values inflate far beside the bounds.
    let violated =
        |step: &PolishStep, i: usize| step.slack[i] < -row_tolerance(qp, &step.x, i, tol);
    // Rows where the step contradicts the guess: inactive rows it violates, active rows
    // whose multiplier comes out negative.
    let wrong_rows = |step: &PolishStep, kkt: &Kkt, active: &[bool]| -> Vec<usize> {
        let negative = tol.dual_feas * kkt.dual_scale;
        (0..m)
            .filter(|&i| {
                if active[i] {
                    step.multiplier[i] < -negative
                } else {
                    violated(step, i)
                }
            })
            .collect()
    };
    let feasible =
        |step: &PolishStep, active: &[bool]| (0..m).all(|i| active[i] || !violated(step, i));
    for _ in 0..rounds {
        let correctable = match corrections {
            Corrections::Few => {
                let n_active = active.iter().filter(|&&a| a).count();
                MIN_CORRECTABLE.max(n_active / POLISH_CORRECTABLE)
            }
            Corrections::AllWhileFewer => last_wrong / 2,
        };
        let hopeless = |rough: &PolishStep| {
            wrong_rows(rough, &kkt_of(rough, &active), &active).len()
                > HOPELESS.saturating_mul(correctable.max(MIN_CORRECTABLE))
        };
        let step = polish_step(
            qp,
            normal,
            cons,
            &from,
            (&active, false, &hopeless),
            tol,
            space,
        )?;
        let kkt = kkt_of(&step, &active);
        if kkt.within(tol, 1.0) && feasible(&step, &active) {
            return Ok(Polished::of(step, active));
        }
        let wrong = wrong_rows(&step, &kkt, &active);
        if wrong.is_empty() {
            // The right active set, missed by the factor's accuracy: where whole groups of
            // dependent rows are active, solved again without two rows each, because rounding
            // along those dependent combinations is amplified by 1/δ.
            if qp.groups.any_wholly_active(&active) {
                let never = |_: &PolishStep| false;
                let step =
                    polish_step(qp, normal, cons, &from, (&active, true, &never), tol, space)
                        .map_err(|_| PolishFailure::Inexact)?;
                if kkt_of(&step, &active).within(tol, 1.0) && feasible(&step, &active) {
                    return Ok(Polished::of(step, active));
                }
            }
            return Err(PolishFailure::Inexact);
        }
        if wrong.len() > correctable {
            return Err(PolishFailure::EarlyGuess);
        }
        last_wrong = wrong.len();
        for i in wrong {
            active[i] = !active[i];
        }
    }
    Err(PolishFailure::EarlyGuess)
}

/// How far below its bound the inequality row i may lie at `x`: the feasibility tolerance
/// relative to the bound, plus the rounding of the row's terms (differences of large Airy
/// values).
fn row_tolerance(qp: &Qp, x: &[f64], i: usize, tol: &Tolerances) -> f64 {
    let terms: f64 = qp.ineq.row(i).map(|(c, v)| (v * x[c]).abs()).sum();
    tol.feas * (1.0 + qp.h[i].abs()) + 64.0 * f64::EPSILON * terms
}

/// The active set an iterate suggests: the inequality rows whose multiplier exceeds their
/// slack.
pub(super) fn active_guess(s: &[f64], z: &[f64]) -> Vec<bool> {
    s.iter().zip(z).map(|(s, z)| z > s).collect()
}

/// The Newton step of `polish` for one guess of the active set. Slacks and multipliers are
/// left unclipped: their signs show where the guess was wrong.
pub(super) struct PolishStep {
    pub(super) x: Vec<f64>,
    pub(super) lambda: Vec<f64>,
    /// G x − h per inequality row.
    pub(super) slack: Vec<f64>,
    /// The multiplier of each active row before clipping (0 on inactive rows).
    pub(super) multiplier: Vec<f64>,
}

/// The iterate `polish` starts from, with the parts of its Newton right-hand side that do not
/// depend on the active-set guess, computed once for all its rounds.
pub(super) struct PolishFrom<'a> {
    pub(super) point: Point<'a>,
    /// P x + c − Eᵀλ: the dual residual before the active rows' Gᵀz.
    pub(super) dual_before_g: Vec<f64>,
    /// The constraint rows: f − E x, then h − G x.
    pub(super) b2: Vec<f64>,
}

impl<'a> PolishFrom<'a> {
    pub(super) fn new(qp: &Qp, normal: &Normal, point: &Point<'a>) -> PolishFrom<'a> {
        let Point { x, lambda, .. } = *point;
        let n = x.len();
        let px = normal.mul_p(x);
        let et_l = mul_t(qp.eq, lambda, n);
        let dual_before_g = (0..n).map(|i| px[i] + qp.c[i] - et_l[i]).collect();
        let mut b2: Vec<f64> = qp.eq.mul(x).iter().zip(qp.f).map(|(a, b)| b - a).collect();
        b2.extend(qp.ineq.mul(x).iter().zip(qp.h).map(|(a, b)| b - a));
        PolishFrom {
            point: *point,
            dual_before_g,
            b2,
        }
    }
}

/// Whether the unrefined step of a polishing round is wrong in too many rows to refine it.
pub(super) type Hopeless<'a> = &'a dyn Fn(&PolishStep) -> bool;

/// The Newton step of `polish` from `from` for the active set `active` (with `release`, less
/// the rows that wholly active groups imply), refined to the tolerances unless `hopeless`
/// gives up on the unrefined step (`EarlyGuess`); `Inexact` when no regularisation gives a
/// factor fit for refinement.
pub(super) fn polish_step(
    qp: &Qp,
    normal: &Normal,
    cons: &Csr,
    from: &PolishFrom,
    (active, release, hopeless): (&[bool], bool, Hopeless),
    tol: &Tolerances,
    space: &mut FactorSpace,
) -> Result<PolishStep, PolishFailure> {
    let Point { x, lambda, z, .. } = from.point;
    let (n, m_eq, m) = (x.len(), qp.eq.nrows(), z.len());
    // With `release`, rows of wholly active groups that the others imply are held only
    // through them.
    let active: Vec<bool> = if release {
        let released = qp.groups.released(active, z);
        (0..m).map(|i| active[i] && !released[i]).collect()
    } else {
        active.to_vec()
    };
    let z_active: Vec<f64> = (0..m).map(|i| if active[i] { z[i] } else { 0.0 }).collect();
    let gt_z = mul_t(qp.ineq, &z_active, n);
    let b1: Vec<f64> = (0..n).map(|i| -(from.dual_before_g[i] - gt_z[i])).collect();
    let b2 = &from.b2;
    let step_of = |[dx, w]: &[Vec<f64>; 2]| {
        let x_new: Vec<f64> = x.iter().zip(dx).map(|(x, d)| x + d).collect();
        let lambda_new: Vec<f64> = (0..m_eq).map(|i| lambda[i] - w[i]).collect();
        let gx = qp.ineq.mul(&x_new);
        let slack: Vec<f64> = (0..m).map(|i| gx[i] - qp.h[i]).collect();
        let multiplier: Vec<f64> = (0..m)
            .map(|i| {
                if active[i] {
                    z_active[i] - w[m_eq + i]
                } else {
                    0.0
                }
            })
            .collect();
        PolishStep {
            x: x_new,
            lambda: lambda_new,
            slack,
            multiplier,
        }
    };
    // D = 0 holds a row as an equality; a huge D drops it (its multiplier is D⁻¹ × residual).
    let mut d = vec![0.0; m_eq];
    d.extend(active.iter().map(|&a| if a { 0.0 } else { 1e30 }));
    REGULARISATION
        .iter()
        .find_map(|&reg| {
            let mut newton = Newton::new(normal, cons, d.clone(), reg, space)?;
            let rough = newton.approximate(&b1, b2);
            // The refinement to the tolerances costs several solves; a guess wrong in many
            // times more rows than a round may correct is given up on the unrefined step.
            if hopeless(&step_of(&rough)) {
                return Some(Err(PolishFailure::EarlyGuess));
            }
            let sol = newton.refine(rough, &b1, b2, 1e-2 * tol.feas, true, None)?;
            Some(Ok(step_of(&sol)))
        })
        .unwrap_or(Err(PolishFailure::Inexact))
}
