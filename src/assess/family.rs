//! The least thickness over a family of envelopes E(t) whose bounds are functions of the
//! thickness, such as Heyman's dome (spheres R ± t/2 read vertically) or compas_tno's bounds
//! (docs/method.md §16.4): [`min_thickness_of_family`].

use super::{assess, AssessResult, AssessSettings, Envelope, Objective};
use crate::error::{Error, Result};
use crate::problem::Problem;

/// The answer of [`min_thickness_of_family`].
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct FamilyThickness {
    /// The least thickness found whose envelope holds a certified thrust surface.
    pub thickness: f64,
    /// The least-thickness analysis of `E(thickness)`: its surface lies inside the envelope
    /// scaled by `thickness_scale` ≤ 1 about its middle, so inside `E(thickness)`. (When
    /// the middle surface stands, the analysis of the last round's `E(t_k)`, with
    /// `thickness` = t_k × `thickness_scale`.)
    pub result: AssessResult,
    /// Least-thickness analyses run in all (one per thickness tried).
    pub rounds: usize,
    /// True when this round's scale was within `scale_tolerance` below 1: no uniformly
    /// thinner copy of `E(thickness)` holds a surface, the condition of a local least
    /// thickness of a nested family.
    pub converged: bool,
}

/// Below this least scale the middle surface stands: the least thickness is 0 to within it.
const STANDS: f64 = 1e-6;

/// Rounds of [`min_thickness_of_family`] at most.
const MAX_ROUNDS: usize = 12;

/// The least thickness t of a family of envelopes `envelope_at(t)` that holds a certified
/// thrust surface, starting from `thickness`.
///
/// Each round runs the least-thickness analysis ([`Objective::MinThickness`]) on
/// `E(t_k)`, whose loads are `E(t_k)`'s own, and finds the scale s_k of its half extents
/// that still holds a surface; the next thickness solves s(t) = 1 (first t_k·s_k, then the
/// secant of ln s over ln t through the last two rounds, kept inside the bracket the rounds
/// have found; a round whose search finds no surface, after one that did, is a thin end of
/// the bracket). A round with s_k ≤ 1 certifies t_k: its surface lies inside `E(t_k)` (with
/// `E(t_k)`'s springing joints scaled by s_k too). The search ends
/// when 1 − `scale_tolerance` ≤ s_k ≤ 1 (or after twelve rounds); for a nested family (bounds that move inward as t
/// falls) that thickness is a local minimum over the family, because the round's analysis
/// found no uniformly thinner copy of `E(t_k)` that holds a surface. A round whose least
/// scale is below 1e-6 ends the search with t_k·s_k: the middle surface of `E(t_k)` holds a
/// thrust surface to that precision (the least thickness is 0), and its analysis is
/// certified inside `E(t_k)` scaled by s_k. Otherwise returns the least
/// certified thickness; an error when no round certified one (the message gives the last
/// round's end) or when `thickness` or `scale_tolerance` is not finite and > 0.
pub fn min_thickness_of_family(
    problem: &Problem,
    mut envelope_at: impl FnMut(f64) -> Result<Envelope>,
    thickness: f64,
    scale_tolerance: f64,
    settings: &AssessSettings,
) -> Result<FamilyThickness> {
    crate::validate::above("thickness", thickness, 0.0)?;
    crate::validate::above("scale_tolerance", scale_tolerance, 0.0)?;
    let settings = settings.clone().with_objective(Objective::MinThickness);
    // Aim at the middle of the accepted band [1 − tolerance, 1] of scales.
    let target = 1.0 - 0.5 * scale_tolerance;
    let mut search = Bracket::default();
    let mut best: Option<FamilyThickness> = None;
    let (mut t, mut rounds) = (thickness, 0);
    while rounds < MAX_ROUNDS {
        rounds += 1;
        let result = assess(problem, &envelope_at(t)?, &settings, None)?;
        if !result.feasible {
            let end = result.termination.to_string();
            if best.is_none() {
                return Err(no_surface(t, &end));
            }
            // Too thin for the search to find a surface: a thin end of the bracket.
            search.add(t, f64::INFINITY);
            t = search.next(t, 1.0);
            continue;
        }
        let s = result.thickness_scale;
        if s < STANDS {
            // The middle surface of E(t) itself (nearly) holds a thrust surface.
            return Ok(FamilyThickness {
                thickness: t * s,
                result,
                rounds,
                converged: true,
            });
        }
        let converged = s <= 1.0 && s >= 1.0 - scale_tolerance;
        if s <= 1.0 && best.as_ref().is_none_or(|b| t < b.thickness) {
            best = Some(FamilyThickness {
                thickness: t,
                result,
                rounds,
                converged,
            });
        }
        if converged {
            break;
        }
        search.add(t, (s / target).ln());
        t = search.next(t, s / target);
    }
    finish(best, rounds)
        .ok_or_else(|| no_surface(t, "no round's surface fitted its envelope at scale <= 1"))
}

fn finish(best: Option<FamilyThickness>, rounds: usize) -> Option<FamilyThickness> {
    best.map(|b| FamilyThickness { rounds, ..b })
}

fn no_surface(t: f64, end: &str) -> Error {
    Error::InvalidArgument {
        name: "envelope_at",
        reason: format!("no certified thrust surface fits the family at thickness {t} ({end})"),
    }
}

/// The thicknesses tried with g = ln(s / target): the smallest with g < 0 (too thick) and
/// the largest with g > 0 (too thin; +∞ where no surface was found), and the last two
/// finite ones for the secant, taken in ln t: s(t) falls like a power of t, so the secant
/// of ln s over ln t finds the root in a few rounds where that of s over t crawls.
#[derive(Default)]
struct Bracket {
    thick: Option<(f64, f64)>,
    thin: Option<(f64, f64)>,
    last: Vec<(f64, f64)>,
}

impl Bracket {
    fn add(&mut self, t: f64, g: f64) {
        if g < 0.0 && self.thick.is_none_or(|(b, _)| t < b) {
            self.thick = Some((t, g));
        }
        if g > 0.0 && self.thin.is_none_or(|(b, _)| t > b) {
            self.thin = Some((t, g));
        }
        if g.is_finite() {
            self.last.push((t, g));
        }
    }

    /// The secant root in ln t through the last two rounds, or t·s after one; clamped into
    /// the open bracket (bisection in ln t when the secant leaves it).
    fn next(&self, t: f64, s: f64) -> f64 {
        let guess = match self.last.as_slice() {
            [.., (t0, g0), (t1, g1)] if (g1 - g0).abs() > 0.0 => {
                let (x0, x1) = (t0.ln(), t1.ln());
                (x1 - g1 * (x1 - x0) / (g1 - g0)).exp()
            }
            _ => t * s,
        };
        match (self.thin, self.thick) {
            (Some((lo, _)), Some((hi, _))) if !(guess > lo && guess < hi) => (lo * hi).sqrt(),
            _ if !(guess.is_finite() && guess > 0.0) => t * s,
            _ => guess,
        }
    }
}
