//! The inputs of an assessment read from the command line (the envelope, the live load
//! pattern, the settings) and the run itself.

use std::path::Path;

use serde_json::Value;
use voussoir::{assess, io, AssessResult, AssessSettings, Envelope, Objective};

use crate::args::Options;
use crate::model::Model;
use voussoir::io::UpAxis;

/// Everything an assessment produced, with its inputs.
pub struct Assessed {
    pub model: Model,
    pub envelope: Envelope,
    pub settings: AssessSettings,
    pub result: AssessResult,
    /// The uniform thickness of `--thickness`, if given.
    pub thickness: Option<f64>,
}

/// `voussoir::Error::InvalidArgument` of the envelope or settings in the command line's
/// words: `--thickness: …`, `--intrados: …`, `--load-pattern: …`.
pub fn message(e: &voussoir::Error, fallback: &str) -> String {
    match e {
        voussoir::Error::InvalidArgument { name, reason } => {
            let flag = match *name {
                "thickness" | "envelope" => "--thickness",
                "intrados" => "--intrados",
                "extrados" => "--extrados",
                "unit_weight" => "--unit-weight",
                "fixed_supports" => "--fixed-supports",
                "load_pattern" => "--load-pattern",
                "q_min" => "--qmin",
                "tolerance" => "--tol",
                "max_iterations" => "--max-iter",
                other => return format!("{other}: {reason}"),
            };
            format!("{flag}: {reason}")
        }
        other => format!("{fallback}: {other}"),
    }
}

type Surface = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// A mesh file of `--intrados` or `--extrados`, Z-up.
fn surface(flag: &str, path: &Path, up: UpAxis) -> Result<Surface, String> {
    let (positions, faces) = io::read_mesh(path).map_err(|e| format!("{flag}: {e}"))?;
    let positions = positions.into_iter().map(|p| up.to_z_up(p)).collect();
    Ok((positions, faces))
}

/// The envelope of `--thickness` or `--intrados` / `--extrados` over the model's plan.
pub fn envelope(model: &Model, o: &Options) -> Result<Envelope, String> {
    let a = &o.assess;
    if let Some(thickness) = crate::assess::args::thickness(o) {
        return Envelope::from_thickness(model.mesh(), &thickness)
            .map_err(|e| message(&e, "--thickness"));
    }
    let (Some(intrados), Some(extrados)) = (&a.intrados, &a.extrados) else {
        return Err("--assess needs --thickness T, or --intrados A --extrados B".into());
    };
    let lower = surface("--intrados", intrados, o.up)?;
    let upper = surface("--extrados", extrados, o.up)?;
    Envelope::from_surfaces(model.mesh(), (&lower.0, &lower.1), (&upper.0, &upper.1))
        .map_err(|e| message(&e, "--intrados"))
}

/// The loads of a JSON file: `[..]`, `{"loads": [..]}` (one per input vertex) or
/// `{"loads": {"ID": load, ..}}`, as (input vertex, load) pairs.
fn pattern_entries(text: &str, n_input: usize) -> Result<Vec<(usize, f64)>, String> {
    let json: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let loads = match &json {
        Value::Object(map) => map.get("loads").ok_or(
            "expected {\"loads\": [..]}, [..] or {\"loads\": {\"ID\": load, ..}}".to_string(),
        )?,
        other => other,
    };
    let number = |what: String, v: &Value| match v.as_f64() {
        Some(x) if x.is_finite() => Ok(x),
        _ => Err(format!("{what} is {v}, not a finite number")),
    };
    match loads {
        Value::Array(list) => {
            if list.len() != n_input {
                return Err(format!(
                    "has {} loads, expected one per vertex of MESH ({n_input}, ids before welding)",
                    list.len()
                ));
            }
            (list.iter().enumerate())
                .map(|(v, x)| Ok((v, number(format!("the load of vertex {v}"), x)?)))
                .collect()
        }
        Value::Object(map) => map
            .iter()
            .map(|(id, x)| {
                let v = id.trim().parse::<usize>().ok().filter(|&v| v < n_input);
                let v = v.ok_or(format!(
                    "`{id}` is not a vertex id of MESH (0 to {}, ids before welding)",
                    n_input.saturating_sub(1)
                ))?;
                Ok((v, number(format!("the load of vertex {v}"), x)?))
            })
            .collect(),
        _ => Err("expected {\"loads\": [..]}, [..] or {\"loads\": {\"ID\": load, ..}}".into()),
    }
}

/// `--load-pattern`: a load per mesh vertex; the loads of input vertices welded into one add.
pub fn load_pattern(model: &Model, path: &Path) -> Result<Vec<f64>, String> {
    let fail = |e: String| format!("--load-pattern: {}: {e}", path.display());
    let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
    let n = model.mesh().n_vertices();
    let welded = &model.read.welded_ids;
    let mut loads = vec![0.0; n];
    for (v, x) in pattern_entries(&text, welded.len()).map_err(fail)? {
        loads[welded[v] as usize] += x;
    }
    Ok(loads)
}

/// The settings of the command line: the assessment's defaults, changed by the options given.
pub fn settings(o: &Options, pattern: Option<Vec<f64>>) -> AssessSettings {
    let a = &o.assess;
    let given = |flag: &str| o.given.iter().any(|g| g == flag);
    let mut s = AssessSettings::default()
        .with_objective(a.objective.unwrap_or(Objective::Fit))
        .with_fixed_supports(a.fixed_supports)
        .with_unit_weight(a.unit_weight.unwrap_or(1.0))
        .with_load_rule(o.settings.stress.load_rule);
    if given("--tol") {
        s = s.with_tolerance(o.settings.tolerance);
    }
    if given("--max-iter") {
        s = s.with_max_iterations(o.settings.max_iterations);
    }
    if given("--qmin") {
        s = s.with_q_min(o.settings.stress.q_min);
    }
    if let Some(p) = pattern {
        s = s.with_load_pattern(p);
    }
    s
}

/// Runs the assessment (with a progress bar on a terminal).
pub fn run(
    model: Model,
    envelope: Envelope,
    settings: AssessSettings,
    o: &Options,
) -> Result<Assessed, voussoir::Error> {
    let problem = model.read.problem.clone();
    let bar = crate::run::progress_bar(settings.max_iterations, "assessment", "infeasibility");
    let mut report = |k: usize, infeasibility: f64| {
        if let Some(bar) = &bar {
            bar.set_position(k as u64);
            bar.set_message(format!("{infeasibility:.2e}"));
        }
        true
    };
    let result = assess(&problem, &envelope, &settings, Some(&mut report));
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let result = result?;
    let thickness = match crate::assess::args::thickness(o) {
        Some(voussoir::Thickness::Uniform(t)) => Some(t),
        _ => None,
    };
    Ok(Assessed {
        model,
        envelope,
        settings,
        result,
        thickness,
    })
}
