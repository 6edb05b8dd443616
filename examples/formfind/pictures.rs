//! The SVG pictures: forces in plan, force diagram, residuals before/after, height change, and
//! a shaded 3-D view.

mod axonometric;
mod envelope;
pub mod section;

use svg::node::element::{Circle, Group, Polygon, Rectangle};
use svg::Document;
use voussoir::Mesh;

use crate::draw::{self, bbox, colour_bar, fmt, line, page, text, Bulk, View};
use crate::run::Outcome;

const WIDTH: f64 = 900.0;
const TOP: f64 = 70.0;
const LEGEND: f64 = 95.0;

fn plan(p: &[f64; 3]) -> [f64; 2] {
    [p[0], p[1]]
}

/// The top of a colour scale for `q`: its 98th percentile, so that a few heavily loaded edges
/// do not darken all the others, and tick labels (the top one "≥" when values exceed it).
fn q_scale(q: impl Iterator<Item = f64>) -> (f64, Vec<(f64, String)>) {
    let mut sorted: Vec<f64> = q.filter(|v| v.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    let max = sorted.last().copied().unwrap_or(0.0);
    let top = sorted
        .get((sorted.len() * 98 / 100).min(sorted.len().saturating_sub(1)))
        .copied()
        .unwrap_or(0.0);
    let top = if top > 0.0 { top } else { max };
    let last = if max > top * (1.0 + 1e-9) {
        format!("≥ {}", fmt(top))
    } else {
        fmt(top)
    };
    let ticks = vec![(0.0, "0".into()), (0.5, fmt(top / 2.0)), (1.0, last)];
    (top, ticks)
}

/// Referenced vertices' plan bounding box.
fn plan_box(mesh: &Mesh, positions: &[[f64; 3]]) -> ([f64; 2], [f64; 2]) {
    bbox(
        (0..mesh.n_vertices())
            .filter(|&v| mesh.referenced()[v])
            .map(|v| plan(&positions[v])),
    )
}

/// A page whose drawing area fits the box `lo`..`hi` into `columns` side-by-side panels.
fn layout(lo: [f64; 2], hi: [f64; 2], columns: usize) -> (f64, Vec<View>) {
    let gap = 20.0;
    let panel_w = (WIDTH - 40.0 - gap * (columns - 1) as f64) / columns as f64;
    let aspect = (hi[1] - lo[1]).max(1e-300) / (hi[0] - lo[0]).max(1e-300);
    let panel_h = (panel_w * aspect).clamp(200.0, 620.0);
    let views = (0..columns)
        .map(|c| {
            let x = 20.0 + c as f64 * (panel_w + gap);
            View::fit(lo, hi, [x, TOP + 24.0, panel_w, panel_h])
        })
        .collect();
    (TOP + 24.0 + panel_h + LEGEND, views)
}

fn polygon(view: &View, points: impl IntoIterator<Item = [f64; 2]>) -> Polygon {
    let pts: Vec<String> = points
        .into_iter()
        .map(|p| {
            let (x, y) = view.px(p);
            format!("{x:.2},{y:.2}")
        })
        .collect();
    Polygon::new().set("points", pts.join(" "))
}

/// Faces filled with `fill(face)`.
fn faces(mesh: &Mesh, pos: &[[f64; 3]], view: &View, fill: impl Fn(usize) -> String) -> Group {
    let mut g = Bulk::default();
    for (t, f) in mesh.faces().iter().enumerate() {
        let c = fill(t);
        g = g.add(
            polygon(view, f.map(|v| plan(&pos[v as usize])))
                .set("fill", c.clone())
                .set("stroke", c)
                .set("stroke-width", 0.4),
        );
    }
    g.into_group(Group::new())
}

/// Boundary loops (outer and holes).
fn outline(mesh: &Mesh, pos: &[[f64; 3]], view: &View) -> Group {
    let mut g = Group::new();
    for lp in mesh.loops() {
        g = g.add(
            polygon(view, lp.vertices.iter().map(|&v| plan(&pos[v as usize])))
                .set("fill", "none")
                .set("stroke", "#333")
                .set("stroke-width", 1.2),
        );
    }
    g
}

fn wireframe(mesh: &Mesh, pos: &[[f64; 3]], view: &View, colour: &str) -> Group {
    let mut g = Bulk::default();
    for e in mesh.edges() {
        let [a, b] = e.v.map(|v| view.px(plan(&pos[v as usize])));
        g = g.add(line(a, b, colour, 0.5));
    }
    g.into_group(Group::new())
}

/// Black squares at the anchored vertices.
fn anchors(mesh: &Mesh, pos: &[[f64; 3]], view: &View) -> Group {
    let mut g = Bulk::default();
    for v in (0..mesh.n_vertices()).filter(|&v| mesh.anchored()[v] && mesh.referenced()[v]) {
        let (x, y) = view.px(plan(&pos[v]));
        g = g.add(
            Rectangle::new()
                .set("x", x - 3.0)
                .set("y", y - 3.0)
                .set("width", 6.0)
                .set("height", 6.0)
                .set("fill", "#111"),
        );
    }
    g.into_group(Group::new())
}

fn anchor_key(x: f64, y: f64) -> Group {
    Group::new()
        .add(
            Rectangle::new()
                .set("x", x)
                .set("y", y - 8.0)
                .set("width", 6.0)
                .set("height", 6.0)
                .set("fill", "#111"),
        )
        .add(text(x + 12.0, y - 1.0, 12.0, "anchored (support)"))
}

/// (a) Edges coloured and sized by force density; supports and free vertices that need τ.
fn plan_forces(o: &Outcome) -> Document {
    let s = &o.stress;
    plan_forces_of(
        &o.model.name,
        o.model.mesh(),
        &o.positions,
        &s.force_densities,
        &s.tau,
    )
}

/// The forces in plan of model `name`: force densities `q` per edge, `tau` per vertex.
fn plan_forces_of(name: &str, mesh: &Mesh, pos: &[[f64; 3]], q: &[f64], tau: &[f64]) -> Document {
    let q_max = q.iter().copied().fold(0.0, f64::max);
    let (q_top, ticks) = q_scale(q.iter().copied());
    let (lo, hi) = plan_box(mesh, pos);
    let (height, views) = layout(lo, hi, 1);
    let view = &views[0];
    let mean = q.iter().sum::<f64>() / q.len().max(1) as f64;
    let mut doc = page(
        WIDTH,
        height,
        &format!("{name}: force densities in plan"),
        &format!(
            "compression per edge (force / length): max {}, mean {}; colour and width grow with q",
            fmt(q_max),
            fmt(mean)
        ),
    )
    .add(faces(mesh, pos, view, |_| "#f3efe6".into()));
    let mut order: Vec<usize> = (0..q.len()).collect();
    order.sort_by(|&a, &b| q[a].total_cmp(&q[b]));
    let mut edges = Bulk::default();
    for e in order {
        let [a, b] = mesh.edges()[e].v.map(|v| view.px(plan(&pos[v as usize])));
        let t = if q_top > 0.0 {
            (q[e] / q_top).min(1.0)
        } else {
            0.0
        };
        edges = edges.add(if t < 1e-6 {
            line(a, b, "#bbb", 0.6).set("stroke-dasharray", "3,2")
        } else {
            line(a, b, &draw::viridis(t), 0.6 + 4.4 * t).set("stroke-linecap", "round")
        });
    }
    doc = doc
        .add(edges.into_group(Group::new()))
        .add(anchors(mesh, pos, view));
    let tau_max = tau.iter().copied().fold(0.0, f64::max);
    let mut ties = Bulk::default();
    for v in (0..mesh.n_vertices()).filter(|&v| tau[v] > 1e-9 * tau_max.max(1e-300)) {
        let (x, y) = view.px(plan(&pos[v]));
        ties = ties.add(
            Circle::new()
                .set("cx", x)
                .set("cy", y)
                .set("r", 2.5 + 3.5 * tau[v] / tau_max)
                .set("fill", "none")
                .set("stroke", "#d62728")
                .set("stroke-width", 1.5),
        );
    }
    let y = height - LEGEND + 40.0;
    doc.add(ties.into_group(Group::new()))
        .add(colour_bar(
            "q",
            (30.0, y, 300.0),
            draw::viridis,
            "force density q",
            &ticks,
        ))
        .add(anchor_key(380.0, y + 4.0))
        .add(
            Circle::new()
                .set("cx", 383.0)
                .set("cy", y + 20.0)
                .set("r", 4.0)
                .set("fill", "none")
                .set("stroke", "#d62728")
                .set("stroke-width", 1.5),
        )
        .add(text(392.0, y + 24.0, 12.0, "τ > 0: free edge needs a tie"))
        .add(text(392.0, y + 40.0, 12.0, "dashed: q = 0").set("fill", "#777"))
        .add(draw::scale_bar(view, (640.0, y + 10.0), 200.0, "length"))
}

/// (b) The force diagram: one segment per interior edge, coloured by force density.
fn force_diagram(o: &Outcome) -> Document {
    let s = &o.stress;
    let q = &s.force_densities;
    let segments: Vec<(usize, [[f64; 2]; 2])> = s
        .force_diagram
        .segments
        .iter()
        .enumerate()
        .filter_map(|(e, seg)| seg.map(|seg| (e, seg)))
        .collect();
    // Boundary edges have no segment: scale colours to the interior edges drawn.
    let (q_top, ticks) = q_scale(segments.iter().map(|(e, _)| q[*e]));
    let (lo, hi) = bbox(segments.iter().flat_map(|(_, s)| *s));
    let (height, views) = layout(lo, hi, 1);
    let view = &views[0];
    let mut doc = page(
        WIDTH,
        height,
        &format!("{}: force diagram", o.model.name),
        "one point per face, one segment per interior edge (perpendicular to it); length = horizontal force q × plan length",
    );
    let mut g = Bulk::default();
    for (e, [a, b]) in segments {
        let t = if q_top > 0.0 {
            (q[e] / q_top).min(1.0)
        } else {
            0.0
        };
        g = g.add(
            line(view.px(a), view.px(b), &draw::viridis(t), 1.0).set("stroke-linecap", "round"),
        );
    }
    let y = height - LEGEND + 40.0;
    doc = doc.add(g.into_group(Group::new()));
    doc.add(colour_bar(
        "qd",
        (30.0, y, 300.0),
        draw::viridis,
        "force density q of the edge",
        &ticks,
    ))
    .add(draw::scale_bar(view, (640.0, y + 10.0), 200.0, "force"))
}

/// (c) |r_i| / p̄ per vertex on a log scale, before and after.
fn residuals(o: &Outcome) -> Document {
    let mesh = o.model.mesh();
    let tol = o.tolerance;
    let floor = (tol / 10.0).log10().floor();
    let mut panels = vec![("input", mesh.positions(), &o.before)];
    if o.termination.is_some() {
        panels.push(("form-found", o.positions.as_slice(), &o.stress));
    }
    // |r_i| over the mean load of the same stress step (loads follow the 3-D area).
    let rel: Vec<Vec<f64>> = panels
        .iter()
        .map(|(_, _, s)| {
            let mean = o.model.read.problem.mean_load(&s.loads);
            s.residuals.iter().map(|r| r.abs() / mean).collect()
        })
        .collect();
    let top = rel
        .iter()
        .flatten()
        .copied()
        .fold(0.0, f64::max)
        .log10()
        .ceil()
        .max(floor + 1.0);
    let (lo, hi) = plan_box(mesh, &o.positions);
    let (height, views) = layout(lo, hi, panels.len());
    let mut doc = page(
        WIDTH,
        height,
        &format!("{}: vertical residual per vertex", o.model.name),
        &format!(
            "|r_i| / mean load, log scale; tolerance {tol:e}; balanced vertices are pale and small"
        ),
    );
    for (((label, pos, s), rel), view) in panels.iter().zip(&rel).zip(&views) {
        let (x, _) = view.px(lo);
        let g = Group::new()
            .add(text(
                x,
                TOP + 14.0,
                14.0,
                format!("{label}: ε∞ = {:.2e}", s.eps_inf),
            ))
            .add(wireframe(mesh, pos, view, "#d8d8d8"))
            .add(outline(mesh, pos, view));
        let mut dots = Bulk::default();
        for v in (0..mesh.n_vertices()).filter(|&v| mesh.is_non_anchored(v)) {
            let t = ((rel[v].log10() - floor) / (top - floor)).max(0.0);
            let (cx, cy) = view.px(plan(&pos[v]));
            dots = dots.add(
                Circle::new()
                    .set("cx", cx)
                    .set("cy", cy)
                    .set("r", 1.5 + 3.5 * t)
                    .set("fill", draw::heat(t))
                    .set("stroke", "#555")
                    .set("stroke-width", 0.3),
            );
        }
        doc = doc.add(dots.into_group(g)).add(anchors(mesh, pos, view));
    }
    let y = height - LEGEND + 40.0;
    let decades = (top - floor) as usize;
    let step = decades.div_ceil(6).max(1);
    let ticks: Vec<(f64, String)> = (0..=decades)
        .step_by(step)
        .map(|k| {
            (
                k as f64 / decades as f64,
                format!("1e{}", floor as i64 + k as i64),
            )
        })
        .collect();
    let tx = 30.0 + 360.0 * (tol.log10() - floor) / (top - floor);
    doc.add(colour_bar(
        "r",
        (30.0, y, 360.0),
        draw::heat,
        "|r_i| / mean load (blue mark: tolerance)",
        &ticks,
    ))
    .add(line((tx, y - 3.0), (tx, y + 15.0), "#1f77b4", 2.0))
    .add(anchor_key(440.0, y + 4.0))
}

/// (d) Height change per face (mean of its vertices), blue down, red up.
fn height_change(o: &Outcome) -> Document {
    let mesh = o.model.mesh();
    let dz: Vec<f64> = (0..mesh.n_vertices())
        .map(|v| o.positions[v][2] - mesh.positions()[v][2])
        .collect();
    let m = dz.iter().fold(0.0f64, |a, d| a.max(d.abs()));
    let (lo, hi) = plan_box(mesh, &o.positions);
    let (height, views) = layout(lo, hi, 1);
    let view = &views[0];
    let doc = page(
        WIDTH,
        height,
        &format!("{}: height change", o.model.name),
        &format!(
            "form-found minus input height: max |Δz| = {} ({:.2}% of the plan diagonal), RMS {:.2}%",
            fmt(m),
            100.0 * o.hausdorff,
            100.0 * o.l2
        ),
    );
    let fill = |t: usize| {
        let mean = mesh.faces()[t].iter().map(|&v| dz[v as usize]).sum::<f64>() / 3.0;
        draw::diverging(if m > 0.0 { 0.5 + 0.5 * mean / m } else { 0.5 })
    };
    let y = height - LEGEND + 40.0;
    let ticks = vec![
        (0.0, fmt(-m)),
        (0.5, "0".to_string()),
        (1.0, format!("+{}", fmt(m))),
    ];
    doc.add(faces(mesh, &o.positions, view, fill))
        .add(wireframe(mesh, &o.positions, view, "rgba(0,0,0,0.12)"))
        .add(outline(mesh, &o.positions, view))
        .add(anchors(mesh, &o.positions, view))
        .add(colour_bar(
            "dz",
            (30.0, y, 300.0),
            draw::diverging,
            "Δz (down blue, up red)",
            &ticks,
        ))
        .add(anchor_key(380.0, y + 4.0))
        .add(draw::scale_bar(view, (640.0, y + 10.0), 200.0, "length"))
}

/// The file names of the pictures (no height change without form finding).
pub fn names(stress_only: bool) -> Vec<&'static str> {
    let mut names = vec!["plan_forces.svg", "force_diagram.svg", "residuals.svg"];
    if !stress_only {
        names.push("height_change.svg");
    }
    names.push("shape_3d.svg");
    names
}

