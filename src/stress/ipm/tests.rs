use super::graph::amd_labels;
use super::kkt::{Progress, STALL_WINDOW};
use super::newton::{FactorSpace, Newton};
use super::pattern::{
    product_pattern, products, relabel_vector, relabelled_lower, stacked, symbolic_cholesky,
    transpose, Normal, Pattern, PatternCache,
};
use super::polish::{
    active_guess, polish, polish_step, Corrections, Hopeless, Point, PolishFailure, PolishFrom,
    PolishStep,
};
use super::{
    factorise, fallback_is_costly, inf_norm, ordering, solve, supernodal, IpmStatus, Qp,
    Relabelled, RowGroups, Tolerances,
};
use crate::stress::sparse::Csr;

fn csr(ncols: usize, rows: &[&[(usize, f64)]]) -> Csr {
    let mut m = Csr::new(ncols);
    for r in rows {
        m.push_row(r.to_vec());
    }
    m
}

/// Two rows of a wholly active group are released, not collinear, and such that moving the
/// multipliers along the group's combinations to zero them leaves its others non-negative
/// (a vertex of {a : z_k + a·c_k ≥ 0}); a group with an inactive row releases none.
#[test]
fn released_rows_are_a_vertex_of_the_multiplier_shifts() {
    let star: Vec<[f64; 2]> = [0.1f64, 1.2, 2.0, 3.3, 4.1, 5.4]
        .iter()
        .map(|a| [a.cos() * (1.0 + 0.3 * a), a.sin() * (1.0 + 0.3 * a)])
        .collect();
    let mut coef = star.clone();
    coef.extend_from_slice(&star[..3]);
    let groups = RowGroups {
        start: vec![0, 6, 9],
        row: (0..9).collect(),
        coef,
    };
    let mut active = vec![true; 9];
    active[8] = false;
    for seed in 0..50u32 {
        let z: Vec<f64> = (0..9)
            .map(|k| 0.05 + ((seed * 7 + k * 13) % 17) as f64 / 4.0)
            .collect();
        let released = groups.released(&active, &z);
        let rows: Vec<usize> = (0..9).filter(|&r| released[r]).collect();
        assert_eq!(rows.len(), 2, "seed {seed}: {rows:?}");
        let ([i, j], [a, b]) = ([rows[0], rows[1]], [star[rows[0]], star[rows[1]]]);
        assert!(j < 6);
        let det = a[0] * b[1] - a[1] * b[0];
        assert!(det.abs() > 1e-3);
        let shift = [
            (-z[i] * b[1] + z[j] * a[1]) / det,
            (-z[j] * a[0] + z[i] * b[0]) / det,
        ];
        for (k, c) in star.iter().enumerate() {
            let shifted = z[k] + shift[0] * c[0] + shift[1] * c[1];
            assert!(
                shifted >= -1e-9,
                "seed {seed}: row {k} shifted to {shifted}"
            );
        }
    }
}

/// Every product of a row's entries lands in the slot of its (row, column) pair in the
/// relabelled lower triangle, for rows of several lengths over a shuffled set of columns.
#[test]
fn product_slots_point_at_their_entries() {
    let n = 40;
    // A deterministic scramble of columns: rows of 1–12 distinct entries.
    let mut seed = 12345u64;
    let mut next = |k: usize| {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 33) as usize % k
    };
    let mut rows = |count: usize| {
        let mut m = Csr::new(n);
        for _ in 0..count {
            let len = 1 + next(12);
            m.push_row((0..len).map(|_| (next(n), 1.0 + next(5) as f64)).collect());
        }
        m
    };
    let (quad, cons) = (rows(30), rows(25));
    let pattern = Pattern::new(&quad, &cons, 3, None).expect("pattern");
    for (m, slots) in [(&quad, &pattern.quad_slot), (&cons, &pattern.row_slot)] {
        let pairs: Vec<(usize, usize)> = products(m).map(|(_, a, b, ..)| (a, b)).collect();
        assert_eq!(pairs.len(), slots.len());
        for (&(a, b), &slot) in pairs.iter().zip(slots.iter()) {
            let (col, row) = (pattern.label[a], pattern.label[b]);
            let (col, row) = (col.min(row), col.max(row));
            assert!((pattern.col_ptr[col]..pattern.col_ptr[col + 1]).contains(&slot));
            assert_eq!(pattern.row_idx[slot], row, "product ({a}, {b})");
        }
    }
    for (i, &slot) in pattern.diag.iter().enumerate() {
        assert_eq!(pattern.row_idx[slot], pattern.label[i]);
    }
}

