//! The last plan check: no two faces overlap in plan.
//!
//! With every face counter-clockwise, the number of faces covering a plan point changes only
//! across boundary edges. So where faces overlap, the region they overlap in is bounded by
//! boundary edges, and a point of such an edge lies in a face other than the edge's own, the
//! two faces overlapping on the edge's inner side. The boundary edges go into a uniform grid;
//! each face is tested (separating axes) against the faces of the boundary edges in the cells
//! it covers, row by row, so that a long thin face visits only the cells along it. Faces
//! sharing a vertex are never tested: the plan angle checks before this one ensure that their
//! sectors at that vertex, and so the faces themselves, do not overlap.

use super::Edge;

/// Faces closer than this (relative to the plan bounding-box diagonal) to being disjoint count
/// as touching: rounding in the input must not make neighbours overlap.
const TOUCH_TOL: f64 = 1e-9;

type Box2 = ([f64; 2], [f64; 2]);

fn plan_of(positions: &[[f64; 3]], f: &[u32; 3]) -> [[f64; 2]; 3] {
    f.map(|v| {
        let p = positions[v as usize];
        [p[0], p[1]]
    })
}

fn bounding_box(t: &[[f64; 2]; 3]) -> Box2 {
    let lo = [0, 1].map(|d| t.iter().map(|p| p[d]).fold(f64::INFINITY, f64::min));
    let hi = [0, 1].map(|d| t.iter().map(|p| p[d]).fold(f64::NEG_INFINITY, f64::max));
    (lo, hi)
}

/// True when an edge of `a` (counter-clockwise) has all of `b` on or outside it, up to `tol`.
fn an_edge_separates(a: &[[f64; 2]; 3], b: &[[f64; 2]; 3], tol: f64) -> bool {
    (0..3).any(|k| {
        let (p, q) = (a[k], a[(k + 1) % 3]);
        let d = [q[0] - p[0], q[1] - p[1]];
        let slack = tol * d[0].hypot(d[1]);
        b.iter()
            .all(|r| d[0] * (r[1] - p[1]) - d[1] * (r[0] - p[0]) <= slack)
    })
}

/// Whether two counter-clockwise triangles share interior points (separating axis theorem:
/// two convex polygons are disjoint exactly when an edge line of one separates them).
fn interiors_overlap(a: &[[f64; 2]; 3], b: &[[f64; 2]; 3], tol: f64) -> bool {
    !an_edge_separates(a, b, tol) && !an_edge_separates(b, a, tol)
}

/// Uniform grid over the plan holding the boundary edges (as their faces' ids), as CSR
/// lists per cell.
struct Grid {
    lo: [f64; 2],
    cell: f64,
    dims: [usize; 2],
    start: Vec<usize>,
    faces: Vec<u32>,
}

impl Grid {
    /// Cells at least as large as the mean boundary edge, and at most about 12 per boundary
    /// edge in all, so that neither the cells nor the lists grow quadratic.
    fn new(plan: Box2, segments: &[(u32, [[f64; 2]; 2])]) -> Grid {
        let (lo, hi) = plan;
        let size = [hi[0] - lo[0], hi[1] - lo[1]];
        let m = segments.len().max(1) as f64;
        let mean_length = segments
            .iter()
            .map(|(_, [a, b])| (b[0] - a[0]).hypot(b[1] - a[1]))
            .sum::<f64>()
            / m;
        let cell = mean_length
            .max((size[0] * size[1] / (4.0 * m)).sqrt())
            .max(size[0].max(size[1]) / (4.0 * m));
        let cell = if cell > 0.0 && cell.is_finite() {
            cell
        } else {
            1.0
        };
        let dims = size.map(|s| (s / cell) as usize + 1);
        let mut grid = Grid {
            lo,
            cell,
            dims,
            start: vec![0; dims[0] * dims[1] + 1],
            faces: Vec::new(),
        };
        let mut count = vec![0usize; dims[0] * dims[1]];
        for (_, seg) in segments {
            grid.cover(seg, |c| count[c] += 1);
        }
        for (c, n) in count.iter().enumerate() {
            grid.start[c + 1] = grid.start[c] + n;
        }
        let mut fill = grid.start.clone();
        let mut faces = vec![0; grid.start[count.len()]];
        for (face, seg) in segments {
            grid.cover(seg, |c| {
                faces[fill[c]] = *face;
                fill[c] += 1;
            });
        }
        grid.faces = faces;
        grid
    }

