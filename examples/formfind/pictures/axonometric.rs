//! The 3-D picture: shaded axonometric views of the input and of the form-found shape, side by
//! side with one projection and scale, faces coloured by the height change.

use svg::node::element::{Group, Polygon};
use svg::Document;
use voussoir::Mesh;

use super::{layout, plan_box, LEGEND, TOP, WIDTH};
use crate::draw::{self, bbox, colour_bar, fmt, page, text};
use crate::run::Outcome;

/// Where the viewer stands: azimuth in plan (degrees from +x, counter-clockwise), so plan x runs
/// to the right and away, plan y to the left and away.
pub const AZIMUTH_DEG: f64 = -60.0;
/// The viewer's elevation above the horizon, in degrees.
pub const ELEVATION_DEG: f64 = 30.0;
/// Brightness of a face turned away from the light, so that no face turns black.
const AMBIENT: f64 = 0.35;
/// Brightness of a face square to the light: below 1, so that pale faces stand out from the page.
const FULL: f64 = 0.92;
/// Brightness factor of back faces: the underside, seen through openings or past free edges.
const BACK: f64 = 0.55;

type V3 = [f64; 3];

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// An orthographic view along a fixed direction, and a fixed light.
pub(super) struct Projection {
    right: V3,
    up: V3,
    /// Unit vector from the scene towards the viewer.
    eye: V3,
    /// Unit vector towards the light.
    light: V3,
}

impl Projection {
    pub(super) fn new() -> Projection {
        let (a, e) = (AZIMUTH_DEG.to_radians(), ELEVATION_DEG.to_radians());
        let eye = [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()];
        let right = [-a.sin(), a.cos(), 0.0];
        let up = cross(eye, right);
        // From the upper left, on the viewer's side: the usual light of a drawing.
        let l: V3 = std::array::from_fn(|k| -0.6 * right[k] + 0.6 * up[k] + 0.45 * eye[k]);
        let n = dot(l, l).sqrt();
        Projection {
            right,
            up,
            eye,
            light: l.map(|c| c / n),
        }
    }

    /// Page coordinates (y up) of a point, in model units.
    pub(super) fn screen(&self, p: V3) -> [f64; 2] {
        [dot(self.right, p), dot(self.up, p)]
    }

    /// Distance from the viewer along the view direction, up to a constant.
    fn depth(&self, p: V3) -> f64 {
        -dot(self.eye, p)
    }

    /// Lambert brightness in [0, 1] of the triangle `a b c` (counter-clockwise seen from its
    /// front), darkened by [`BACK`] when the viewer sees its back.
    fn brightness(&self, [a, b, c]: [V3; 3]) -> f64 {
        let n = cross(sub(b, a), sub(c, a));
        let front = dot(n, self.eye) >= 0.0;
        let length = dot(n, n).sqrt();
        let lit = if length > 0.0 {
            let facing = if front { 1.0 } else { -1.0 } * dot(n, self.light) / length;
            AMBIENT + (FULL - AMBIENT) * facing.max(0.0)
        } else {
            AMBIENT
        };
        if front {
            lit
        } else {
            BACK * lit
        }
    }
}

/// Face indices from the farthest to the nearest by mean depth (the painter's order).
fn back_to_front(mesh: &Mesh, pos: &[V3], projection: &Projection) -> Vec<usize> {
    let depth: Vec<f64> = mesh
        .faces()
        .iter()
        .map(|f| {
            f.iter()
                .map(|&v| projection.depth(pos[v as usize]))
                .sum::<f64>()
                / 3.0
        })
        .collect();
    let mut order: Vec<usize> = (0..mesh.n_faces()).collect();
    order.sort_by(|&a, &b| depth[b].total_cmp(&depth[a]));
    order
}

/// One view's faces, back to front, each in its colour `base` shaded. Each polygon carries only
/// its points (to a tenth of a pixel) and its colour; the group fills and outlines every face
/// with that colour (`currentColor`), which closes the hairline gaps anti-aliasing leaves
/// between neighbours.
pub(super) fn shaded_faces(
    mesh: &Mesh,
    pos: &[V3],
    projection: &Projection,
    view: &draw::View,
    base: &[[f64; 3]],
    id: &str,
) -> Group {
    let mut g = draw::Bulk::default();
    for t in back_to_front(mesh, pos, projection) {
        let corners = mesh.faces()[t].map(|v| pos[v as usize]);
        let points: Vec<String> = corners
            .iter()
            .map(|&p| {
                let (x, y) = view.px(projection.screen(p));
                format!("{x:.1},{y:.1}")
            })
            .collect();
        let k = projection.brightness(corners);
        g = g.add(
            Polygon::new()
                .set("points", points.join(" "))
                .set("color", draw::hex(base[t].map(|c| c * k))),
        );
    }
    g.into_group(
        Group::new()
            .set("id", id)
            .set("fill", "currentColor")
            .set("stroke", "currentColor")
            .set("stroke-width", 0.5)
            .set("stroke-linejoin", "round"),
    )
}