/// min (x0 − 1)² + (x1 − 2)² + (x0 + x1 − 4)²  s.t. x0 − x1 = −0.5, x0 ≥ 1.8: on the
/// line x1 = x0 + 0.5 the objective is least at x0 = 19/12 < 1.8, so the bound binds.
#[test]
fn small_qp_with_active_bound_and_equality() {
    let quad = csr(2, &[&[(0, 1.0)], &[(1, 1.0)], &[(0, 1.0), (1, 1.0)]]);
    let weight = [2.0, 2.0, 2.0];
    // c = −2 Σ_k b_k a_k with targets b = (1, 2, 4).
    let c = [-10.0, -12.0];
    let eq = csr(2, &[&[(0, 1.0), (1, -1.0)]]);
    let ineq = csr(2, &[&[(0, 1.0)]]);
    let out = solve(
        &Qp {
            quad: &quad,
            quad_weight: &weight,
            c: &c,
            constant: 1.0 + 4.0 + 16.0,
            eq: &eq,
            f: &[-0.5],
            ineq: &ineq,
            h: &[1.8],
            groups: &RowGroups::default(),
            positions: None,
            slack_unit: None,
        },
        &Tolerances::default(),
        &mut PatternCache::default(),
    );
    assert_eq!(out.status, IpmStatus::Solved);
    assert!((out.x[0] - 1.8).abs() < 1e-8, "{:?}", out.x);
    assert!((out.x[1] - 2.3).abs() < 1e-8, "{:?}", out.x);
}

/// `polish` from the iterate (x, s, z) (no equality rows), in the caller's labels.
fn polish_at(
    qp: &Qp,
    x: &[f64],
    s: &[f64],
    z: &[f64],
    tol: &Tolerances,
) -> Result<Vec<f64>, PolishFailure> {
    let cons = stacked(qp.eq, qp.ineq);
    let mut cache = PatternCache::default();
    let (pattern, _) = cache
        .pattern(qp.quad, &cons, 0, None)
        .expect("normal matrix");
    let normal = Normal::new(pattern, qp.quad, qp.quad_weight, &cons);
    let label = &normal.pattern.label;
    let relabelled = Relabelled::new(qp, label);
    let (qp, cons) = (relabelled.qp(qp), &relabelled.cons);
    let mut space =
        FactorSpace::new(&normal.pattern.symbolic, normal.p_values.len()).expect("factor space");
    let x = relabel_vector(x, label);
    let point = Point {
        x: &x,
        lambda: &[],
        z,
    };
    let guess = active_guess(s, z);
    let polished = polish(
        &qp,
        &normal,
        cons,
        &point,
        (&guess, Corrections::Few),
        tol,
        &mut space,
    )?;
    Ok(label.iter().map(|&l| polished.x[l]).collect())
}

/// min (x0 − 2)² + (x1 + 10⁻⁶)² subject to x1 ≥ 0: the bound is active at the optimum
/// (2, 0) with the tiny multiplier 2·10⁻⁶. At an iterate that has not told it apart yet
/// (s = 10⁻³ > z = 10⁻⁷) the plain guess drops it and its step lands at x1 = −10⁻⁶,
/// violating it; the corrected guess must find the optimum.
#[test]
fn polishing_corrects_a_wrongly_dropped_row() {
    let quad = csr(2, &[&[(0, 1.0)], &[(1, 1.0)]]);
    let qp = Qp {
        quad: &quad,
        quad_weight: &[2.0, 2.0],
        c: &[-4.0, 2e-6],
        constant: 4.0 + 1e-12,
        eq: &csr(2, &[]),
        f: &[],
        ineq: &csr(2, &[&[(1, 1.0)]]),
        h: &[0.0],
        groups: &RowGroups::default(),
        positions: None,
        slack_unit: None,
    };
    let x = polish_at(&qp, &[2.0, 1e-3], &[1e-3], &[1e-7], &Tolerances::default())
        .expect("the corrected guess is optimal");
    assert!((x[0] - 2.0).abs() < 1e-12 && x[1].abs() < 1e-12, "{x:?}");
}

/// min Σ (x_i + 1)² subject to x ≥ 0 (`k` rows): every bound is active at the optimum
/// x = 0, with multiplier 2.
fn active_bounds<R>(k: usize, run: impl FnOnce(&Qp) -> R) -> R {
    let identity: Vec<Vec<(usize, f64)>> = (0..k).map(|i| vec![(i, 1.0)]).collect();
    let rows: Vec<&[(usize, f64)]> = identity.iter().map(|r| r.as_slice()).collect();
    let quad = csr(k, &rows);
    run(&Qp {
        quad: &quad,
        quad_weight: &vec![2.0; k],
        c: &vec![2.0; k],
        constant: k as f64,
        eq: &csr(k, &[]),
        f: &[],
        ineq: &quad,
        h: &vec![0.0; k],
        groups: &RowGroups::default(),
        positions: None,
        slack_unit: None,
    })
}

fn four_active_bounds<R>(run: impl FnOnce(&Qp) -> R) -> R {
    active_bounds(4, run)
}

