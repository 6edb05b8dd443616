//! The last plan check: no two faces overlap in plan.
//!
//! With every face counter-clockwise, the number of faces covering a plan point changes only
//! across boundary edges, so where faces overlap, a face with a boundary edge overlaps another
//! one (the edge of the overlap region lies on a boundary edge, and on its inner side two
//! faces cover it, that edge's face among them). Only pairs with such a face are tested: the
//! faces with a boundary edge go into a uniform grid, and every face is tested against those
//! in the grid cells its bounding box covers. Faces sharing a vertex are never tested: the
//! plan angle checks before this one ensure that their sectors at that vertex, and so the
//! faces themselves, do not overlap.

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

/// Uniform grid over the plan holding the faces with a boundary edge, as CSR lists per cell.
struct Grid {
    lo: [f64; 2],
    cell: f64,
    dims: [usize; 2],
    start: Vec<usize>,
    faces: Vec<u32>,
}

impl Grid {
    /// Cells at least as large as the mean extent of the faces stored, and at most about
    /// 12 per stored face in all, so that neither the cells nor the lists grow quadratic.
    fn new(plan: Box2, stored: &[(u32, Box2)]) -> Grid {
        let (lo, hi) = plan;
        let size = [hi[0] - lo[0], hi[1] - lo[1]];
        let m = stored.len().max(1) as f64;
        let mean_extent = stored
            .iter()
            .map(|(_, (a, b))| (b[0] - a[0]).max(b[1] - a[1]))
            .sum::<f64>()
            / m;
        let cell = mean_extent
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
        for (_, b) in stored {
            for c in grid.cells(b) {
                grid.start[c + 1] += 1;
            }
        }
        for c in 0..dims[0] * dims[1] {
            grid.start[c + 1] += grid.start[c];
        }
        let mut fill = grid.start.clone();
        grid.faces = vec![0; grid.start[dims[0] * dims[1]]];
        for (t, b) in stored {
            for c in grid.cells(b) {
                grid.faces[fill[c]] = *t;
                fill[c] += 1;
            }
        }
        grid
    }

    /// The cell index range (clamped to the grid) of coordinate `x` along axis `d`.
    fn index(&self, x: f64, d: usize) -> usize {
        let k = ((x - self.lo[d]) / self.cell).floor();
        (k.max(0.0) as usize).min(self.dims[d] - 1)
    }

    /// The cells a bounding box covers, row by row.
    fn cells(&self, (lo, hi): &Box2) -> impl Iterator<Item = usize> {
        let (x0, x1) = (self.index(lo[0], 0), self.index(hi[0], 0));
        let (y0, y1) = (self.index(lo[1], 1), self.index(hi[1], 1));
        let nx = self.dims[0];
        (y0..=y1).flat_map(move |y| (x0..=x1).map(move |x| y * nx + x))
    }

    /// The first cell two boxes share (where their intersection's lower corner lies): a pair
    /// found in several cells is tested in that one only.
    fn first_shared_cell(&self, a: &Box2, b: &Box2) -> usize {
        let x = self.index(a.0[0].max(b.0[0]), 0);
        let y = self.index(a.0[1].max(b.0[1]), 1);
        y * self.dims[0] + x
    }

    fn list(&self, c: usize) -> &[u32] {
        &self.faces[self.start[c]..self.start[c + 1]]
    }
}

fn boxes_meet(a: &Box2, b: &Box2, tol: f64) -> bool {
    (0..2).all(|d| a.0[d] <= b.1[d] + tol && b.0[d] <= a.1[d] + tol)
}

/// A pair of faces whose interiors overlap in plan (smaller id first), the one of the
/// smallest face id that has one. `faces` are
/// counter-clockwise in plan, with valid plan angles at every vertex (checks 1-11 passed).
pub(super) fn first_overlap(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    edges: &[Edge],
) -> Option<[usize; 2]> {
    let triangles: Vec<[[f64; 2]; 3]> = faces.iter().map(|f| plan_of(positions, f)).collect();
    let boxes: Vec<Box2> = triangles.iter().map(bounding_box).collect();
    let mut on_boundary = vec![false; faces.len()];
    for e in edges.iter().filter(|e| e.is_boundary()) {
        if let Some(side) = e.left.or(e.right) {
            on_boundary[side.face as usize] = true;
        }
    }
    let stored: Vec<(u32, Box2)> = (0..faces.len())
        .filter(|&t| on_boundary[t])
        .map(|t| (t as u32, boxes[t]))
        .collect();
    let plan = boxes.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), (a, b)| {
            (
                [lo[0].min(a[0]), lo[1].min(a[1])],
                [hi[0].max(b[0]), hi[1].max(b[1])],
            )
        },
    );
    let tol = TOUCH_TOL * (plan.1[0] - plan.0[0]).hypot(plan.1[1] - plan.0[1]);
    let grid = Grid::new(plan, &stored);
    for (g, f) in faces.iter().enumerate() {
        let mut partner: Option<usize> = None;
        for c in grid.cells(&boxes[g]) {
            for &h in grid.list(c) {
                let h = h as usize;
                // Pairs of two stored faces are tested from the smaller id only.
                let tested_elsewhere = on_boundary[g] && h < g;
                if h == g
                    || tested_elsewhere
                    || partner.is_some_and(|p| p <= h)
                    || faces[h].iter().any(|v| f.contains(v))
                    || !boxes_meet(&boxes[g], &boxes[h], tol)
                    || grid.first_shared_cell(&boxes[g], &boxes[h]) != c
                {
                    continue;
                }
                if interiors_overlap(&triangles[g], &triangles[h], tol) {
                    partner = Some(h);
                }
            }
        }
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
