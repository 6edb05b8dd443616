//! The report's section of this command line alone: the printable solid of `--solid`. The
//! rest of the report is the library's (`voussoir::report`), shared with `python -m voussoir`.

use serde_json::{json, Value};

use crate::args::Options;
use crate::run::Outcome;

/// The printable solid of `--solid`: the thickness asked for, its size, volume and the range
/// of the distances between the upper and lower copies of a vertex.
pub fn solid(solid: &voussoir::Solid, outcome: &Outcome, o: &Options) -> Value {
    let t = &solid.vertex_thickness;
    let area: f64 = outcome
        .model
        .mesh()
        .faces()
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| outcome.positions[v as usize]);
            let (u, w) = (
                [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
            );
            let n = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() / 2.0
        })
        .sum();
    let thickness = match &o.solid {
        Some((crate::args::SolidThickness::Uniform(t), _)) => json!(t),
        _ => json!({ "density": o.density, "unit_weight": o.solid_unit_weight }),
    };
    json!({
        "thickness": thickness,
        "vertices": solid.positions.len(),
        "faces": solid.faces.len(),
        "volume": solid.volume(),
        "mid_surface_area": area,
        // Thickness over the mean cosine between a vertex's offset and its faces' normals.
        "vertex_offset_min": t.iter().copied().fold(f64::INFINITY, f64::min),
        "vertex_offset_max": t.iter().copied().fold(0.0, f64::max),
    })
}