/// Dropping all 40 active bounds of `active_bounds`: the unrefined step already violates
/// each of them (x_i = −1), as the refined one does, so `polish` may give the guess up before
/// refining it (40 wrong rows against at most 3 correctable); and a step given up is an
/// early guess, not an inexact one.
#[test]
fn a_hopeless_guess_shows_its_wrong_rows_before_refinement() {
    active_bounds(40, |qp| {
        let cons = stacked(qp.eq, qp.ineq);
        let mut cache = PatternCache::default();
        let (pattern, _) = cache
            .pattern(qp.quad, &cons, 0, None)
            .expect("normal matrix");
        let normal = Normal::new(pattern, qp.quad, qp.quad_weight, &cons);
        let mut space = FactorSpace::new(&normal.pattern.symbolic, normal.p_values.len())
            .expect("factor space");
        let (x, z) = (vec![0.1; 40], vec![1e-3; 40]);
        let point = Point {
            x: &x,
            lambda: &[],
            z: &z,
        };
        let from = PolishFrom::new(qp, &normal, &point);
        let dropped = vec![false; 40];
        let violated = |step: &PolishStep| step.slack.iter().filter(|&&s| s < -0.5).count();
        let rough = std::cell::Cell::new(0);
        let record = |step: &PolishStep| {
            rough.set(violated(step));
            false
        };
        let tol = Tolerances::default();
        let mut step_with = |hopeless: Hopeless| {
            polish_step(
                qp,
                &normal,
                &cons,
                &from,
                (&dropped, false, hopeless),
                &tol,
                &mut space,
            )
        };
        let refined = step_with(&record).expect("a sound factor");
        assert_eq!((rough.get(), violated(&refined)), (40, 40));
        let given_up = step_with(&|_: &PolishStep| true);
        assert_eq!(given_up.err(), Some(PolishFailure::EarlyGuess));
        let guess = active_guess(&[0.1; 40], &z);
        assert_eq!(guess, dropped);
        let polished = polish(
            qp,
            &normal,
            &cons,
            &point,
            (&guess, Corrections::Few),
            &tol,
            &mut space,
        );
        assert_eq!(polished.err(), Some(PolishFailure::EarlyGuess));
    });
}

/// A guess that drops all four active bounds has more wrong rows than a round may correct
/// (at most three here): the iterate was early, and the caller may retry next iteration.
#[test]
fn polishing_a_guess_with_too_many_wrong_rows_reports_an_early_guess() {
    let failure = four_active_bounds(|qp| {
        polish_at(qp, &[0.1; 4], &[0.1; 4], &[1e-3; 4], &Tolerances::default())
    });
    assert_eq!(failure, Err(PolishFailure::EarlyGuess));
}

/// The right guess with a tolerance no step can meet (a negative gap) has no wrong row,
/// so it is the precision that failed: the caller waits for the gap to fall before
/// retrying. The same guess meets the default tolerances.
#[test]
fn polishing_the_right_guess_beyond_reach_reports_inexact() {
    let at = |tol: Tolerances| {
        four_active_bounds(|qp| polish_at(qp, &[0.1; 4], &[1e-3; 4], &[1.0; 4], &tol))
    };
    let unreachable = Tolerances {
        gap_abs: -1.0,
        ..Tolerances::default()
    };
    assert_eq!(at(unreachable), Err(PolishFailure::Inexact));
    let x = at(Tolerances::default()).expect("the right guess is optimal");
    assert!(x.iter().all(|v| v.abs() < 1e-12), "{x:?}");
}

/// min (x_0 − 10⁷)² + Σ (x_{i+1} − x_i − t_i)² subject to x_{i+1} − x_i ≥ 0.1, with
/// t_i = −1 on every other difference (bound active, multiplier 2.2) and +1 on the rest.
/// Polishing from a perturbed iterate lands on the optimum, but the slack of an active row,
/// x_{i+1} − x_i − 0.1 with x near 10⁷, comes out as rounding (~1e-9) rather than 0. Those
/// rows are held on their bounds, so that is an inequality residual (within its tolerance)
/// and not complementarity: counted in the gap, the positive ones times z = 2.2 exceed the
/// gap's tolerance (1e-12 + 1e-11 × 60.5) and would fail the step as inexact.
#[test]
fn polished_active_rows_count_on_their_bounds_in_the_gap() {
    let n = 101;
    let bound = 0.1;
    let target: Vec<f64> = (0..n - 1)
        .map(|i| if i % 2 == 0 { -1.0 } else { 1.0 })
        .collect();
    let mut rows: Vec<Vec<(usize, f64)>> = vec![vec![(0, 1.0)]];
    rows.extend((0..n - 1).map(|i| vec![(i, -1.0), (i + 1, 1.0)]));
    let quad = csr(n, &rows.iter().map(|r| r.as_slice()).collect::<Vec<_>>());
    let ineq = csr(
        n,
        &rows[1..].iter().map(|r| r.as_slice()).collect::<Vec<_>>(),
    );
    let weight = vec![2.0; n];
    // c = −2 Aᵀ b with b = (10⁷, t).
    let mut c = vec![0.0; n];
    c[0] = -2e7;
    for (i, t) in target.iter().enumerate() {
        c[i] += 2.0 * t;
        c[i + 1] -= 2.0 * t;
    }
    let constant = 1e14 + target.iter().map(|t| t * t).sum::<f64>();
    let qp = Qp {
        quad: &quad,
        quad_weight: &weight,
        c: &c,
        constant,
        eq: &csr(n, &[]),
        f: &[],
        ineq: &ineq,
        h: &vec![bound; n - 1],
        groups: &RowGroups::default(),
        positions: None,
        slack_unit: None,
    };
    let active = |i: usize| target[i] < bound;
    let mut optimum = vec![1e7];
    for t in &target {
        optimum.push(optimum.last().expect("x_0") + t.max(bound));
    }
    let x: Vec<f64> = (0..n)
        .map(|i| optimum[i] + 1e-3 * (((i * 7) % 5) as f64 - 2.0))
        .collect();
    let s: Vec<f64> = (0..n - 1)
        .map(|i| if active(i) { 1e-6 } else { 1.0 })
        .collect();
    let z: Vec<f64> = (0..n - 1)
        .map(|i| if active(i) { 2.2 } else { 1e-6 })
        .collect();
    let polished = polish_at(&qp, &x, &s, &z, &Tolerances::default())
        .expect("the right active set polishes to the optimum");
    for (i, t) in target.iter().enumerate() {
        let d = polished[i + 1] - polished[i];
        assert!(
            (d - t.max(bound)).abs() < 1e-6,
            "difference {i} = {d} for target {t}"
        );
    }
    let above = (0..n - 1)
        .filter(|&i| active(i) && polished[i + 1] - polished[i] - bound > 0.0)
        .count();
    assert!(
        above > 0,
        "no active slack rounds above 0: the test shows nothing"
    );
}

