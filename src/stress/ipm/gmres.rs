//! One cycle of GMRES: the least-squares combination of a Krylov basis that best reduces a
//! residual. Where the regularised factor leaves a few directions of the Newton system
//! unresolved (curvatures below the static regularisation), plain refinement converges at
//! the rate reg / (reg + λ) ≈ 1 along them and stalls; a Krylov method preconditioned with the
//! same factor resolves a few such directions in as many iterations.

use super::dot;

/// Runs up to `k` Arnoldi steps of the operator `op` from the residual `r0`, stopping early once
/// the least-squares residual (2-norm) is at most `target`. Returns Σ y_j v_j, the combination
/// of the basis vectors that minimises ‖r0 − op(Σ y_j v_j)‖₂, and that minimum; None if `r0` is
/// zero or not finite, or if the first step already breaks down (op(r0) zero or not finite).
pub(super) fn cycle(
    op: &mut dyn FnMut(&[f64]) -> Vec<f64>,
    r0: &[f64],
    k: usize,
    target: f64,
) -> Option<(Vec<f64>, f64)> {
    let beta = norm(r0);
    if !(beta.is_finite() && beta > 0.0) {
        return None;
    }
    let mut basis: Vec<Vec<f64>> = vec![r0.iter().map(|v| v / beta).collect()];
    // Hessenberg columns, rotated into upper triangular form as they come.
    let mut h: Vec<Vec<f64>> = Vec::new();
    let (mut cs, mut sn): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
    let mut g = vec![beta];
    let mut residual = beta;
    for j in 0..k {
        crate::interrupt::poll();
        let mut w = op(&basis[j]);
        let w_norm = norm(&w);
        // Modified Gram–Schmidt, twice: the basis must stay orthogonal to the last digits
        // for the least-squares residual to be the true one.
        let mut coef = vec![0.0; j + 1];
        for _ in 0..2 {
            for (i, v) in basis.iter().enumerate() {
                let c = dot(&w, v);
                coef[i] += c;
                w.iter_mut().zip(v).for_each(|(a, b)| *a -= c * b);
            }
        }
        let mut col = coef;
        let h_next = norm(&w);
        col.push(h_next);
        for i in 0..j {
            let (a, b) = (col[i], col[i + 1]);
            col[i] = cs[i] * a + sn[i] * b;
            col[i + 1] = -sn[i] * a + cs[i] * b;
        }
        let (a, b) = (col[j], col[j + 1]);
        let r = a.hypot(b);
        if !(r.is_finite() && r > f64::MIN_POSITIVE) {
            break;
        }
        cs.push(a / r);
        sn.push(b / r);
        col[j] = r;
        col[j + 1] = 0.0;
        g.push(-sn[j] * g[j]);
        g[j] *= cs[j];
        h.push(col);
        residual = g[j + 1].abs();
        // Breakdown: what op adds to the basis is rounding (the solution lies in it).
        if residual <= target || h_next <= f64::EPSILON * w_norm || j + 1 == k {
            break;
        }
        basis.push(w.iter().map(|v| v / h_next).collect());
    }
    if h.is_empty() {
        return None;
    }
    // Back substitution in the rotated (triangular) system.
    let m = h.len();
    let mut y = vec![0.0; m];
    for i in (0..m).rev() {
        let s: f64 = (i + 1..m).map(|l| h[l][i] * y[l]).sum();
        y[i] = (g[i] - s) / h[i][i];
    }
    let mut out = vec![0.0; r0.len()];
    for (v, c) in basis.iter().zip(&y) {
        out.iter_mut().zip(v).for_each(|(o, v)| *o += c * v);
    }
    Some((out, residual))
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A nonsymmetric 6×6 system: a full cycle solves it exactly, a short one reduces the
    /// residual to the reported minimum.
    #[test]
    fn a_full_cycle_solves_and_a_short_one_reports_its_residual() {
        let n = 6;
        let a: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        if i == j {
                            4.0 + i as f64
                        } else {
                            ((i * 7 + j * 3) % 5) as f64 * 0.3 - 0.5
                        }
                    })
                    .collect()
            })
            .collect();
        let mul = |x: &[f64]| -> Vec<f64> { a.iter().map(|row| dot(row, x)).collect() };
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 1.3).sin() + 0.2).collect();
        let (x, res) = cycle(&mut |v| mul(v), &b, n, 0.0).unwrap();
        let r: Vec<f64> = mul(&x).iter().zip(&b).map(|(ax, b)| b - ax).collect();
        assert!(norm(&r) < 1e-12 * norm(&b), "residual {}", norm(&r));
        assert!(res < 1e-12 * norm(&b));
        let (x2, res2) = cycle(&mut |v| mul(v), &b, 2, 0.0).unwrap();
        let r2: Vec<f64> = mul(&x2).iter().zip(&b).map(|(ax, b)| b - ax).collect();
        assert!((norm(&r2) - res2).abs() < 1e-12 * norm(&b));
        assert!(res2 < norm(&b) && res2 > 1e-6 * norm(&b));
        assert!(cycle(&mut |v| mul(v), &vec![0.0; n], n, 0.0).is_none());
        // A target stops the cycle as soon as the least-squares residual meets it.
        let mut calls = 0;
        let target = 0.5 * norm(&b);
        let (x3, res3) = cycle(
            &mut |v| {
                calls += 1;
                mul(v)
            },
            &b,
            n,
            target,
        )
        .unwrap();
        let r3: Vec<f64> = mul(&x3).iter().zip(&b).map(|(ax, b)| b - ax).collect();
        assert!(res3 <= target && (norm(&r3) - res3).abs() < 1e-12 * norm(&b));
        assert!(calls < n, "{calls} operator calls");
        // An operator that returns NaN ends the cycle without an answer.
        assert!(cycle(&mut |v| vec![f64::NAN; v.len()], &b, n, 0.0).is_none());
    }
}
