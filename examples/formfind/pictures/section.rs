//! The section picture of an assessment (`section.svg`): a vertical plane through the plan
//! cuts the masonry (between intrados and extrados), the middle surface and the thrust
//! surface; each surface is sampled on the plane through the mesh's triangles, with its
//! heights interpolated linearly along the edges the plane crosses.

use svg::node::element::{Circle, Group, Path, Polygon};
use svg::Document;
use voussoir::Mesh;

use super::{layout, plan_box, LEGEND, WIDTH};
use crate::assess::args::Section;
use crate::assess::run::Assessed;
use crate::draw::{self, bbox, fmt, line, page, text, View};

const STONE: &str = "#e9dfc9";
const LEAST: &str = "#c8ab74";
const THRUST: &str = "#d62728";

/// Where the plane crosses a mesh edge: heights there are `(1 − t) h[a] + t h[b]`.
#[derive(Debug, Clone, Copy)]
struct Station {
    /// The coordinate along the section (y for a plane x = const, x for y = const).
    s: f64,
    a: usize,
    b: usize,
    t: f64,
}

impl Station {
    fn height(&self, h: &[f64]) -> f64 {
        (1.0 - self.t) * h[self.a] + self.t * h[self.b]
    }

    /// The vertex it stands on, if any.
    fn vertex(&self) -> Option<usize> {
        if self.t == 0.0 {
            Some(self.a)
        } else if self.t == 1.0 {
            Some(self.b)
        } else {
            None
        }
    }
}

/// The plane's position: the value given or the plan's centre on its axis.
pub fn position(mesh: &Mesh, section: Section) -> f64 {
    let (lo, hi) = plan_box(mesh, mesh.positions());
    section
        .at
        .unwrap_or(0.5 * (lo[section.axis] + hi[section.axis]))
}

/// The plane must cross the plan.
pub fn check(mesh: &Mesh, section: Section) -> Result<(), String> {
    let at = position(mesh, section);
    if cut(mesh, section.axis, at).is_empty() {
        let (lo, hi) = plan_box(mesh, mesh.positions());
        let name = section.axis_name();
        return Err(format!(
            "--section: the plane {name} = {at} does not cross the plan ({name} from {} to {})",
            lo[section.axis], hi[section.axis]
        ));
    }
    Ok(())
}