/// min Σ (x_{i+1} − x_i − t_i)² subject to x_{i+1} ≥ x_i and x_0 = 10⁷: the differences
/// come out at max(t_i, 0) while every unknown is near 10⁷, so P x sums terms of 10⁷ to
/// O(1) results and its rounding (~1e-9) exceeds 1e-10 of the dual residual's scale. The
/// method must still report the optimum as solved (the rounding floor), not stall.
#[test]
fn large_unknowns_with_small_differences_converge_at_the_rounding_floor() {
    let n = 200;
    let target: Vec<f64> = (0..n - 1)
        .map(|i| ((i * 37) % 11) as f64 / 5.0 - 1.0)
        .collect();
    let diffs: Vec<Vec<(usize, f64)>> = (0..n - 1).map(|i| vec![(i, -1.0), (i + 1, 1.0)]).collect();
    let rows: Vec<&[(usize, f64)]> = diffs.iter().map(|r| r.as_slice()).collect();
    let quad = csr(n, &rows);
    let weight = vec![2.0; n - 1];
    // c = −2 Aᵀ t.
    let mut c = vec![0.0; n];
    for (i, t) in target.iter().enumerate() {
        c[i] += 2.0 * t;
        c[i + 1] -= 2.0 * t;
    }
    let constant = target.iter().map(|t| t * t).sum();
    let out = solve(
        &Qp {
            quad: &quad,
            quad_weight: &weight,
            c: &c,
            constant,
            eq: &csr(n, &[&[(0, 1.0)]]),
            f: &[1e7],
            ineq: &quad,
            h: &vec![0.0; n - 1],
            groups: &RowGroups::default(),
            positions: None,
            slack_unit: None,
        },
        &Tolerances::default(),
        &mut PatternCache::default(),
    );
    assert_eq!(out.status, IpmStatus::Solved);
    for (i, t) in target.iter().enumerate() {
        let d = out.x[i + 1] - out.x[i];
        assert!(
            (d - t.max(0.0)).abs() < 1e-6,
            "difference {i} = {d} for target {t}"
        );
    }
}

/// min Σ (x_i − t_i)² subject to x ≥ 0 and x constant over blocks of four: with targets of
/// both signs many bounds are active, and each block must come out at the positive part
/// of its mean (never 0: no degenerate bound), to the accuracy the tolerances imply
/// (values are O(1); a wrong active set would be off by O(0.1)).
#[test]
fn bound_constrained_least_squares_finds_the_active_set() {
    let n = 400;
    let target: Vec<f64> = (0..n).map(|i| ((i * 7919) % 13) as f64 - 5.9).collect();
    // The identity: the objective's rows and the bounds x ≥ 0.
    let identity = csr(
        n,
        &(0..n)
            .map(|i| vec![(i, 1.0)])
            .collect::<Vec<_>>()
            .iter()
            .map(|r| r.as_slice())
            .collect::<Vec<_>>(),
    );
    let weight = vec![2.0; n];
    let c: Vec<f64> = target.iter().map(|t| -2.0 * t).collect();
    let constant = target.iter().map(|t| t * t).sum();
    let chain: Vec<Vec<(usize, f64)>> = (0..n - 1)
        .filter(|i| i % 4 != 3)
        .map(|i| vec![(i, 1.0), (i + 1, -1.0)])
        .collect();
    let eq = csr(n, &chain.iter().map(|r| r.as_slice()).collect::<Vec<_>>());
    let out = solve(
        &Qp {
            quad: &identity,
            quad_weight: &weight,
            c: &c,
            constant,
            eq: &eq,
            f: &vec![0.0; chain.len()],
            ineq: &identity,
            h: &vec![0.0; n],
            groups: &RowGroups::default(),
            positions: None,
            slack_unit: None,
        },
        &Tolerances::default(),
        &mut PatternCache::default(),
    );
    assert_eq!(out.status, IpmStatus::Solved);
    for block in 0..n / 4 {
        let mean = target[4 * block..4 * block + 4].iter().sum::<f64>() / 4.0;
        for i in 4 * block..4 * block + 4 {
            assert!(
                (out.x[i] - mean.max(0.0)).abs() < 1e-7,
                "x{i} = {} for block mean {mean}",
                out.x[i]
            );
        }
    }
}