/// Per face: the mean height change of its vertices.
fn face_change(mesh: &Mesh, before: &[V3], after: &[V3]) -> Vec<f64> {
    mesh.faces()
        .iter()
        .map(|f| {
            f.iter()
                .map(|&v| after[v as usize][2] - before[v as usize][2])
                .sum::<f64>()
                / 3.0
        })
        .collect()
}

/// The input and (after form finding) the form-found shape, seen from [`AZIMUTH_DEG`] and
/// [`ELEVATION_DEG`]; faces coloured by the height change (neutral without form finding).
pub fn shape_3d(o: &Outcome) -> Document {
    let mesh = o.model.mesh();
    let projection = Projection::new();
    let mut panels = vec![("input", mesh.positions())];
    if o.termination.is_some() {
        panels.push(("form-found", o.positions.as_slice()));
    }
    let referenced = || (0..mesh.n_vertices()).filter(|&v| mesh.referenced()[v]);
    let (lo, hi) = bbox(
        panels
            .iter()
            .flat_map(|(_, pos)| referenced().map(|v| projection.screen(pos[v]))),
    );
    let (height, views) = layout(lo, hi, panels.len());
    let dz = face_change(mesh, mesh.positions(), &o.positions);
    let m = referenced()
        .map(|v| (o.positions[v][2] - mesh.positions()[v][2]).abs())
        .fold(0.0, f64::max);
    let base: Vec<[f64; 3]> = dz
        .iter()
        .map(|d| draw::diverging_rgb(if m > 0.0 { 0.5 + 0.5 * d / m } else { 0.5 }))
        .collect();
    let both = if panels.len() > 1 {
        "; one projection and scale for both views"
    } else {
        ""
    };
    let mut doc = page(
        WIDTH,
        height,
        &format!("{}: 3-D view", o.model.name),
        &format!(
            "axonometric, from {}° azimuth (plan x to the right), {ELEVATION_DEG}° above the horizon{both}",
            fmt(AZIMUTH_DEG).replace('-', "−")
        ),
    );
    for ((label, pos), view) in panels.iter().zip(&views) {
        let (x, _) = view.px(lo);
        let id = format!("{label}-faces");
        doc = doc.add(text(x, TOP + 14.0, 14.0, *label)).add(shaded_faces(
            mesh,
            pos,
            &projection,
            view,
            &base,
            &id,
        ));
    }
    let y = height - LEGEND + 40.0;
    let (colours, x) = if o.termination.is_some() {
        let (plan_lo, plan_hi) = plan_box(mesh, &o.positions);
        let diagonal = (plan_hi[0] - plan_lo[0]).hypot(plan_hi[1] - plan_lo[1]);
        doc = doc.add(change_bar(m, diagonal, y));
        ("same colours in both views: down blue, up red", 420.0)
    } else {
        (
            "no form finding (--stress-only): the input alone, in grey",
            30.0,
        )
    };
    doc.add(text(x, y + 4.0, 12.0, colours))
        .add(text(
            x,
            y + 22.0,
            12.0,
            "lit from the upper left; darker: the underside",
        ))
        .add(draw::scale_bar(
            &views[0],
            (790.0, y + 10.0),
            90.0,
            "length",
        ))
}

/// The colour bar of the height change, up to `m` either way, with ticks in model units and in
/// per cent of the plan `diagonal`.
fn change_bar(m: f64, diagonal: f64, y: f64) -> Group {
    let share = format!("{:.2}%", 100.0 * m / diagonal.max(1e-300));
    let ticks = vec![
        (0.0, format!("−{} (−{share})", fmt(m))),
        (0.5, "0".to_string()),
        (1.0, format!("+{} (+{share})", fmt(m))),
    ];
    colour_bar(
        "dz3",
        (70.0, y, 260.0),
        draw::diverging,
        "height change Δz in model units (% of the plan diagonal)",
        &ticks,
    )
}