/// The pictures of a run as (file name, SVG text), in the order of [`names`].
pub fn all(o: &Outcome) -> Vec<(&'static str, String)> {
    // One picture's element tree at a time.
    let mut out = vec![plan_forces(o).to_string()];
    out.push(force_diagram(o).to_string());
    out.push(residuals(o).to_string());
    if o.termination.is_some() {
        out.push(height_change(o).to_string());
    }
    out.push(axonometric::shape_3d(o).to_string());
    names(o.termination.is_none())
        .into_iter()
        .zip(out)
        .collect()
}

/// The file names of an assessment's pictures.
pub const ASSESSMENT: [&str; 3] = ["plan_forces.svg", "section.svg", "shape_3d.svg"];

/// The pictures of an assessment as (file name, SVG text), in the order of [`ASSESSMENT`].
pub fn assessment(
    a: &crate::assess::run::Assessed,
    at: crate::assess::args::Section,
) -> Vec<(&'static str, String)> {
    let r = &a.result;
    let no_tau = vec![0.0; r.positions.len()];
    // One picture's element tree at a time.
    let plan = plan_forces_of(
        &a.model.name,
        a.model.mesh(),
        &r.positions,
        &r.force_densities,
        &no_tau,
    )
    .to_string();
    let section = section::section(a, at).to_string();
    let out = [plan, section, envelope::shape_3d(a).to_string()];
    ASSESSMENT.into_iter().zip(out).collect()
}