/// The segment the plane `p[axis] = at` cuts from each face it crosses, in face order.
/// Crossings closer than 1e-9 of the plan's extent are one (the plane through a vertex
/// crosses its two edges there).
fn cut(mesh: &Mesh, axis: usize, at: f64) -> Vec<[Station; 2]> {
    let along = 1 - axis;
    let (lo, hi) = plan_box(mesh, mesh.positions());
    let tolerance = 1e-9 * (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let mut segments = Vec::new();
    for f in mesh.faces() {
        let v = f.map(|v| v as usize);
        let d = v.map(|v| mesh.positions()[v][axis] - at);
        let mut points: Vec<Station> = Vec::new();
        for k in 0..3 {
            let (i, j) = (k, (k + 1) % 3);
            let t = if d[i] == 0.0 {
                0.0
            } else if d[i] * d[j] < 0.0 {
                d[i] / (d[i] - d[j])
            } else {
                continue;
            };
            let (a, b) = (v[i], v[j]);
            let s = (1.0 - t) * mesh.positions()[a][along] + t * mesh.positions()[b][along];
            if points.iter().all(|p| (p.s - s).abs() > tolerance) {
                points.push(Station { s, a, b, t });
            }
        }
        if let [p, q] = points[..] {
            segments.push(if p.s <= q.s { [p, q] } else { [q, p] });
        }
    }
    segments
}

/// One `M x,y L x,y` subpath per segment of the surface of heights `h`.
fn polyline(segments: &[[Station; 2]], h: &[f64], view: &View) -> String {
    let mut d = String::new();
    for [p, q] in segments {
        let (a, b) = (view.px([p.s, p.height(h)]), view.px([q.s, q.height(h)]));
        d += &format!("M{:.2},{:.2} L{:.2},{:.2} ", a.0, a.1, b.0, b.1);
    }
    d.trim_end().to_string()
}

/// One closed quadrilateral per segment between the surfaces `lo` and `hi`.
fn band(segments: &[[Station; 2]], lo: &[f64], hi: &[f64], view: &View) -> String {
    let mut d = String::new();
    for [p, q] in segments {
        let corners = [
            view.px([p.s, p.height(lo)]),
            view.px([q.s, q.height(lo)]),
            view.px([q.s, q.height(hi)]),
            view.px([p.s, p.height(hi)]),
        ];
        let c: Vec<String> = corners
            .iter()
            .map(|(x, y)| format!("{x:.2},{y:.2}"))
            .collect();
        d += &format!("M{} L{} L{} L{} Z ", c[0], c[1], c[2], c[3]);
    }
    d.trim_end().to_string()
}

fn stroke(id: &str, d: String, colour: &str, width: f64) -> Path {
    Path::new()
        .set("id", id)
        .set("d", d)
        .set("fill", "none")
        .set("stroke", colour)
        .set("stroke-width", width)
        .set("stroke-linecap", "round")
}

fn fill(id: &str, d: String, colour: &str) -> Path {
    Path::new()
        .set("id", id)
        .set("d", d)
        .set("fill", colour)
        .set("stroke", colour)
        .set("stroke-width", 0.3)
}

/// Supports on the plane: stations at an anchored vertex or on an edge between two.
fn supports(mesh: &Mesh, segments: &[[Station; 2]], z: &[f64], view: &View) -> Group {
    let mut g = Group::new().set("id", "supports");
    let mut seen: Vec<f64> = Vec::new();
    for p in segments.iter().flatten() {
        let anchored = match p.vertex() {
            Some(v) => mesh.anchored()[v],
            None => mesh.anchored()[p.a] && mesh.anchored()[p.b],
        };
        if !anchored || seen.contains(&p.s) {
            continue;
        }
        seen.push(p.s);
        let (x, y) = view.px([p.s, p.height(z)]);
        g = g.add(
            Polygon::new()
                .set(
                    "points",
                    format!(
                        "{x:.2},{y:.2} {:.2},{:.2} {:.2},{:.2}",
                        x - 6.0,
                        y + 10.0,
                        x + 6.0,
                        y + 10.0
                    ),
                )
                .set("fill", "#111"),
        );
    }
    g
}

/// Circles where the thrust surface meets a bound of the reported thickness on the plane
/// (a hinge), within 1e-6 of the plan diagonal.
fn contacts(a: &Assessed, segments: &[[Station; 2]], z: &[f64], view: &View) -> Group {
    let r = &a.result;
    let (lo, hi) = plan_box(a.model.mesh(), &r.positions);
    let slack = 1e-6 * (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    let mut g = Group::new().set("id", "contacts");
    let mut seen: Vec<f64> = Vec::new();
    for p in segments.iter().flatten() {
        let h = p.height(z);
        let touches =
            (h - p.height(&r.lower)).abs() <= slack || (p.height(&r.upper) - h).abs() <= slack;
        if !touches || seen.contains(&p.s) {
            continue;
        }
        seen.push(p.s);
        let (x, y) = view.px([p.s, h]);
        g = g.add(
            Circle::new()
                .set("cx", x)
                .set("cy", y)
                .set("r", 4.0)
                .set("fill", "none")
                .set("stroke", "#1f77b4")
                .set("stroke-width", 1.5),
        );
    }
    g
}

/// The section picture of an assessment.
pub fn section(a: &Assessed, section: Section) -> Document {
    let mesh = a.model.mesh();
    let r = &a.result;
    let at = position(mesh, section);
    let segments = cut(mesh, section.axis, at);
    let env = &a.envelope;
    let z: Vec<f64> = r.positions.iter().map(|p| p[2]).collect();
    let least = r.thickness_scale != 1.0;
    let mut heights = vec![&env.lower, &env.upper, &z];
    if least {
        heights.extend([&r.lower, &r.upper]);
    }
    let (lo, hi) = bbox(
        segments
            .iter()
            .flatten()
            .flat_map(|p| heights.iter().map(|h| [p.s, p.height(h)])),
    );
    let (height, views) = layout(lo, hi, 1);
    let view = &views[0];
    let along = ["y", "x"][section.axis];
    let verdict = if r.feasible {
        "a thrust surface fits".to_string()
    } else {
        format!(
            "no thrust surface found inside the envelope (ε∞ = {:.2e})",
            r.eps_inf
        )
    };
    let mut doc = page(
        WIDTH,
        height,
        &format!(
            "{}: section {} = {}",
            a.model.name,
            section.axis_name(),
            fmt(at)
        ),
        &format!(
            "vertical section along {along}, true scale; {}: {verdict}",
            r.objective.as_str()
        ),
    )
    .add(fill(
        "envelope",
        band(&segments, &env.lower, &env.upper, view),
        STONE,
    ));
    if least {
        doc = doc.add(fill(
            "least-envelope",
            band(&segments, &r.lower, &r.upper, view),
            LEAST,
        ));
    }
    doc = doc
        .add(stroke(
            "intrados",
            polyline(&segments, &env.lower, view),
            "#8c7853",
            1.0,
        ))
        .add(stroke(
            "extrados",
            polyline(&segments, &env.upper, view),
            "#8c7853",
            1.0,
        ))
        .add(
            stroke(
                "middle",
                polyline(&segments, &env.middle, view),
                "#777",
                0.8,
            )
            .set("stroke-dasharray", "4,3"),
        )
        .add(stroke("thrust", polyline(&segments, &z, view), THRUST, 2.0))
        .add(contacts(a, &segments, &z, view))
        .add(supports(mesh, &segments, &z, view));
    legend(doc, height, view, least, along)
}

fn legend(doc: Document, height: f64, view: &View, least: bool, along: &str) -> Document {
    let y = height - LEGEND + 30.0;
    let swatch = |x: f64, colour: &str| {
        svg::node::element::Rectangle::new()
            .set("x", x)
            .set("y", y - 10.0)
            .set("width", 18.0)
            .set("height", 12.0)
            .set("fill", colour)
    };
    let mut doc = doc
        .add(swatch(30.0, STONE))
        .add(text(54.0, y, 12.0, "masonry: intrados to extrados"))
        .add(line((260.0, y - 4.0), (284.0, y - 4.0), THRUST, 2.0))
        .add(text(290.0, y, 12.0, "thrust surface"))
        .add(
            Circle::new()
                .set("cx", 402.0)
                .set("cy", y - 4.0)
                .set("r", 4.0)
                .set("fill", "none")
                .set("stroke", "#1f77b4")
                .set("stroke-width", 1.5),
        )
        .add(text(412.0, y, 12.0, "touches a bound (hinge)"))
        .add(
            Polygon::new()
                .set(
                    "points",
                    format!(
                        "{},{} {},{} {},{}",
                        572.0,
                        y - 9.0,
                        566.0,
                        y + 1.0,
                        578.0,
                        y + 1.0
                    ),
                )
                .set("fill", "#111"),
        )
        .add(text(584.0, y, 12.0, "support"));
    if least {
        doc = doc.add(swatch(30.0, LEAST).set("y", y + 12.0)).add(text(
            54.0,
            y + 22.0,
            12.0,
            "at the least thickness",
        ));
    }
    doc.add(text(
        260.0,
        y + 22.0,
        12.0,
        format!("horizontal: {along}; vertical: z"),
    ))
    .add(draw::scale_bar(view, (700.0, y + 6.0), 150.0, "length"))
}
