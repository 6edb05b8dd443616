//! Vertical loads per vertex (docs/method.md §2): a share of each face's weight plus point loads.

use crate::mesh::Mesh;

/// How a face's weight is shared among its three vertices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum LoadRule {
    /// One third of the 3-D triangle area each (the paper's and VHWP12's rule).
    #[default]
    Barycentric,
    /// Mixed Voronoi area of the 3-D triangle (Meyer et al.): smoother on irregular meshes.
    Voronoi,
    /// One third of the plan (projected) area each: a load given per unit of plan.
    PlanArea,
}

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// 2^e, exactly (for e in the normal exponent range).
fn power_of_two(e: i32) -> f64 {
    f64::from_bits(((e + 1023) as u64) << 52)
}

/// Area shares of the three corners of triangle (a, b, c) under `rule`, computed on the
/// triangle scaled by a power of two to coordinates of order 1 and scaled back: the squares
/// inside the area formulas then neither overflow (coordinates beyond about 1e77) nor
/// underflow (below about 1e-77), and in between the result is bit for bit the unscaled one.
fn corner_shares(rule: LoadRule, p: [[f64; 3]; 3]) -> [f64; 3] {
    let largest = p.iter().flatten().fold(0.0f64, |m, c| m.max(c.abs()));
    if !largest.is_normal() {
        return unscaled_shares(rule, p);
    }
    // 2^(2e) stays a double; beyond, the coordinates are far outside what a mesh accepts.
    let e = (largest.log2().floor() as i32).clamp(-511, 511);
    let scaled = p.map(|q| q.map(|c| c * power_of_two(-e)));
    unscaled_shares(rule, scaled).map(|s| s * power_of_two(2 * e))
}

/// Area shares of the three corners of triangle (a, b, c) under `rule`.
fn unscaled_shares(rule: LoadRule, p: [[f64; 3]; 3]) -> [f64; 3] {
    match rule {
        LoadRule::Barycentric => {
            let n = cross3(sub3(p[1], p[0]), sub3(p[2], p[0]));
            [dot3(n, n).sqrt() / 6.0; 3]
        }
        LoadRule::PlanArea => {
            let a = ((p[1][0] - p[0][0]) * (p[2][1] - p[0][1])
                - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]))
                .abs();
            [a / 6.0; 3]
        }
        LoadRule::Voronoi => {
            let n = cross3(sub3(p[1], p[0]), sub3(p[2], p[0]));
            let area = dot3(n, n).sqrt() / 2.0;
            // Corner k, its edges to the next (i) and previous (j) corner.
            let corner_dot = |k: usize| {
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                dot3(sub3(p[i], p[k]), sub3(p[j], p[k]))
            };
            if let Some(obtuse) = (0..3).find(|&k| corner_dot(k) < 0.0) {
                return std::array::from_fn(|k| if k == obtuse { area / 2.0 } else { area / 4.0 });
            }
            let cot = |k: usize| corner_dot(k) / (2.0 * area);
            let len2 = |a: usize, b: usize| dot3(sub3(p[a], p[b]), sub3(p[a], p[b]));
            // Voronoi area at k: (|k i|² cot(j) + |k j|² cot(i)) / 8.
            std::array::from_fn(|k| {
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                (len2(k, i) * cot(j) + len2(k, j) * cot(i)) / 8.0
            })
        }
    }
}

/// Loads p_i = Σ_t ρ_t · share_i(t) + extra_i. `density` is per face, `extra` per vertex.
pub fn vertex_loads(
    mesh: &Mesh,
    positions: &[[f64; 3]],
    rule: LoadRule,
    density: &[f64],
    extra: &[f64],
) -> Vec<f64> {
    let mut p = extra.to_vec();
    for (t, f) in mesh.faces.iter().enumerate() {
        let shares = corner_shares(rule, f.map(|i| positions[i as usize]));
        for k in 0..3 {
            p[f[k] as usize] += density[t] * shares[k];
        }
    }
    p
}

/// Derivatives of the loads with respect to heights, ∂p_i/∂z_k, for vertices sharing a face:
/// `diagonal[i]` = ∂p_i/∂z_i and, per edge (v0, v1), `edge[e]` = [∂p_v0/∂z_v1, ∂p_v1/∂z_v0].
/// Nearly vertical faces make loads change fastest with heights.
pub struct LoadJacobian {
    pub diagonal: Vec<f64>,
    pub edge: Vec<[f64; 2]>,
}