    /// The cell index (clamped to the grid) of coordinate `x` along axis `d`.
    fn index(&self, x: f64, d: usize) -> usize {
        let k = ((x - self.lo[d]) / self.cell).floor();
        (k.max(0.0) as usize).min(self.dims[d] - 1)
    }

    /// Visits the cells that the convex polygon (or segment) `points` meets, row by row: in
    /// each row, those between the polygon's least and greatest x within the row's band (its
    /// vertices in the band and its edges' crossings of the band's edges), widened by a
    /// hundredth of a cell against rounding. A long thin face visits the cells along it only.
    fn cover(&self, points: &[[f64; 2]], mut visit: impl FnMut(usize)) {
        let margin = 0.01 * self.cell;
        let y_lo = points.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        let y_hi = points
            .iter()
            .map(|p| p[1])
            .fold(f64::NEG_INFINITY, f64::max);
        let (r0, r1) = (self.index(y_lo - margin, 1), self.index(y_hi + margin, 1));
        for r in r0..=r1 {
            let band_lo = (self.lo[1] + r as f64 * self.cell - margin).max(y_lo);
            let band_hi = (self.lo[1] + (r + 1) as f64 * self.cell + margin).min(y_hi);
            let (mut x_lo, mut x_hi) = (f64::INFINITY, f64::NEG_INFINITY);
            let mut take = |x: f64| {
                x_lo = x_lo.min(x);
                x_hi = x_hi.max(x);
            };
            for (k, a) in points.iter().enumerate() {
                if (band_lo..=band_hi).contains(&a[1]) {
                    take(a[0]);
                }
                let b = points[(k + 1) % points.len()];
                for y in [band_lo, band_hi] {
                    if (a[1] - y) * (b[1] - y) < 0.0 {
                        take(a[0] + (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]));
                    }
                }
            }
            if x_lo > x_hi {
                continue;
            }
            let (c0, c1) = (self.index(x_lo - margin, 0), self.index(x_hi + margin, 0));
            for c in c0..=c1 {
                visit(r * self.dims[0] + c);
            }
        }
    }

    fn list(&self, c: usize) -> &[u32] {
        &self.faces[self.start[c]..self.start[c + 1]]
    }
}

