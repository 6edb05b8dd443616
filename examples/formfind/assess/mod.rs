//! `--assess`: a thrust surface inside the masonry's envelope (Heyman's safe theorem) instead
//! of form finding: the options, the run, the report and the summary. The pictures are in
//! `pictures/section.rs` and `pictures/envelope.rs`.

pub mod args;
pub mod report;
pub mod run;

use std::process::ExitCode;

use crate::{bad_input, failed, output, pictures, Failure, Outputs, Paths, NOT_CONVERGED};
use voussoir::{Objective, Termination};

/// Errors of the solver are about the input unless numerical; the envelope is the one of
/// `--intrados` and `--extrados` where they gave it.
fn solver_failure(e: voussoir::Error, o: &crate::args::Options) -> Failure {
    match e {
        voussoir::Error::Numerical { .. } | voussoir::Error::Io { .. } => failed(e),
        voussoir::Error::InvalidArgument {
            name: "envelope",
            reason,
        } if o.assess.intrados.is_some() => bad_input(format!("--intrados, --extrados: {reason}")),
        e => bad_input(run::message(&e, "--assess")),
    }
}

/// Reads the envelope and load pattern, checks the outputs, runs, writes everything.
pub fn main(o: &crate::args::Options, model: crate::model::Model) -> Result<ExitCode, Failure> {
    let section = o.assess.section.unwrap_or_default();
    pictures::section::check(model.mesh(), section).map_err(bad_input)?;
    let envelope = run::envelope(&model, o).map_err(bad_input)?;
    let pattern = (o.assess.load_pattern.as_ref())
        .map(|p| run::load_pattern(&model, p))
        .transpose()
        .map_err(bad_input)?;
    let settings = run::settings(o, pattern);
    settings
        .validate()
        .map_err(|e| bad_input(run::message(&e, "--assess")))?;
    let paths = Paths::of(o, &model.name, "thrust");
    output::check(
        &paths.targets(&pictures::ASSESSMENT),
        &crate::input_paths(o),
    )
    .map_err(bad_input)?;

    let a = run::run(model, envelope, settings, o).map_err(|e| solver_failure(e, o))?;
    let report = serde_json::to_value(report::build(o, &a)).map_err(failed)?;
    let pictures = pictures::assessment(&a, section);
    let outputs = Outputs {
        positions: &a.result.positions,
        solid: None,
        report: &report,
        pictures: &pictures,
    };
    crate::write_outputs(o, &paths, &a.model, &outputs)?;

    summary(&a);
    say!("wrote:");
    say!(
        "  {:<40} {}",
        paths.out.display(),
        "thrust surface (same faces)"
    );
    let hint = format!(
        "--assess {} --thickness 0.1 --section x",
        a.settings.objective.as_str()
    );
    crate::print_written(&paths, &pictures, &hint);
    let r = &a.result;
    let thicker = r.objective == Objective::MinThickness && r.thickness_scale > 1.0;
    if r.feasible && r.termination == Termination::Converged && !thicker {
        return Ok(ExitCode::SUCCESS);
    }
    let why = if r.feasible && thicker {
        format!(
            "the least thickness found is {:.4} times the given one (safety factor {:.4} < 1): \
             no thrust surface was found inside the vault as given",
            r.thickness_scale, r.safety_factor
        )
    } else if r.feasible {
        format!(
            "{}: the thrust surface written is certified, its {} not proven optimal",
            r.termination_message(),
            r.objective.as_str()
        )
    } else if let Termination::Infeasible { constraint } = &r.termination {
        format!(
            "no thrust surface exists in any envelope: relax {constraint}; the outputs hold \
             the middle surface without force"
        )
    } else {
        format!(
            "no thrust surface found inside the envelope ({}): the outputs hold the least \
             infeasible state",
            r.termination_message()
        )
    };
    eprintln!("formfind: {why}");
    Ok(ExitCode::from(NOT_CONVERGED))
}

fn summary(a: &run::Assessed) {
    crate::print_model(&a.model);
    let r = &a.result;
    say!(
        "assessment {}: {} after {} iterations, {:.2} s",
        r.objective.as_str(),
        r.termination.name().replace('_', " "),
        r.iterations,
        r.seconds
    );
    let (excess, vertex) = r.worst_bound;
    if r.feasible {
        let scaled = if r.thickness_scale == 1.0 {
            String::new()
        } else {
            format!(" at {:.6} times the thickness", r.thickness_scale)
        };
        say!(
            "a thrust surface fits{scaled}: ε∞ = {:.2e}, q ≥ 0, every height within its bounds",
            r.eps_inf
        );
    } else {
        let at = vertex.map_or(String::new(), |v| format!(" at vertex {v}"));
        say!(
            "no certified thrust surface: ε∞ = {:.2e}, largest excess over a bound {excess:.3e}{at}",
            r.eps_inf
        );
    }
    match r.objective {
        Objective::MinThickness if !r.feasible => say!(
            "no least thickness proven: the search ended at scale {:.6} of the envelope",
            r.thickness_scale
        ),
        Objective::MinThickness => {
            let t_min = a.thickness.map_or(String::new(), |t| {
                format!("least thickness {:.6e}, ", r.thickness_scale * t)
            });
            say!(
                "{t_min}scale {:.6} of the envelope; geometric safety factor {:.4}",
                r.thickness_scale,
                r.safety_factor
            );
        }
        Objective::MaxLoad => say!("load factor λ = {:.6e}", r.load_factor),
        _ => {}
    }
    if r.unbounded {
        let what = if r.objective == Objective::MaxLoad {
            "the load factor"
        } else {
            "the greatest thrust"
        };
        say!(
            "{what} has no bound: this surface's force densities scaled up by any factor \
             from some s0 on still fit"
        );
    }
    say!(
        "horizontal thrust (Σ |H| over the supports): {:.6e}",
        r.thrust_horizontal
    );
}