/// The load Jacobian at `positions` by central differences of each face's corner shares
/// (step 1e-6 of the face's longest edge; the shares are smooth in the heights).
pub fn load_jacobian(
    mesh: &Mesh,
    positions: &[[f64; 3]],
    rule: LoadRule,
    density: &[f64],
) -> LoadJacobian {
    let mut diagonal = vec![0.0; positions.len()];
    let mut edge = vec![[0.0; 2]; mesh.edges.len()];
    for (t, f) in mesh.faces.iter().enumerate() {
        // Relative to the first corner where the heights lie far from 0 (the shares depend on
        // differences only, and a step of 1e-6 added to heights of 10⁷ would be rounded to a
        // thousandth of itself).
        let corners = f.map(|i| positions[i as usize]);
        let heights = corners.map(|c| c[2]);
        let corners = match super::far_base(&heights[..1], &heights) {
            0.0 => corners,
            _ => corners.map(|c| sub3(c, corners[0])),
        };
        let size = (0..3)
            .map(|k| {
                dot3(
                    sub3(corners[(k + 1) % 3], corners[k]),
                    sub3(corners[(k + 1) % 3], corners[k]),
                )
            })
            .fold(0.0f64, f64::max)
            .sqrt();
        let h = 1e-6 * size;
        if h == 0.0 {
            continue;
        }
        for k in 0..3 {
            let (mut up, mut down) = (corners, corners);
            up[k][2] += h;
            down[k][2] -= h;
            let (su, sd) = (corner_shares(rule, up), corner_shares(rule, down));
            for i in 0..3 {
                let d = density[t] * (su[i] - sd[i]) / (2.0 * h);
                if i == k {
                    diagonal[f[i] as usize] += d;
                    continue;
                }
                let (a, b) = (f[i], f[k]);
                let e = mesh.face_edges[t]
                    .iter()
                    .copied()
                    .find(|&e| {
                        let v = mesh.edges[e as usize].v;
                        (v[0] == a && v[1] == b) || (v[0] == b && v[1] == a)
                    })
                    .expect("the corners of a face share an edge") as usize;
                edge[e][usize::from(mesh.edges[e].v[0] != a)] += d;
            }
        }
    }
    LoadJacobian { diagonal, edge }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voronoi_shares_sum_to_area_for_acute_and_obtuse() {
        for tri in [
            [[0.0, 0.0, 0.0], [1.0, 0.1, 0.3], [0.4, 0.9, -0.2]],
            [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [1.0, 0.2, 0.1]],
        ] {
            let n = cross3(sub3(tri[1], tri[0]), sub3(tri[2], tri[0]));
            let area = dot3(n, n).sqrt() / 2.0;
            let s = corner_shares(LoadRule::Voronoi, tri);
            assert!(
                (s.iter().sum::<f64>() - area).abs() < 1e-14,
                "{s:?} vs {area}"
            );
            assert!(s.iter().all(|&x| x > 0.0));
        }
    }

    #[test]
    fn shares_are_exact_at_extreme_scales() {
        let tri = [[0.0, 0.0, 0.0], [1.0, 0.1, 0.3], [0.4, 0.9, -0.2]];
        for rule in [LoadRule::Barycentric, LoadRule::Voronoi, LoadRule::PlanArea] {
            let unit = corner_shares(rule, tri);
            // Powers of two: the shares scale exactly by the square.
            for e in [-250, -80, 80, 250] {
                let s = 2f64.powi(e);
                let scaled = corner_shares(rule, tri.map(|p| p.map(|c| c * s)));
                let expected = unit.map(|a| a * s * s);
                assert_eq!(scaled, expected, "{rule:?} at 2^{e}");
            }
        }
    }

    #[test]
    fn plan_share_ignores_height() {
        let s = corner_shares(
            LoadRule::PlanArea,
            [[0.0, 0.0, 5.0], [2.0, 0.0, -1.0], [0.0, 3.0, 2.0]],
        );
        assert_eq!(s, [1.0; 3]);
    }
}