/// The same QP solved again starts from the last answer's active set (no interior-point
/// iterations), unless the shape is said to be far from balance and the QP is large.
#[test]
fn far_from_balance_skips_the_last_active_set_only_beyond_20k_unknowns() {
    for n in [400, 20_001] {
        let target: Vec<f64> = (0..n).map(|i| ((i * 7919) % 13) as f64 - 5.9).collect();
        let rows: Vec<Vec<(usize, f64)>> = (0..n).map(|i| vec![(i, 1.0)]).collect();
        let identity = csr(n, &rows.iter().map(|r| r.as_slice()).collect::<Vec<_>>());
        let weight = vec![2.0; n];
        let c: Vec<f64> = target.iter().map(|t| -2.0 * t).collect();
        let constant = target.iter().map(|t| t * t).sum();
        let qp = Qp {
            quad: &identity,
            quad_weight: &weight,
            c: &c,
            constant,
            eq: &Csr::new(n),
            f: &[],
            ineq: &identity,
            h: &vec![0.0; n],
            groups: &RowGroups::default(),
            positions: None,
            slack_unit: None,
        };
        let tol = Tolerances::for_size(n);
        let mut cache = PatternCache::default();
        let cold = solve(&qp, &tol, &mut cache);
        assert_eq!(cold.status, IpmStatus::Solved);
        assert!(cold.iterations > 0);
        let near = solve(&qp, &tol, &mut cache);
        assert_eq!(
            (near.status, near.iterations),
            (IpmStatus::Solved, 0),
            "n = {n}"
        );
        cache.far_from_balance(true);
        let far = solve(&qp, &tol, &mut cache);
        let expected = if fallback_is_costly(n) {
            cold.iterations
        } else {
            0
        };
        assert_eq!(
            (far.status, far.iterations),
            (IpmStatus::Solved, expected),
            "n = {n}"
        );
    }
}

/// A stall is a window of `STALL_WINDOW` iterations in which neither the residuals halved
/// nor the gap fell tenfold; progress on either, however slow, keeps the iterations going.
#[test]
fn a_stall_is_a_window_without_halved_residuals_or_a_tenfold_gap() {
    let first_stall = |excess: &dyn Fn(u32) -> [f64; 2]| {
        let mut progress = Progress::new();
        (0..300).find(|&k| progress.stalled(k, excess(k)))
    };
    // Nothing moves: a stall as the window ends.
    assert_eq!(first_stall(&|_| [10.0, 1e3]), Some(STALL_WINDOW));
    // Slow but steady: the gap tenfold every 8 iterations, or the residuals halved every
    // 9, the other flat.
    let falling = |k: u32, per: f64, factor: f64| factor.powf(-(k as f64) / per);
    assert_eq!(first_stall(&|k| [10.0, 1e3 * falling(k, 8.0, 10.0)]), None);
    assert_eq!(first_stall(&|k| [10.0 * falling(k, 9.0, 2.0), 1e3]), None);
    // Too slow: the residuals falling by 40% a window, the gap bouncing within a factor
    // of 5: a stall as the first window ends.
    assert_eq!(
        first_stall(&|k| [
            10.0 * 0.6f64.powf(k as f64 / STALL_WINDOW as f64),
            if k % 2 == 0 { 1e3 } else { 2e2 }
        ]),
        Some(STALL_WINDOW)
    );
    // Progress restarts the window: the residuals halved at iteration 7, then flat.
    let halved_at_7 = |k: u32| [if k < 7 { 10.0 } else { 4.9 }, 1e3];
    assert_eq!(first_stall(&halved_at_7), Some(7 + STALL_WINDOW));
}

