//! The JSON report of an assessment: the `"assessment"` figures and certificate, the thrust
//! surface's forces, and the settings used.

use serde_json::{json, Value};
use voussoir::QBound;

use super::run::Assessed;
use crate::args::Options;

/// The termination's name and its details (as form finding's).
pub fn termination(t: &voussoir::Termination) -> (String, Value) {
    let detail = match t {
        voussoir::Termination::Stalled { vertices } => json!({ "vertices": vertices }),
        voussoir::Termination::NumericalError { what } => json!({ "what": what }),
        voussoir::Termination::Infeasible { constraint } => json!({ "constraint": constraint }),
        _ => Value::Null,
    };
    (t.name().to_string(), detail)
}

/// `[[v, x, y], ...]` for the vertices where `f` is non-zero.
fn sparse_pairs(f: &[[f64; 2]]) -> Value {
    (f.iter().enumerate())
        .filter(|(_, f)| f[0] != 0.0 || f[1] != 0.0)
        .map(|(v, f)| json!([v, f[0], f[1]]))
        .collect()
}

/// The figures of the analysis: what it found, at which thickness, and its certificate.
pub fn assessment(a: &Assessed) -> Value {
    let r = &a.result;
    let (name, detail) = termination(&r.termination);
    let (worst, worst_vertex) = r.worst_bound;
    json!({
        "objective": r.objective.as_str(),
        "feasible": r.feasible,
        "termination": name,
        "termination_detail": detail,
        "iterations": r.iterations,
        "seconds": r.seconds,
        "thickness": a.thickness,
        // The thickness of `bounds`: the least one for min-thickness.
        "thickness_min": a.thickness.map(|t| r.thickness_scale * t),
        "thickness_scale": r.thickness_scale,
        "safety_factor": r.safety_factor,
        "thrust_horizontal": r.thrust_horizontal,
        "load_factor": r.load_factor,
        "eps_inf": r.eps_inf,
        "horizontal_imbalance": r.horizontal_imbalance,
        "worst_bound": { "excess": worst, "vertex": worst_vertex },
        "worst_residual_vertex": r.worst_residual_vertex,
        "bounds": { "lower": r.lower, "upper": r.upper },
        "envelope": {
            "lower": a.envelope.lower,
            "upper": a.envelope.upper,
            "middle": a.envelope.middle,
            "face_thickness": a.envelope.face_thickness,
        },
        "reactions": sparse_pairs(&r.reactions),
        "load_pattern": a.settings.load_pattern,
    })
}

fn bound(b: QBound) -> Value {
    match b {
        QBound::Relative(v) => json!({ "relative": v }),
        QBound::Absolute(v) => json!({ "absolute": v }),
        other => json!({ "bound": format!("{other:?}") }),
    }
}

fn settings(o: &Options, a: &Assessed) -> Value {
    let s = &a.settings;
    let opts = &o.assess;
    let path = |p: &Option<std::path::PathBuf>| p.as_ref().map(|p| p.display().to_string());
    json!({
        "mesh": a.model.read.source,
        "supports": a.model.supports,
        "weld": a.model.read.weld,
        "strict": o.strict,
        "up": o.up,
        "polygon_diagonals": a.model.read.diagonals.len(),
        "objective": s.objective.as_str(),
        "thickness": match opts.thickness {
            Some(crate::args::SolidThickness::Uniform(t)) => json!(t),
            Some(crate::args::SolidThickness::FromDensity) => json!({ "density": o.density }),
            None => Value::Null,
        },
        "intrados": path(&opts.intrados),
        "extrados": path(&opts.extrados),
        "unit_weight": s.unit_weight,
        "fixed_supports": s.fixed_supports,
        "load_pattern": path(&opts.load_pattern),
        "load_rule": s.load_rule,
        "q_min": bound(s.q_min),
        "tolerance": s.tolerance,
        "max_iterations": s.max_iterations,
        "debug": format!("{s:?}"),
    })
}

pub fn build(o: &Options, a: &Assessed) -> Value {
    let mesh = a.model.mesh();
    let r = &a.result;
    let anchored: Vec<usize> = (0..mesh.n_vertices())
        .filter(|&v| mesh.anchored[v])
        .collect();
    json!({
        "assessment": assessment(a),
        "edges": mesh.edges.iter().map(|e| e.v).collect::<Vec<_>>(),
        // `+ 0.0` turns -0.0 (edges without force) into 0.
        "force_densities": r.force_densities.iter().map(|q| q + 0.0).collect::<Vec<_>>(),
        "loads": r.loads,
        "residuals": r.residuals,
        "mesh": {
            "vertices": mesh.n_vertices(),
            "faces": mesh.n_faces(),
            "edges": mesh.n_edges(),
            "holes": mesh.holes().count(),
        },
        "anchored": anchored,
        "plan_repairs": a.model.read.repairs,
        "unreferenced": mesh.unreferenced,
        "units": "input units: lengths as in the mesh, loads = unit weight x thickness x area (plus the load factor x the load pattern), force densities = force / length",
        "settings": settings(o, a),
        "voussoir_version": env!("CARGO_PKG_VERSION"),
    })
}
