//! The JSON report: every number a run computed, in physical units, plus the settings used.

use serde_json::{json, Value};
use voussoir::PlanRepair;
use voussoir::{QBound, StressResult, Termination};

use crate::args::{name_of, Options, LOADS, METHODS, QP_SOLVERS, SCOPES, SOLVERS, TAUS};
use crate::run::Outcome;

/// snake_case name of an enum variant from its `Debug` text (`Stalled { .. }` → `stalled`), so
/// variants added to the library later are reported without a change here.
pub fn variant_name(debug: &str) -> String {
    let head = debug
        .split(|c: char| !c.is_alphanumeric())
        .next()
        .unwrap_or("");
    let mut out = String::new();
    for (k, c) in head.chars().enumerate() {
        if c.is_uppercase() && k > 0 {
            out.push('_');
        }
        out.extend(c.to_lowercase());
    }
    out
}

/// The termination's name and its details (blocking vertices, constraint to relax, ...).
pub fn termination(outcome: &Outcome) -> (String, Value) {
    let Some(t) = &outcome.termination else {
        return ("stress_only".into(), Value::Null);
    };
    let detail = if let Termination::Stalled { vertices } = t {
        json!({ "vertices": vertices })
    } else if let Termination::Blocked { vertices, hint } = t {
        json!({ "vertices": vertices, "hint": hint })
    } else if let Termination::Infeasible { constraint } = t {
        json!({ "constraint": constraint })
    } else if let Termination::NumericalError { what } = t {
        json!({ "what": what })
    } else {
        Value::Null
    };
    (variant_name(&format!("{t:?}")), detail)
}

fn bound(b: QBound, unit: f64) -> Value {
    match b {
        QBound::Relative(v) => json!({ "relative": v, "physical": b.physical(unit) }),
        QBound::Absolute(v) => json!({ "absolute": v, "physical": v }),
        other => json!({ "bound": format!("{other:?}"), "physical": other.physical(unit) }),
    }
}

/// How the input was welded: the output mesh and every vertex id in this report are welded
/// ids, numbered in the order of their first input vertex.
pub fn weld(model: &crate::model::Model) -> Value {
    match &model.weld {
        None => Value::Null,
        Some(w) => json!({
            "input_vertices": w.input_vertices,
            "merged": w.merged,
            "relative_tolerance": w.relative_tolerance,
            "tolerance": w.tolerance,
            "collapsed_faces": w.collapsed_faces,
            "vertex_order": "welded vertices are numbered in the order of their first input vertex",
        }),
    }
}

/// One plan repair as JSON: a flip (faces, removed and added edge) or a nudge (vertex, face,
/// plan position before and after).
pub fn repair(r: &PlanRepair) -> Value {
    match r {
        PlanRepair::Flip {
            faces,
            removed,
            added,
        } => json!({ "flip": { "faces": faces, "removed": removed, "added": added } }),
        PlanRepair::Nudge {
            vertex,
            face,
            from,
            to,
        } => json!({ "nudge": { "vertex": vertex, "face": face, "from": from, "to": to } }),
        other => json!({ "other": other.to_string() }),
    }
}

fn settings(o: &Options, outcome: &Outcome) -> Value {
    let s = &o.settings;
    let st = &s.stress;
    json!({
        "mesh": outcome.model.source,
        "supports": outcome.model.supports,
        "weld": weld(&outcome.model),
        "strict": o.strict,
        "up": if o.up == voussoir::io::UpAxis::Y { "y" } else { "z" },
        "polygon_diagonals": outcome.model.diagonals.len(),
        "stress_only": o.stress_only,
        "solver": name_of(&SOLVERS, st.formulation),
        "qp_solver": name_of(&QP_SOLVERS, st.solver),
        "tolerance": s.tolerance,
        "max_iterations": s.max_iterations,
        "method": name_of(&METHODS, s.method),
        "fairness": s.fairness,
        "max_height_change": s.max_height_change,
        "stall_window": s.stall_window,
        "proximal_weight": s.proximal_weight,
        "q_min": bound(st.q_min, outcome.q_unit),
        "q_min_scope": name_of(&SCOPES, st.q_min_scope),
        "q_max": st.q_max.map_or(Value::Null, |b| bound(b, outcome.q_unit)),
        "q_unit": outcome.q_unit,
        "q_unit_note": "relative bounds are multiples of q_unit = mean load / L0 (half the plan diagonal), at the final shape",
        "tau": name_of(&TAUS, st.tau),
        "dual_length_smoothing": st.dual_length_smoothing,
        "smoothing_decay": s.smoothing_decay,
        "holes": variant_name(&format!("{:?}", st.holes)),
        "load": name_of(&LOADS, st.load_rule),
        "density": o.density,
        "regularisation": st.regularisation,
        "regularisation_used": outcome.stress.regularisation,
        "odt": o.odt,
        "schedule": {
            "mu0": s.schedule.mu0,
            "beta": s.schedule.beta,
            "mu_min": s.schedule.mu_min,
            "eta": s.schedule.eta,
            "pull": s.schedule.pull,
        },
        // Every field, including any this program does not know by name.
        "debug": format!("{s:?}"),
    })
}