/// `supernodal::solve_in_place` on the normal matrix of a QP whose quadratic rows are a
/// 15 × 15 grid's five-point stencils (a two-ring normal matrix, factored in many
/// supernodes): its solution solves the assembled matrix to rounding and equals faer's solve.
#[test]
fn supernodal_solve_matches_the_matrix_and_faer() {
    let (quad, cons, _) = grid_qp(15);
    let n = quad.ncols;
    let mut cache = PatternCache::default();
    let (pattern, _) = cache.pattern(&quad, &cons, 0, None).expect("normal matrix");
    let normal = Normal::new(pattern, &quad, &vec![1.0; n], &cons);
    let mut space =
        FactorSpace::new(&normal.pattern.symbolic, normal.p_values.len()).expect("factor space");
    let d: Vec<f64> = (0..n).map(|i| 0.5 + (i % 3) as f64).collect();
    drop(Newton::new(&normal, &cons, d, 1e-12, &mut space).expect("a sound factor"));
    let symbolic = &normal.pattern.symbolic;
    let faer::sparse::linalg::cholesky::SymbolicCholeskyRaw::Supernodal(sym) = symbolic.raw()
    else {
        panic!("the normal matrix is factored supernodally");
    };
    assert!(sym.n_supernodes() > 20, "{} supernodes", sym.n_supernodes());
    let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
    let mut theirs = b.clone();
    faer::sparse::linalg::cholesky::LdltRef::new(symbolic, &space.l_values)
        .solve_in_place_with_conj(
            faer::Conj::No,
            faer::MatMut::from_column_major_slice_mut(&mut theirs, n, 1),
            faer::Par::Seq,
            faer::dyn_stack::MemStack::new(&mut space.buffer),
        );
    // Both directions of the backward solve's reading, in sequence and on two threads.
    let split = supernodal::Split::new(symbolic, 0, |ncols, nrows| (ncols * nrows) as u64)
        .expect("a tree worth splitting");
    for (downwards, split) in [(false, None), (true, None), (true, Some(&split))] {
        let mut own = b.clone();
        assert!(supernodal::solve_in_place_reading(
            symbolic,
            &space.l_values,
            &mut own,
            &mut Vec::new(),
            downwards,
            split
        ));
        // A x from the factored lower triangle.
        let (col_ptr, row_idx) = (&normal.pattern.col_ptr, &normal.pattern.row_idx);
        let mut ax = vec![0.0; n];
        for c in 0..n {
            let range = col_ptr[c]..col_ptr[c + 1];
            for (&r, &v) in row_idx[range.clone()].iter().zip(&space.values[range]) {
                ax[r] += v * own[c];
                if r != c {
                    ax[c] += v * own[r];
                }
            }
        }
        let max_gap = |u: &[f64], v: &[f64]| {
            (u.iter().zip(v))
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        };
        let residual = max_gap(&ax, &b);
        assert!(
            residual <= 1e-12 * inf_norm(&b),
            "downwards {downwards}, split {}: residual {residual:e}",
            split.is_some()
        );
        let gap = max_gap(&own, &theirs);
        assert!(
            gap <= 1e-12 * inf_norm(&theirs),
            "downwards {downwards}, split {}: own against faer's: {gap:e}",
            split.is_some()
        );
    }
}

/// The quadratic rows of a k × k grid's five-point stencils (a two-ring normal matrix), one
/// bound per unknown, and the grid positions of the unknowns.
fn grid_qp(k: usize) -> (Csr, Csr, Vec<[f64; 2]>) {
    let n = k * k;
    let stencils: Vec<Vec<(usize, f64)>> = (0..n)
        .map(|v| {
            let (i, j) = (v / k, v % k);
            let mut row = vec![(v, 4.0 + 0.1 * (v % 7) as f64)];
            let neighbours = [
                (i + 1, j),
                (i, j + 1),
                (i.wrapping_sub(1), j),
                (i, j.wrapping_sub(1)),
            ];
            for (a, b) in neighbours.into_iter().filter(|&(a, b)| a < k && b < k) {
                row.push((a * k + b, -1.0 - 0.01 * ((a * k + b) % 5) as f64));
            }
            row.sort_by_key(|e| e.0);
            row
        })
        .collect();
    let rows: Vec<&[(usize, f64)]> = stencils.iter().map(|r| r.as_slice()).collect();
    let bounds: Vec<Vec<(usize, f64)>> = (0..n).map(|i| vec![(i, 1.0)]).collect();
    let bound_rows: Vec<&[(usize, f64)]> = bounds.iter().map(|r| r.as_slice()).collect();
    let cons = stacked(&csr(n, &[]), &csr(n, &bound_rows));
    let positions = (0..n).map(|v| [(v / k) as f64, (v % k) as f64]).collect();
    (csr(n, &rows), cons, positions)
}

/// A QP of 44k unknowns (a grid's two-ring normal matrix, part of its bounds active) solved
/// in the nested-dissection order of its unknowns' positions and in AMD's order: the same
/// optimum. This is the path of large stress QPs: the dissection from 40k unknowns, the
/// factorisation and the solves on two threads.
#[test]
fn dissection_order_solves_a_large_qp_as_amds_does() {
    let k = 210;
    let (quad, cons, positions) = grid_qp(k);
    let n = k * k;
    let (weight, eq) = (vec![1.0; n], csr(n, &[]));
    let c: Vec<f64> = (0..n).map(|v| ((v * 7919) % 13) as f64 - 6.0).collect();
    let h: Vec<f64> = (0..n).map(|v| ((v * 31) % 5) as f64 * 0.1).collect();
    let groups = RowGroups::default();
    let qp = |positions| Qp {
        quad: &quad,
        quad_weight: &weight,
        c: &c,
        constant: 0.0,
        eq: &eq,
        f: &[],
        ineq: &cons,
        h: &h,
        groups: &groups,
        positions,
        slack_unit: None,
    };
    let (mut dissected, mut amd) = (PatternCache::default(), PatternCache::default());
    let tol = Tolerances::for_size(n);
    let ours = solve(&qp(Some(&positions)), &tol, &mut dissected);
    let theirs = solve(&qp(None), &tol, &mut amd);
    let label = |cache: &PatternCache| cache.pattern.as_ref().expect("a pattern").label.clone();
    assert_ne!(
        label(&dissected),
        label(&amd),
        "the same order: no dissection"
    );
    for out in [&ours, &theirs] {
        assert_eq!(out.status, IpmStatus::Solved);
    }
    let active = ours
        .x
        .iter()
        .zip(&h)
        .filter(|(x, h)| *x - *h < 1e-6)
        .count();
    assert!(
        active > n / 20 && active < n - n / 20,
        "{active} of {n} bounds active"
    );
    let gap = (ours.x.iter().zip(&theirs.x))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        gap <= 1e-6 * inf_norm(&theirs.x),
        "orders differ by {gap:e}"
    );
}

