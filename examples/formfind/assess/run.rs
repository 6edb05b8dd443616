//! The inputs of an assessment read from the command line (the envelope, the live load
//! pattern, the settings) and the run itself.

use std::path::Path;

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
                "springing" => "--springing",
                "reach" => "--reach",
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

/// A mesh file of `--intrados` or `--extrados`, Z-up.
fn surface(flag: &str, path: &Path, up: UpAxis) -> Result<io::RawMesh, String> {
    io::read_surface(path, up).map_err(|e| format!("{flag}: {e}"))
}

/// The envelope of `--thickness` or `--intrados` / `--extrados` over the model's plan, with
/// the springing joint of `--springing` and `--reach` at the supports.
pub fn envelope(model: &Model, o: &Options) -> Result<Envelope, String> {
    let envelope = bounds(model, o)?;
    let a = &o.assess;
    if a.springing.is_none() && a.reach.is_none() {
        return Ok(envelope);
    }
    envelope
        .with_joint_at_supports(model.mesh(), a.springing, a.reach)
        .map_err(|e| message(&e, "--springing"))
}

/// The envelope of `--thickness` or `--intrados` / `--extrados` over the model's plan.
fn bounds(model: &Model, o: &Options) -> Result<Envelope, String> {
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

/// `--load-pattern`: a load per mesh vertex; the loads of input vertices welded into one add.
pub fn load_pattern(model: &Model, path: &Path) -> Result<Vec<f64>, String> {
    let n = model.mesh().n_vertices();
    io::read_load_pattern(path, &model.read.welded_ids, n)
        .map_err(|e| message(&e, "--load-pattern"))
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