/// A pair of faces whose interiors overlap in plan (smaller id first), the one of the
/// smallest face id that has one. `faces` are counter-clockwise in plan, with valid plan
/// angles at every vertex (checks 1-11 passed).
///
/// Where two faces overlap, a point of a boundary edge lies in a face other than its own with
/// the overlap on the edge's inner side (see the module's documentation); so each face is
/// tested against the faces of the boundary edges in the cells it covers.
pub(super) fn first_overlap(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    edges: &[Edge],
) -> Option<[usize; 2]> {
    let triangles: Vec<[[f64; 2]; 3]> = faces.iter().map(|f| plan_of(positions, f)).collect();
    let plan_xy = |v: u32| {
        let p = positions[v as usize];
        [p[0], p[1]]
    };
    let segments: Vec<(u32, [[f64; 2]; 2])> = edges
        .iter()
        .filter_map(|e| {
            let side = if e.is_boundary() {
                e.left.or(e.right)
            } else {
                None
            }?;
            Some((side.face, e.v.map(plan_xy)))
        })
        .collect();
    let plan = triangles.iter().map(bounding_box).fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), (a, b)| {
            (
                [lo[0].min(a[0]), lo[1].min(a[1])],
                [hi[0].max(b[0]), hi[1].max(b[1])],
            )
        },
    );
    let tol = TOUCH_TOL * (plan.1[0] - plan.0[0]).hypot(plan.1[1] - plan.0[1]);
    let grid = Grid::new(plan, &segments);
    // The last face each boundary face was tested against: a pair met in several cells, or
    // through several boundary edges, is tested once.
    let mut tested_with = vec![u32::MAX; faces.len()];
    for (g, f) in faces.iter().enumerate() {
        let mut partner: Option<usize> = None;
        grid.cover(&triangles[g], |c| {
            for &h in grid.list(c) {
                if tested_with[h as usize] == g as u32 {
                    continue;
                }
                tested_with[h as usize] = g as u32;
                let h = h as usize;
                if h == g
                    || partner.is_some_and(|p| p <= h)
                    || faces[h].iter().any(|v| f.contains(v))
                {
                    continue;
                }
                if interiors_overlap(&triangles[g], &triangles[h], tol) {
                    partner = Some(h);
                }
            }
        });
        if let Some(h) = partner {
            return Some([g.min(h), g.max(h)]);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::super::Mesh;

    /// Unit square (vertices 4 k .. 4 k + 3) at `offset`, as two counter-clockwise faces.
    fn square(k: u32, offset: [f64; 2]) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let positions = corners
            .iter()
            .map(|c| [c[0] + offset[0], c[1] + offset[1], 0.0])
            .collect();
        let b = 4 * k;
        (positions, vec![[b, b + 1, b + 2], [b, b + 2, b + 3]])
    }

    fn two_squares(offset: [f64; 2]) -> crate::Result<Mesh> {
        let (mut p, mut f) = square(0, [0.0, 0.0]);
        let (q, g) = square(1, offset);
        p.extend(q);
        f.extend(g);
        Mesh::new(p, f, &[0, 4])
    }

    #[test]
    fn components_that_only_touch_are_accepted() {
        // Side by side (a shared edge, its vertices doubled), corner to corner, and apart by
        // less than rounding.
        for offset in [[1.0, 0.0], [1.0, 1.0], [1.0 + 1e-15, 0.3], [0.0, -1.0]] {
            assert!(two_squares(offset).is_ok(), "{offset:?}");
        }
    }

    /// A thin strip of two faces along the diagonal from `a` to `b`, `width` wide (vertices
    /// 4 k .. 4 k + 3).
    fn strip(k: u32, a: [f64; 2], b: [f64; 2], width: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let d = [b[0] - a[0], b[1] - a[1]];
        let len = d[0].hypot(d[1]);
        let n = [-d[1] / len * width, d[0] / len * width];
        let corners = [a, b, [b[0] + n[0], b[1] + n[1]], [a[0] + n[0], a[1] + n[1]]];
        let base = 4 * k;
        (
            corners.iter().map(|c| [c[0], c[1], 0.0]).collect(),
            vec![[base, base + 1, base + 2], [base, base + 2, base + 3]],
        )
    }

    fn two_strips(second: (Vec<[f64; 3]>, Vec<[u32; 3]>)) -> crate::Result<Mesh> {
        let (mut p, mut f) = strip(0, [0.0, 0.0], [100.0, 100.0], 0.01);
        p.extend(second.0);
        f.extend(second.1);
        Mesh::new(p, f, &[0, 4])
    }

    /// Long thin faces are found where they cross, away from their ends, and not where they
    /// only run close beside each other.
    #[test]
    fn long_thin_faces_crossing_mid_way_overlap() {
        let crossing = two_strips(strip(1, [0.0, 100.0], [100.0, 0.0], 0.01));
        assert!(
            matches!(crossing, Err(crate::Error::OverlappingFaces { .. })),
            "{crossing:?}"
        );
        let beside = two_strips(strip(1, [0.02, 0.0], [100.02, 100.0], 0.01));
        assert!(beside.is_ok(), "{beside:?}");
    }

    #[test]
    fn components_that_overlap_are_named() {
        for (offset, faces) in [
            ([0.0, 0.0], [0, 2]),
            ([0.999, 0.0], [0, 2]),
            ([-0.999, 0.0], [0, 2]),
            ([-0.5, 0.2], [0, 2]),
            ([0.2, 0.2], [0, 2]),
        ] {
            let err = two_squares(offset).unwrap_err();
            assert_eq!(err, crate::Error::OverlappingFaces { faces }, "{offset:?}");
        }
    }
}