/// The two-thread factorisation (and the same code on one thread) gives faer's factor of a
/// grid's normal matrix with two dense rows factored apart (negative pivots), to rounding: a
/// dropped or misplaced update or a wrong pivot sign would change it by the size of the
/// entries.
#[test]
fn own_factorisation_equals_faers() {
    let (mut quad, mut cons, _) = grid_qp(40);
    let n = quad.ncols;
    // Dense rows of P and of C, factored apart with negative pivots (see `dense`).
    quad.push_row((0..n).step_by(7).map(|i| (i, 0.5)).collect());
    cons.push_row(
        (0..n)
            .step_by(5)
            .map(|i| (i, 1.0 + (i % 3) as f64))
            .collect(),
    );
    let mut cache = PatternCache::default();
    let (pattern, _) = cache.pattern(&quad, &cons, 0, None).expect("normal matrix");
    assert_eq!(pattern.dense.count(), 2);
    let normal = Normal::new(pattern, &quad, &vec![1.0; quad.nrows()], &cons);
    let symbolic = &normal.pattern.symbolic;
    let mut space = FactorSpace::for_pattern(pattern).expect("factor space");
    assert!(
        normal.pattern.plan.is_none(),
        "faer factors a matrix this small"
    );
    let d: Vec<f64> = (0..cons.nrows()).map(|i| 0.5 + (i % 3) as f64).collect();
    drop(Newton::new(&normal, &cons, d, 1e-12, &mut space).expect("a sound factor"));
    let theirs = space.l_values.clone();
    let scale = inf_norm(&theirs);
    let split = supernodal::Split::new(symbolic, 0, supernodal::factor_work)
        .expect("a tree worth splitting");
    let (first, second) = (split.branches[0].len(), split.branches[1].len());
    assert!(
        first > 10 && second > 10,
        "branches of {first} and {second} supernodes"
    );
    for split in [Some(split), None] {
        let threads = if split.is_some() { 2 } else { 1 };
        let plan = factorise::Plan::with_split(symbolic, split, n).expect("a supernodal plan");
        let mut own = vec![f64::NAN; theirs.len()];
        let matrix = (
            &pattern.col_ptr[..],
            &pattern.row_idx[..],
            &space.values[..],
        );
        assert!(plan.factorise(matrix, &mut own));
        let gap = (own.iter().zip(&theirs))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            gap <= 1e-12 * scale,
            "{threads} threads: {gap:e} against {scale:e}"
        );
    }
}

/// The nested dissection of a grid: a permutation, postordered, whose factor splits into
/// two branches of comparable work (what the two-thread factorisation needs; the first cut
/// halves the grid), with less than half the fill of the grid's own order and near AMD's; an
/// unknown coupled to many is ordered last, and unknowns all at one point are still ordered
/// (by AMD).
#[test]
fn dissection_splits_a_grid_into_halves() {
    let k = 64;
    let (mut quad, cons, mut positions) = grid_qp(k);
    let n = k * k;
    // A hub in a constraint with each unknown of four rows of the grid (as a hole's
    // coefficient is with the vertices around the hole): 8× the mean coupling and more.
    let hub = n;
    let mut wide = Csr::new(n + 1);
    for r in 0..quad.nrows() {
        wide.push_row(quad.row(r).collect());
    }
    let mut cons_wide = Csr::new(n + 1);
    for r in 0..cons.nrows() {
        cons_wide.push_row(cons.row(r).collect());
    }
    for v in 0..4 * k {
        cons_wide.push_row(vec![(v, 1.0), (hub, 1.0)]);
    }
    (quad, positions) = (wide, [positions, vec![[0.0, 0.0]]].concat());
    let (col_ptr, row_idx) = product_pattern([&quad, &cons_wide], n + 1);
    let label = ordering::nested_dissection_labels(&col_ptr, &row_idx, &positions);
    let mut seen = vec![false; n + 1];
    label.iter().for_each(|&l| seen[l] = true);
    assert!(seen.iter().all(|&s| s), "not a permutation");
    assert_eq!(label[hub], n, "the hub is ordered last");
    let factor = |label: &[usize]| {
        let (col_ptr, row_idx) = relabelled_lower(n + 1, &col_ptr, &row_idx, label);
        let (up_ptr, up_idx) = transpose(n + 1, &col_ptr, &row_idx);
        symbolic_cholesky(n + 1, &up_ptr, &up_idx).expect("a symbolic factor")
    };
    let dissected = factor(&label);
    let grid_order = factor(&(0..=n).collect::<Vec<_>>());
    let (ours, banded) = (dissected.len_val(), grid_order.len_val());
    // Near AMD's fill at this size (306k stored values against 260k).
    let amd = factor(&amd_labels(n + 1, &col_ptr, &row_idx).expect("AMD")).len_val();
    assert!(
        100 * ours < 125 * amd,
        "{ours} factor values against AMD's {amd}"
    );
    assert!(
        2 * ours < banded,
        "{ours} factor values against {banded} in grid order"
    );
    let work = supernodal::factor_work;
    let split = supernodal::Split::new(&dissected, 0, work).expect("a split");
    let faer::sparse::linalg::cholesky::SymbolicCholeskyRaw::Supernodal(sym) = dissected.raw()
    else {
        panic!("supernodal");
    };
    let weight = |members: &[usize]| -> u64 {
        (members.iter())
            .map(|&s| {
                let ncols = sym.supernode_end()[s] - sym.supernode_begin()[s];
                let nrows = ncols + sym.col_ptr_for_row_idx()[s + 1] - sym.col_ptr_for_row_idx()[s];
                work(ncols, nrows)
            })
            .sum()
    };
    // Postordered: every supernode's subtree is the run of supernodes ending at it.
    let (begin, end, row_ptr) = (
        sym.supernode_begin(),
        sym.supernode_end(),
        sym.col_ptr_for_row_idx(),
    );
    let ns = sym.n_supernodes();
    let owner = |col: usize| (0..ns).find(|&s| begin[s] <= col && col < end[s]);
    let (mut lowest, mut size) = ((0..ns).collect::<Vec<_>>(), vec![1; ns]);
    for s in 0..ns {
        if let Some(&r) = sym.row_idx()[row_ptr[s]..row_ptr[s + 1]].first() {
            let p = owner(r).expect("a parent");
            (lowest[p], size[p]) = (lowest[p].min(lowest[s]), size[p] + size[s]);
        }
        assert_eq!(
            s + 1 - lowest[s],
            size[s],
            "supernode {s}'s subtree is not a run"
        );
    }
    let [first, second] = [0, 1].map(|b| weight(&split.branches[b]));
    let total = first + second + weight(&split.stem);
    assert!(
        5 * first.min(second) > 2 * first.max(second) && 10 * (first + second) > 7 * total,
        "branches {first} and {second} of {total}"
    );
    // Everything at one point: no line separates anything.
    let label = ordering::nested_dissection_labels(&col_ptr, &row_idx, &vec![[1.0, 2.0]; n + 1]);
    let mut seen = vec![false; n + 1];
    label.iter().for_each(|&l| seen[l] = true);
    assert!(seen.iter().all(|&s| s), "not a permutation");
}

