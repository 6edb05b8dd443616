//! Whether a closed triangle mesh crosses itself: triangles bucketed in a uniform grid, pairs
//! in a shared cell tested with exact orientation predicates (the `robust` crate).

use robust::{orient3d, Coord3D};

/// Two faces of `faces` that cross, the first such pair found, or `None`.
///
/// Faces sharing an edge are not compared (their offsets are checked face by face); faces
/// sharing one vertex cross when the edge opposite it in one passes through the other. A
/// crossing is counted only when strict: touching and exactly coplanar contacts are not.
pub(crate) fn first_crossing(positions: &[[f64; 3]], faces: &[[u32; 3]]) -> Option<(usize, usize)> {
    let boxes: Vec<[[f64; 3]; 2]> = faces.iter().map(|f| bounding_box(positions, f)).collect();
    let grid = Grid::new(&boxes)?;
    let mut entries: Vec<(u64, u32)> = Vec::new();
    for (t, b) in boxes.iter().enumerate() {
        let (lo, hi) = (grid.cell(b[0]), grid.cell(b[1]));
        for i in lo[0]..=hi[0] {
            for j in lo[1]..=hi[1] {
                for k in lo[2]..=hi[2] {
                    entries.push((grid.key([i, j, k]), t as u32));
                }
            }
        }
    }
    entries.sort_unstable();
    for group in entries.chunk_by(|a, b| a.0 == b.0) {
        for (n, &(key, a)) in group.iter().enumerate() {
            for &(_, b) in &group[n + 1..] {
                let (a, b) = (a as usize, b as usize);
                let Some(meet) = overlap(&boxes[a], &boxes[b]) else {
                    continue;
                };
                // Each pair is tested once: in the cell of its boxes' overlap's lower corner.
                if grid.key(grid.cell(meet)) == key && cross(positions, &faces[a], &faces[b]) {
                    return Some((a.min(b), a.max(b)));
                }
            }
        }
    }
    None
}

fn bounding_box(positions: &[[f64; 3]], face: &[u32; 3]) -> [[f64; 3]; 2] {
    let mut b = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
    for &v in face {
        for k in 0..3 {
            b[0][k] = b[0][k].min(positions[v as usize][k]);
            b[1][k] = b[1][k].max(positions[v as usize][k]);
        }
    }
    b
}

/// The lower corner of the overlap of two boxes, if they overlap.
fn overlap(a: &[[f64; 3]; 2], b: &[[f64; 3]; 2]) -> Option<[f64; 3]> {
    (0..3)
        .all(|k| a[0][k] <= b[1][k] && b[0][k] <= a[1][k])
        .then(|| [0, 1, 2].map(|k| a[0][k].max(b[0][k])))
}

/// A uniform grid over the boxes, cells about the size of a typical face.
struct Grid {
    origin: [f64; 3],
    cell: f64,
    dims: [u64; 3],
}

impl Grid {
    fn new(boxes: &[[[f64; 3]; 2]]) -> Option<Grid> {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        let mut size = 0.0;
        for b in boxes {
            for k in 0..3 {
                lo[k] = lo[k].min(b[0][k]);
                hi[k] = hi[k].max(b[1][k]);
            }
            size += (0..3).map(|k| b[1][k] - b[0][k]).fold(0.0, f64::max);
        }
        let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
        if boxes.is_empty() || extent.is_nan() || extent <= 0.0 {
            return None;
        }
        // At most about 64 cells per face in all: a grid finer than the faces only costs.
        let mut cell = (size / boxes.len() as f64).max(extent * 1e-6);
        let cells = |c: f64| {
            (0..3)
                .map(|k| ((hi[k] - lo[k]) / c).floor() + 1.0)
                .product::<f64>()
        };
        while cells(cell) > 64.0 * boxes.len() as f64 {
            cell *= 2.0;
        }
        let dims = [0, 1, 2].map(|k| ((hi[k] - lo[k]) / cell) as u64 + 1);
        Some(Grid {
            origin: lo,
            cell,
            dims,
        })
    }

    fn cell(&self, p: [f64; 3]) -> [u64; 3] {
        [0, 1, 2].map(|k| (((p[k] - self.origin[k]) / self.cell) as u64).min(self.dims[k] - 1))
    }

    fn key(&self, c: [u64; 3]) -> u64 {
        (c[0] * self.dims[1] + c[1]) * self.dims[2] + c[2]
    }
}

fn coord(p: [f64; 3]) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// Whether triangles `a` and `b` (vertex ids) cross.
fn cross(positions: &[[f64; 3]], a: &[u32; 3], b: &[u32; 3]) -> bool {
    let shared: Vec<u32> = a.iter().copied().filter(|v| b.contains(v)).collect();
    let p = |v: u32| positions[v as usize];
    let tri = |f: &[u32; 3]| f.map(p);
    match shared.as_slice() {
        [] => {
            let (ta, tb) = (tri(a), tri(b));
            (0..3).any(|k| segment_crosses(ta[k], ta[(k + 1) % 3], tb))
                || (0..3).any(|k| segment_crosses(tb[k], tb[(k + 1) % 3], ta))
        }
        [v] => {
            let opposite = |f: &[u32; 3]| {
                let k = f.iter().position(|x| x == v).unwrap_or(0);
                (p(f[(k + 1) % 3]), p(f[(k + 2) % 3]))
            };
            let ((a1, a2), (b1, b2)) = (opposite(a), opposite(b));
            segment_crosses(a1, a2, tri(b)) || segment_crosses(b1, b2, tri(a))
        }
        _ => false,
    }
}

/// Whether segment `p`-`q` passes strictly through the interior of triangle `t`.
fn segment_crosses(p: [f64; 3], q: [f64; 3], t: [[f64; 3]; 3]) -> bool {
    let [t0, t1, t2] = t.map(coord);
    let (p, q) = (coord(p), coord(q));
    let (sp, sq) = (orient3d(t0, t1, t2, p), orient3d(t0, t1, t2, q));
    if !(sp > 0.0 && sq < 0.0 || sp < 0.0 && sq > 0.0) {
        return false;
    }
    let s = [
        orient3d(p, q, t0, t1),
        orient3d(p, q, t1, t2),
        orient3d(p, q, t2, t0),
    ];
    s.iter().all(|x| *x > 0.0) || s.iter().all(|x| *x < 0.0)
}
