//! Distances between two triangulated surfaces (Metro-style, sampled at vertices): the
//! symmetric Hausdorff distance and the area-weighted RMS distance, as the paper reports them.
//! A uniform plan grid prunes the search: the 3-D distance to a triangle is at least the plan
//! distance to its plan bounding box.

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Squared distance from `p` to triangle (a, b, c) (Ericson, Real-Time Collision Detection 5.1.5).
pub fn point_triangle_distance2(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    let closest = |q: [f64; 3]| dot(sub(p, q), sub(p, q));
    let along =
        |o: [f64; 3], d: [f64; 3], t: f64| [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
    if d1 <= 0.0 && d2 <= 0.0 {
        return closest(a);
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return closest(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return closest(along(a, ab, d1 / (d1 - d3)));
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return closest(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return closest(along(a, ac, d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return closest(along(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    closest([
        a[0] + ab[0] * v + ac[0] * w,
        a[1] + ab[1] * v + ac[1] * w,
        a[2] + ab[2] * v + ac[2] * w,
    ])
}

/// A triangle surface with its triangles bucketed on a plan grid.
pub struct Surface<'a> {
    positions: &'a [[f64; 3]],
    faces: &'a [[u32; 3]],
    lo: [f64; 2],
    cell: f64,
    dims: [usize; 2],
    buckets: Vec<Vec<u32>>,
}

impl<'a> Surface<'a> {
    pub fn new(positions: &'a [[f64; 3]], faces: &'a [[u32; 3]]) -> Surface<'a> {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for f in faces {
            for &v in f {
                let p = positions[v as usize];
                for d in 0..2 {
                    lo[d] = lo[d].min(p[d]);
                    hi[d] = hi[d].max(p[d]);
                }
            }
        }
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
        let side = (faces.len() as f64).sqrt().ceil().max(1.0) as usize;
        let cell = extent / side as f64 * 1.000001;
        let dims = [
            ((hi[0] - lo[0]) / cell) as usize + 1,
            ((hi[1] - lo[1]) / cell) as usize + 1,
        ];
        let mut buckets = vec![Vec::new(); dims[0] * dims[1]];
        for (t, f) in faces.iter().enumerate() {
            let (mut a, mut b) = ([usize::MAX; 2], [0usize; 2]);
            for &v in f {
                let p = positions[v as usize];
                for d in 0..2 {
                    let c = ((p[d] - lo[d]) / cell) as usize;
                    a[d] = a[d].min(c);
                    b[d] = b[d].max(c);
                }
            }
            for i in a[0]..=b[0].min(dims[0] - 1) {
                for j in a[1]..=b[1].min(dims[1] - 1) {
                    buckets[i * dims[1] + j].push(t as u32);
                }
            }
        }
        Surface {
            positions,
            faces,
            lo,
            cell,
            dims,
            buckets,
        }
    }

    /// Distance from `p` to the surface: rings of cells are searched outwards until the ring's
    /// plan distance exceeds the best distance found.
    pub fn distance(&self, p: [f64; 3]) -> f64 {
        let c = [0, 1]
            .map(|d| (((p[d] - self.lo[d]) / self.cell).max(0.0) as usize).min(self.dims[d] - 1));
        let mut best = f64::INFINITY;
        let max_ring = self.dims[0].max(self.dims[1]);
        for ring in 0..=max_ring {
            if ring > 0 && ((ring - 1) as f64 * self.cell).powi(2) > best {
                break;
            }
            let (i0, i1) = (
                c[0].saturating_sub(ring),
                (c[0] + ring).min(self.dims[0] - 1),
            );
            let (j0, j1) = (
                c[1].saturating_sub(ring),
                (c[1] + ring).min(self.dims[1] - 1),
            );
            for i in i0..=i1 {
                for j in j0..=j1 {
                    let on_ring = i + ring == c[0]
                        || i == c[0] + ring
                        || j + ring == c[1]
                        || j == c[1] + ring;
                    if !on_ring {
                        continue;
                    }
                    for &t in &self.buckets[i * self.dims[1] + j] {
                        let [a, b, cc] = self.faces[t as usize].map(|v| self.positions[v as usize]);
                        best = best.min(point_triangle_distance2(p, a, b, cc));
                    }
                }
            }
        }
        best.sqrt()
    }
}

/// Symmetric vertex-sampled Hausdorff distance and the RMS distance of `b`'s vertices to `a`
/// weighted by their areas (a third of the incident 3-D triangle areas).
pub fn surface_distances(
    a_positions: &[[f64; 3]],
    b_positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    used: &[bool],
) -> (f64, f64) {
    let (sa, sb) = (
        Surface::new(a_positions, faces),
        Surface::new(b_positions, faces),
    );
    let mut area = vec![0.0; b_positions.len()];
    for f in faces {
        let [p, q, r] = f.map(|v| b_positions[v as usize]);
        let (u, w) = (sub(q, p), sub(r, p));
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        f.iter()
            .for_each(|&v| area[v as usize] += dot(n, n).sqrt() / 6.0);
    }
    let (mut h, mut sum, mut wsum) = (0.0f64, 0.0, 0.0);
    for v in (0..b_positions.len()).filter(|&v| used[v]) {
        let d = sa.distance(b_positions[v]);
        h = h.max(d).max(sb.distance(a_positions[v]));
        sum += area[v] * d * d;
        wsum += area[v];
    }
    (h, if wsum > 0.0 { (sum / wsum).sqrt() } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_triangle_distance_against_closed_cases() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        // Above the interior, beyond a vertex, beside an edge.
        assert!((point_triangle_distance2([0.2, 0.2, 0.5], a, b, c) - 0.25).abs() < 1e-15);
        assert!((point_triangle_distance2([2.0, 0.0, 0.0], a, b, c) - 1.0).abs() < 1e-15);
        assert!((point_triangle_distance2([1.0, 1.0, 0.0], a, b, c) - 0.5).abs() < 1e-15);
        assert!((point_triangle_distance2([0.5, -1.0, 1.0], a, b, c) - 2.0).abs() < 1e-15);
    }

    #[test]
    fn grid_search_equals_brute_force() {
        let mut positions = Vec::new();
        let n = 12;
        for i in 0..=n {
            for j in 0..=n {
                let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                positions.push([x, y, (3.0 * x).sin() * (2.0 * y).cos() * 0.3]);
            }
        }
        let mut faces = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let v = (i * (n + 1) + j) as u32;
                let w = v + n as u32 + 1;
                faces.push([v, w, v + 1]);
                faces.push([v + 1, w, w + 1]);
            }
        }
        let s = Surface::new(&positions, &faces);
        for k in 0..200 {
            let p = [
                (k as f64 * 0.137).fract() * 1.6 - 0.3,
                (k as f64 * 0.291).fract() * 1.6 - 0.3,
                (k as f64 * 0.71).sin(),
            ];
            let brute = faces
                .iter()
                .map(|f| {
                    let [a, b, c] = f.map(|v| positions[v as usize]);
                    point_triangle_distance2(p, a, b, c)
                })
                .fold(f64::INFINITY, f64::min)
                .sqrt();
            assert!((s.distance(p) - brute).abs() < 1e-14, "{p:?}");
        }
    }
}