/// A bound-constrained least-squares QP with coupled unknowns: min Σ (x_i − t_i)² +
/// 100 Σ (x_i − x_{i+1})² subject to x ≥ 0.
fn coupled_bound_qp_solve(
    target: &[f64],
    tol: &Tolerances,
    cache: &mut PatternCache,
) -> super::IpmOutput {
    let n = target.len();
    let mut rows: Vec<Vec<(usize, f64)>> = (0..n).map(|i| vec![(i, 1.0)]).collect();
    rows.extend((0..n - 1).map(|i| vec![(i, 1.0), (i + 1, -1.0)]));
    let quad = csr(n, &rows.iter().map(|r| r.as_slice()).collect::<Vec<_>>());
    let mut weight = vec![2.0; n];
    weight.extend(vec![200.0; n - 1]);
    let bounds: Vec<Vec<(usize, f64)>> = (0..n).map(|i| vec![(i, 1.0)]).collect();
    let ineq = csr(n, &bounds.iter().map(|r| r.as_slice()).collect::<Vec<_>>());
    let c: Vec<f64> = target.iter().map(|t| -2.0 * t).collect();
    let constant = target.iter().map(|t| t * t).sum();
    solve(
        &Qp {
            quad: &quad,
            quad_weight: &weight,
            c: &c,
            constant,
            eq: &Csr::new(n),
            f: &[],
            ineq: &ineq,
            h: &vec![0.0; n],
            groups: &RowGroups::default(),
            positions: None,
            slack_unit: None,
        },
        tol,
        cache,
    )
}

/// After a QP, a changed one whose optimum the last answer's active set misses (the
/// active-set attempt fails) runs the iterations from the last answer blended with the cold
/// point, and reaches the cold start's optimum.
#[test]
fn a_changed_qp_starts_from_the_last_answer_and_reaches_the_same_optimum() {
    let n = 600;
    let first: Vec<f64> = (0..n).map(|i| (i as f64 * 0.05).sin()).collect();
    let second: Vec<f64> = (0..n)
        .map(|i| (i as f64 * 0.05 + 0.3).sin() + 0.2 * (i as f64 * 0.7).cos())
        .collect();
    let tol = Tolerances::for_size(n);
    let mut cache = PatternCache::default();
    let before = coupled_bound_qp_solve(&first, &tol, &mut cache);
    assert_eq!(before.status, IpmStatus::Solved);
    assert_eq!(before.z.len(), n, "the answer's multipliers are kept");
    let warm = coupled_bound_qp_solve(&second, &tol, &mut cache);
    let cold = coupled_bound_qp_solve(&second, &tol, &mut PatternCache::default());
    assert_eq!(
        (warm.status, cold.status),
        (IpmStatus::Solved, IpmStatus::Solved)
    );
    assert!(
        warm.iterations > 0,
        "the active-set attempt alone solved it"
    );
    let gap = (warm.x.iter().zip(&cold.x))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(gap < 1e-7, "warm and cold optima differ by {gap:e}");
}