/// `[[v, x, y], ...]` for the vertices where `f` is non-zero.
fn sparse_pairs(f: &[[f64; 2]]) -> Value {
    f.iter()
        .enumerate()
        .filter(|(_, f)| f[0] != 0.0 || f[1] != 0.0)
        .map(|(v, f)| json!([v, f[0], f[1]]))
        .collect()
}

pub fn build(o: &Options, outcome: &Outcome) -> Value {
    let mesh = &outcome.model.mesh;
    let s: &StressResult = &outcome.stress;
    let (name, detail) = termination(outcome);
    let anchored: Vec<usize> = (0..mesh.n_vertices())
        .filter(|&v| mesh.anchored[v])
        .collect();
    json!({
        "termination": name,
        "termination_detail": detail,
        "stress_status": variant_name(&format!("{:?}", s.status)),
        // The QP solver that produced the final forces (clarabel after a fallback).
        "qp_solver_used": name_of(&QP_SOLVERS, s.solver),
        "iterations": outcome.iterations,
        // Per stress step: clarabel where asked for or where the native method did not converge.
        "step_solvers": outcome.solvers.iter().map(|&q| name_of(&QP_SOLVERS, q)).collect::<Vec<_>>(),
        "eps_inf": s.eps_inf,
        "history": outcome.history,
        "edges": mesh.edges.iter().map(|e| e.v).collect::<Vec<_>>(),
        // `+ 0.0` turns -0.0 (edges without force) into 0.
        "force_densities": s.force_densities.iter().map(|q| q + 0.0).collect::<Vec<_>>(),
        "loads": s.loads,
        "external_horizontal": sparse_pairs(&s.external_horizontal),
        "tau": s.tau,
        "weights": s.weights,
        "airy": s.airy,
        "hole_coefficients": s.hole_coefficients,
        "residuals": s.residuals,
        "objective": s.objective,
        "hausdorff": outcome.hausdorff,
        "l2": outcome.l2,
        "rms_change": outcome.rms_change,
        "max_change": outcome.max_change,
        "timings_s": {
            "stress": outcome.stress_seconds,
            "shape": outcome.shape_seconds,
            "total": outcome.total_seconds,
        },
        "mesh": {
            "vertices": mesh.n_vertices(),
            "faces": mesh.n_faces(),
            "edges": mesh.n_edges(),
            "holes": mesh.holes().count(),
        },
        "anchored": anchored,
        "plan_repairs": outcome.model.repairs.iter().map(repair).collect::<Vec<_>>(),
        "unreferenced": mesh.unreferenced,
        "units": "input units: lengths as in the OBJ, loads = density x area, force densities = force / length",
        "settings": settings(o, outcome),
        "voussoir_version": env!("CARGO_PKG_VERSION"),
    })
}

/// The printable solid of `--solid`: the thickness asked for, its size, volume and the range
/// of the distances between the upper and lower copies of a vertex.
pub fn solid(solid: &voussoir::Solid, outcome: &Outcome, o: &Options) -> Value {
    let t = &solid.vertex_thickness;
    let area: f64 = outcome
        .model
        .mesh
        .faces
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
