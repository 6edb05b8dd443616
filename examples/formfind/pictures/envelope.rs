//! The 3-D picture of an assessment (`shape_3d.svg`): the middle surface, and the thrust
//! surface under the translucent extrados, with one projection and scale (that of the
//! form-finding picture, `axonometric.rs`). The thrust surface's faces are coloured by where
//! they lie in the masonry: blue at the intrados, neutral at mid-thickness, red at the
//! extrados.

use svg::Document;

use super::axonometric::{shaded_faces, Projection, AZIMUTH_DEG, ELEVATION_DEG};
use super::{layout, LEGEND, TOP, WIDTH};
use crate::assess::run::Assessed;
use crate::draw::{self, bbox, colour_bar, fmt, page, text};

/// A pale stone colour, red, green and blue in [0, 255].
const STONE: [f64; 3] = [226.0, 214.0, 190.0];
/// Opacity of the extrados drawn over the thrust surface.
const VEIL: f64 = 0.3;

/// Per face: the mean over its corners of (z − lower) / (upper − lower), 0 at the intrados, 1
/// at the extrados (outside [0, 1] where the surface leaves the envelope).
pub fn depth_in_masonry(a: &Assessed) -> Vec<f64> {
    let r = &a.result;
    (a.model.mesh().faces().iter())
        .map(|f| {
            f.iter()
                .map(|&v| {
                    let v = v as usize;
                    let span = r.upper[v] - r.lower[v];
                    if span > 0.0 {
                        (r.positions[v][2] - r.lower[v]) / span
                    } else {
                        0.5
                    }
                })
                .sum::<f64>()
                / 3.0
        })
        .collect()
}

pub fn shape_3d(a: &Assessed) -> Document {
    let mesh = a.model.mesh();
    let projection = Projection::new();
    let middle = a.envelope.middle_positions(mesh);
    let extrados: Vec<[f64; 3]> = (mesh.positions().iter().zip(&a.envelope.upper))
        .map(|(p, &u)| [p[0], p[1], u])
        .collect();
    let thrust = &a.result.positions;
    let referenced = || (0..mesh.n_vertices()).filter(|&v| mesh.referenced()[v]);
    let (lo, hi) = bbox(
        [&middle, &extrados, thrust]
            .into_iter()
            .flat_map(|pos| referenced().map(|v| projection.screen(pos[v]))),
    );
    let (height, views) = layout(lo, hi, 2);
    let mut doc = page(
        WIDTH,
        height,
        &format!("{}: 3-D view of the assessment", a.model.name),
        &format!(
            "axonometric, from {}° azimuth (plan x to the right), {ELEVATION_DEG}° above the \
             horizon; one projection and scale for both views",
            fmt(AZIMUTH_DEG).replace('-', "−")
        ),
    );
    let stone = vec![STONE; mesh.n_faces()];
    let position = depth_in_masonry(a);
    let coloured: Vec<[f64; 3]> = position.iter().map(|&t| draw::diverging_rgb(t)).collect();
    let (x0, _) = views[0].px(lo);
    let (x1, _) = views[1].px(lo);
    doc = doc
        .add(text(x0, TOP + 14.0, 14.0, "middle surface"))
        .add(shaded_faces(
            mesh,
            &middle,
            &projection,
            &views[0],
            &stone,
            "middle-faces",
        ))
        .add(text(
            x1,
            TOP + 14.0,
            14.0,
            "thrust surface, under the extrados",
        ))
        .add(shaded_faces(
            mesh,
            thrust,
            &projection,
            &views[1],
            &coloured,
            "thrust-faces",
        ))
        .add(
            shaded_faces(
                mesh,
                &extrados,
                &projection,
                &views[1],
                &stone,
                "extrados-faces",
            )
            .set("opacity", VEIL),
        );
    let y = height - LEGEND + 40.0;
    let ticks = vec![
        (0.0, "intrados".to_string()),
        (0.5, "middle".to_string()),
        (1.0, "extrados".to_string()),
    ];
    doc.add(colour_bar(
        "depth",
        (30.0, y, 300.0),
        draw::diverging,
        "where the thrust surface lies in the masonry (at the reported thickness)",
        &ticks,
    ))
    .add(text(
        400.0,
        y + 4.0,
        12.0,
        format!(
            "the extrados drawn translucent ({:.0}% opaque)",
            100.0 * VEIL
        ),
    ))
    .add(text(
        400.0,
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
