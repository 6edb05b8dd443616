//! The 3-D pictures' polygons (`shape_3d.svg`) read back and matched to a mesh's faces by
//! projecting the mesh with the view `formfind --help` documents.

use std::collections::HashMap;

use super::xml::Element;

/// The viewer's direction, as `formfind --help` states it: azimuth −60° in plan, 30° above the
/// horizon.
pub const AZIMUTH_DEG: f64 = -60.0;
pub const ELEVATION_DEG: f64 = 30.0;

pub type V3 = [f64; 3];

/// A drawn face: its three points on the page and its colour as red, green, blue.
pub struct Drawn {
    pub points: [[f64; 2]; 3],
    pub rgb: [u8; 3],
}

/// The polygons inside the group `id`, in drawing order.
pub fn view_polygons(elements: &[Element], id: &str) -> Vec<Drawn> {
    elements
        .iter()
        .filter(|e| e.name == "polygon" && e.parent_id.as_deref() == Some(id))
        .map(|e| {
            let points: Vec<[f64; 2]> = e.attributes["points"]
                .split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').expect("x,y");
                    [x.parse().unwrap(), y.parse().unwrap()]
                })
                .collect();
            assert_eq!(points.len(), 3, "a face is a triangle");
            let colour = e.attributes["color"].strip_prefix('#').expect("#rrggbb");
            let channel = |k: usize| u8::from_str_radix(&colour[2 * k..2 * k + 2], 16).unwrap();
            Drawn {
                points: [points[0], points[1], points[2]],
                rgb: [channel(0), channel(1), channel(2)],
            }
        })
        .collect()
}

pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// (right, up, towards the viewer) of the documented view.
pub fn view_frame() -> [V3; 3] {
    let (a, e) = (AZIMUTH_DEG.to_radians(), ELEVATION_DEG.to_radians());
    let eye = [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()];
    let right = [-a.sin(), a.cos(), 0.0];
    let up = [
        eye[1] * right[2] - eye[2] * right[1],
        eye[2] * right[0] - eye[0] * right[2],
        eye[0] * right[1] - eye[1] * right[0],
    ];
    [right, up, eye]
}

/// For each drawn polygon, the face of `faces` it shows, found by projecting the mesh with
/// the documented view and fitting the page's scale and offset; also returns the scale and the
/// page y of height 0 on the up axis. Every face must be drawn exactly once.
pub fn match_faces(drawn: &[Drawn], pos: &[V3], faces: &[[usize; 3]]) -> (Vec<usize>, f64, f64) {
    let [right, up, _] = view_frame();
    let uv: Vec<[f64; 2]> = pos.iter().map(|&p| [dot(right, p), dot(up, p)]).collect();
    let bounds = |values: &mut dyn Iterator<Item = f64>| {
        values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
    };
    let used: Vec<usize> = faces.iter().flatten().copied().collect();
    let (u_lo, u_hi) = bounds(&mut used.iter().map(|&v| uv[v][0]));
    let (_, v_hi) = bounds(&mut used.iter().map(|&v| uv[v][1]));
    let (x_lo, x_hi) = bounds(&mut drawn.iter().flat_map(|d| d.points.map(|p| p[0])));
    let (y_lo, _) = bounds(&mut drawn.iter().flat_map(|d| d.points.map(|p| p[1])));
    let scale = (x_hi - x_lo) / (u_hi - u_lo);
    let page = |p: [f64; 2]| [x_lo + (p[0] - u_lo) * scale, y_lo + (v_hi - p[1]) * scale];
    let cell = |p: [f64; 2]| ((p[0] / 4.0).floor() as i64, (p[1] / 4.0).floor() as i64);
    let centroid = |q: [[f64; 2]; 3]| [0, 1].map(|k| (q[0][k] + q[1][k] + q[2][k]) / 3.0);
    let projected: Vec<[[f64; 2]; 3]> = faces.iter().map(|f| f.map(|v| page(uv[v]))).collect();
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (t, q) in projected.iter().enumerate() {
        grid.entry(cell(centroid(*q))).or_default().push(t);
    }
    // Rounding to a tenth of a pixel and fitting the scale from rounded extremes.
    let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) < 0.3;
    let same = |d: &Drawn, q: &[[f64; 2]; 3]| {
        d.points.iter().all(|&p| q.iter().any(|&r| close(p, r)))
            && q.iter().all(|&r| d.points.iter().any(|&p| close(p, r)))
    };
    let mut seen = vec![false; faces.len()];
    let order: Vec<usize> = drawn
        .iter()
        .enumerate()
        .map(|(k, d)| {
            let (cx, cy) = cell(centroid(d.points));
            let t = (-1..=1)
                .flat_map(|dx| (-1..=1).map(move |dy| (cx + dx, cy + dy)))
                .filter_map(|c| grid.get(&c))
                .flatten()
                .copied()
                .find(|&t| !seen[t] && same(d, &projected[t]))
                .unwrap_or_else(|| panic!("polygon {k} matches no face of the mesh"));
            seen[t] = true;
            t
        })
        .collect();
    (order, scale, y_lo + v_hi * scale)
}
