//! Tests of the dense rows factored apart (`dense`) and of the released pairs of large groups
//! (`row_groups`).

use super::pattern::{stacked, PatternCache};
use super::{solve, IpmStatus, Qp, RowGroups, Tolerances};
use crate::stress::sparse::Csr;

/// min Σ_i (x_i − t_i)² + (Σ_i x_i − T)² subject to w·x = F, with an inactive dense bound
/// Σ_i x_i ≥ L and an inactive bound per unknown: a dense row of P, one of E and one of G. The
/// optimum is x = t − s 1 + (λ/2) w with s = Σ x − T and the multiplier λ, two unknowns of a
/// 2 × 2 system. The split rows keep the factor at a few entries per unknown (the plain
/// normal matrix would be dense: n²/2 of them).
#[test]
fn dense_rows_are_factored_apart_at_the_same_optimum() {
    let n = 200;
    let t: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 / 5.0 - 1.0).collect();
    let w: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 13) % 7) as f64 / 3.0).collect();
    let (target, f) = (3.0, 2.5);
    let mut quad = Csr::new(n);
    for i in 0..n {
        quad.push_row(vec![(i, 1.0)]);
    }
    quad.push_row((0..n).map(|i| (i, 1.0)).collect());
    let weight = vec![2.0; n + 1];
    // ½ xᵀPx + cᵀx + constant = Σ (x_i − t_i)² + (Σ x_i − T)².
    let c: Vec<f64> = t.iter().map(|t| -2.0 * t - 2.0 * target).collect();
    let constant = t.iter().map(|t| t * t).sum::<f64>() + target * target;
    let mut eq = Csr::new(n);
    eq.push_row(w.iter().copied().enumerate().collect());
    // The optimum: 1ᵀx = T + s and wᵀx = F with x = t − s 1 + (λ/2) w.
    let (sum_t, sum_w) = (t.iter().sum::<f64>(), w.iter().sum::<f64>());
    let (wt, ww) = (dot(&w, &t), dot(&w, &w));
    // (n + 1) s − (sum_w / 2) λ = sum_t − T;  sum_w s − (ww / 2) λ = wt − F.
    let (a, b, cc, d) = ((n + 1) as f64, -sum_w / 2.0, sum_w, -ww / 2.0);
    let det = a * d - b * cc;
    let s = ((sum_t - target) * d - b * (wt - f)) / det;
    let lambda = (a * (wt - f) - cc * (sum_t - target)) / det;
    let x_star: Vec<f64> = (0..n).map(|i| t[i] - s + 0.5 * lambda * w[i]).collect();
    let mut ineq = Csr::new(n);
    ineq.push_row((0..n).map(|i| (i, 1.0)).collect());
    let mut h = vec![x_star.iter().sum::<f64>() - 5.0];
    for (i, x) in x_star.iter().enumerate() {
        ineq.push_row(vec![(i, 1.0)]);
        h.push(x - 1.0);
    }
    let qp = Qp {
        quad: &quad,
        quad_weight: &weight,
        c: &c,
        constant,
        eq: &eq,
        f: &[f],
        ineq: &ineq,
        h: &h,
        groups: &RowGroups::default(),
        positions: None,
        slack_unit: None,
    };
    let mut cache = PatternCache::default();
    let out = solve(&qp, &Tolerances::default(), &mut cache);
    assert_eq!(out.status, IpmStatus::Solved);
    let error = (out.x.iter().zip(&x_star))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(error < 1e-7, "largest error {error:e}");
    let pattern = (cache.pattern.as_ref()).expect("the pattern is kept");
    assert_eq!(pattern.dense.count(), 3);
    let factor = pattern.symbolic.len_val();
    assert!(factor <= 10 * n, "{factor} factor entries for {n} unknowns");
    // The same structure without the dense rows' split would hold n²/2 entries.
    let cons = stacked(&eq, &ineq);
    assert!(cons.start[1] - cons.start[0] > 64);
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// For groups beyond 64 rows `released` looks only at the vertices of the polygon of shifts;
/// it releases the same pair as the test of every pair, the best conditioned one that keeps
/// the multipliers non-negative: with positive multipliers (a polygon with many vertices),
/// with all of them zero (every pair qualifies) and with some of them zero.
#[test]
fn large_groups_release_the_pair_every_pair_would() {
    let k = 150;
    let mut seed = 7u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    // A star of k edges around a vertex, unevenly spread and of uneven lengths.
    let coef: Vec<[f64; 2]> = (0..k)
        .map(|i| {
            let angle = 2.0 * std::f64::consts::PI * (i as f64 + 0.8 * next()) / k as f64;
            let length = 0.5 + next();
            [length * angle.cos(), length * angle.sin()]
        })
        .collect();
    let groups = RowGroups {
        start: vec![0, k],
        row: (0..k).collect(),
        coef: coef.clone(),
    };
    let active = vec![true; k];
    let positive: Vec<f64> = (0..k).map(|_| 0.1 + next()).collect();
    let zero = vec![0.0; k];
    let some_zero: Vec<f64> = (0..k)
        .map(|i| if i % 3 == 0 { 0.0 } else { 0.1 + next() })
        .collect();
    for (name, z) in [
        ("positive", positive),
        ("zero", zero),
        ("some zero", some_zero),
    ] {
        let released = groups.released(&active, &z);
        let rows: Vec<usize> = (0..k).filter(|&r| released[r]).collect();
        let expected = every_pair(&coef, &z);
        assert_eq!(rows.len(), 2, "{name}: {rows:?}");
        let q = |(i, j): (usize, usize)| conditioning(coef[i], coef[j]);
        let expected = expected.expect("a feasible pair");
        assert!(
            q((rows[0], rows[1])) >= q(expected) * (1.0 - 1e-12),
            "{name}: released {rows:?}, the best pair is {expected:?}"
        );
        assert!(keeps_non_negative(&coef, &z, rows[0], rows[1]), "{name}");
    }
}

fn conditioning(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] * b[1] - a[1] * b[0]).abs() / (a[0].hypot(a[1]) * b[0].hypot(b[1]))
}

fn keeps_non_negative(coef: &[[f64; 2]], z: &[f64], i: usize, j: usize) -> bool {
    let (a, b) = (coef[i], coef[j]);
    let det = a[0] * b[1] - a[1] * b[0];
    let shift = [
        (-z[i] * b[1] + z[j] * a[1]) / det,
        (-z[j] * a[0] + z[i] * b[0]) / det,
    ];
    (coef.iter().zip(z))
        .all(|(c, z)| z + shift[0] * c[0] + shift[1] * c[1] >= -1e-9 * z.abs().max(1e-300))
}

/// The best conditioned pair that keeps the multipliers non-negative, by testing every pair.
fn every_pair(coef: &[[f64; 2]], z: &[f64]) -> Option<(usize, usize)> {
    let k = coef.len();
    let mut best: Option<(f64, usize, usize)> = None;
    for i in 0..k {
        for j in i + 1..k {
            let q = conditioning(coef[i], coef[j]);
            if q > 1e-6 && best.is_none_or(|(b, ..)| q > b) && keeps_non_negative(coef, z, i, j) {
                best = Some((q, i, j));
            }
        }
    }
    best.map(|(_, i, j)| (i, j))
}
