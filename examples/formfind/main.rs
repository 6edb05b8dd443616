//! `formfind`: the nearest self-supporting shape to a vault, from the command line.
//!
//! ```sh
//! cargo run --release --example formfind                       # the embedded default vault
//! cargo run --release --example formfind -- MESH --supports S.json [options]
//! cargo run --release --example formfind -- --help             # every option and default
//! ```
//!
//! Reads OBJ, OFF, STL or PLY; writes the form-found mesh (in the format of `--out`), a JSON
//! report and SVG pictures, all or nothing: bad input or output paths get a one-line message
//! on stderr, a non-zero exit status and no output files, and existing files are replaced only
//! when every output is written.

/// `println!` that ignores a closed stdout (as in `formfind | head`) instead of panicking.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

mod args;
mod assess;
mod draw;
mod model;
mod output;
mod pictures;
mod report;
mod run;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use serde_json::Value;

/// Exit status for bad input or options.
const BAD_INPUT: u8 = 2;
/// Exit status when the outputs were written but form finding did not converge.
const NOT_CONVERGED: u8 = 3;
/// Folder of the default output paths.
const OUT_DIR: &str = "formfind-out";

struct Failure {
    code: u8,
    message: String,
}

fn bad_input(message: impl ToString) -> Failure {
    Failure {
        code: BAD_INPUT,
        message: message.to_string(),
    }
}

fn failed(message: impl ToString) -> Failure {
    Failure {
        code: 1,
        message: message.to_string(),
    }
}

/// Errors of the solver are about the input (mesh, supports, settings) unless numerical.
fn solver_failure(e: voussoir::Error) -> Failure {
    match e {
        voussoir::Error::Numerical { .. } | voussoir::Error::Io { .. } => failed(e),
        _ => bad_input(e),
    }
}

fn main() -> ExitCode {
    match formfind() {
        Ok(code) => code,
        Err(f) => {
            let one_line: Vec<&str> = f.message.split_whitespace().collect();
            eprintln!("formfind: error: {}", one_line.join(" "));
            ExitCode::from(f.code)
        }
    }
}

/// Where a run writes.
struct Paths {
    out: PathBuf,
    report: PathBuf,
    pictures: PathBuf,
    /// `--solid`'s output.
    solid: Option<PathBuf>,
    /// Where the embedded input and its supports are copied (without MESH.obj).
    input_copy: Option<(PathBuf, PathBuf)>,
}

impl Paths {
    /// The paths of a run on the model `name`; OUT defaults to `NAME-SUFFIX.obj`.
    fn of(o: &args::Options, name: &str, suffix: &str) -> Paths {
        let dir = PathBuf::from(OUT_DIR);
        let out = (o.out.clone()).unwrap_or_else(|| dir.join(format!("{name}-{suffix}.obj")));
        let input_copy = o.mesh.is_none().then(|| {
            let base = out.parent().unwrap_or(Path::new(""));
            (
                base.join(format!("{name}-input.obj")),
                base.join(format!("{name}-supports.json")),
            )
        });
        Paths {
            report: o.report.clone().unwrap_or_else(|| dir.join("report.json")),
            pictures: o.pictures.clone().unwrap_or_else(|| dir.join("pictures")),
            solid: o.solid.as_ref().map(|(_, path)| path.clone()),
            out,
            input_copy,
        }
    }

    /// Every file a run writes, with the option that names it; `pictures` are file names.
    fn targets(&self, pictures: &[&str]) -> Vec<output::Target> {
        let target = |option: &str, path: &Path| output::Target {
            option: option.into(),
            path: path.to_path_buf(),
        };
        let mut targets = vec![target("--out", &self.out), target("--report", &self.report)];
        if let Some(solid) = &self.solid {
            targets.push(target("--solid", solid));
        }
        for file in pictures {
            targets.push(target("--pictures", &self.pictures.join(file)));
        }
        if let Some((obj, json)) = &self.input_copy {
            targets.push(target("the embedded input's copy (beside --out)", obj));
            targets.push(target("the embedded input's supports (beside --out)", json));
        }
        targets
    }
}

fn formfind() -> Result<ExitCode, Failure> {
    let o = match args::parse(std::env::args_os().skip(1)).map_err(bad_input)? {
        args::Parsed::Help => {
            say!("{}", args::help().trim_end());
            return Ok(ExitCode::SUCCESS);
        }
        args::Parsed::Run(o) => *o,
    };
    let model = match &o.mesh {
        None => model::embedded_default(),
        Some(path) => model::from_files(path, &o).map_err(bad_input)?,
    };
    if o.assess.objective.is_some() {
        return assess::main(&o, model);
    }
    let paths = Paths::of(&o, &model.name, "formfound");
    output::check(
        &paths.targets(&pictures::names(o.stress_only)),
        &input_paths(&o),
    )
    .map_err(bad_input)?;

    let outcome = run::run(model, &o).map_err(solver_failure)?;
    let mut report = serde_json::to_value(outcome.report(&o.settings)).map_err(failed)?;
    let solid = match o.thickness() {
        Some(thickness) => {
            let solid = voussoir::thicken(outcome.model.mesh(), &outcome.positions, &thickness)
                .map_err(|e| bad_input(format!("--solid: {}", reason(&e))))?;
            report["solid"] = report::solid(&solid, &outcome, &o);
            Some(solid)
        }
        None => None,
    };
    let pictures = pictures::all(&outcome);
    let outputs = Outputs {
        positions: &outcome.positions,
        solid: solid.as_ref(),
        report: &report,
        pictures: &pictures,
    };
    write_outputs(&o, &paths, &outcome.model, &outputs)?;

    print_summary(&outcome, &report);
    say!("wrote:");
    say!(
        "  {:<40} {}",
        paths.out.display(),
        "form-found mesh (same faces)"
    );
    if let (Some(solid), Some(path)) = (&solid, &paths.solid) {
        say!(
            "  {:<40} printable solid: {} faces, volume {:.6e}",
            path.display(),
            solid.faces.len(),
            solid.volume()
        );
    }
    print_written(&paths, &pictures, "--tau zero");
    if outcome.succeeded() {
        Ok(ExitCode::SUCCESS)
    } else {
        let why = match outcome.termination {
            Some(_) => format!("not converged ({})", phrase(&report["termination"])),
            None => format!("stress analysis {}", phrase(&report["stress_status"])),
        };
        eprintln!("formfind: {why}: the outputs hold the best state reached");
        Ok(ExitCode::from(NOT_CONVERGED))
    }
}

/// What a run writes besides the embedded input's copy.
struct Outputs<'a> {
    /// OUT's positions (Z-up).
    positions: &'a [[f64; 3]],
    solid: Option<&'a voussoir::Solid>,
    report: &'a Value,
    pictures: &'a [(&'static str, String)],
}

/// Writes every output (all or nothing): OUT and the solid in the input's axes, the report,
/// the pictures and, for the embedded input, its copy and supports.
fn write_outputs(
    o: &args::Options,
    paths: &Paths,
    model: &model::Model,
    outputs: &Outputs,
) -> Result<(), Failure> {
    // Nothing is on disk before this point; the staging writes all files or none.
    let mut staging = output::Staging::default();
    let mesh = model.mesh();
    // Written meshes keep the input's axes.
    let axes_of_input = |positions: &[[f64; 3]]| -> Vec<[f64; 3]> {
        positions.iter().map(|&p| o.up.to_file(p)).collect()
    };
    staging
        .write_mesh(
            &paths.out,
            &axes_of_input(outputs.positions),
            &model.faces,
            o.ascii,
        )
        .map_err(failed)?;
    if let (Some(solid), Some(path)) = (outputs.solid, &paths.solid) {
        staging
            .write_mesh(
                path,
                &axes_of_input(&solid.positions),
                &solid.faces,
                o.ascii,
            )
            .map_err(failed)?;
    }
    staging
        .write(
            &paths.report,
            voussoir::report::json_text(outputs.report).as_bytes(),
        )
        .map_err(failed)?;
    for (file, svg) in outputs.pictures {
        staging
            .write(&paths.pictures.join(file), svg.as_bytes())
            .map_err(failed)?;
    }
    if let Some((obj, json)) = &paths.input_copy {
        let anchored: Vec<usize> = (0..mesh.n_vertices())
            .filter(|&v| mesh.anchored()[v])
            .collect();
        let supports = serde_json::json!({ "anchored": anchored }).to_string() + "\n";
        staging
            .write_obj(obj, mesh.positions(), &model.faces)
            .map_err(failed)?;
        staging.write(json, supports.as_bytes()).map_err(failed)?;
    }
    staging.commit().map_err(failed)
}

/// The lines of the summary after OUT's: the report, the pictures, the embedded input.
/// `options` are those the hint suggests to try on the embedded input.
fn print_written(paths: &Paths, pictures: &[(&str, String)], options: &str) {
    say!("  {:<40} {}", paths.report.display(), "report (JSON)");
    let names: Vec<&str> = pictures.iter().map(|(n, _)| *n).collect();
    say!(
        "  {:<40} {}",
        format!("{}/", paths.pictures.display()),
        names.join(" ")
    );
    if let Some((obj, json)) = &paths.input_copy {
        say!(
            "  {:<40} {}",
            obj.display(),
            "the embedded input, with its supports in"
        );
        say!("  {:<40}", json.display());
        say!(
            "try your own options on it, e.g.:\n  cargo run --release --example formfind -- {} --supports {} {options}",
            obj.display(),
            json.display()
        );
    }
}

/// A library error in words for an option's message: an invalid argument's reason alone
/// (its `invalid argument `name`` prefix names a library parameter, not the option).
fn reason(e: &voussoir::Error) -> String {
    match e {
        voussoir::Error::InvalidArgument { reason, .. } => reason.clone(),
        other => other.to_string(),
    }
}

/// A report's status name in words: `max_iterations` → "stopped at --max-iter".
fn phrase(name: &Value) -> String {
    match name.as_str().unwrap_or("?") {
        "max_iterations" => "stopped at --max-iter".into(),
        other => other.replace('_', " "),
    }
}

/// `n` and the noun, singular for 1: "1 hole", "2 holes".
fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// The input files an output may not overwrite, with the option that names each.
pub fn input_paths(o: &args::Options) -> Vec<(&'static str, &Path)> {
    let mut inputs: Vec<(&'static str, &Path)> = Vec::new();
    if let Some(mesh) = &o.mesh {
        inputs.push(("MESH", mesh));
    }
    if let Some(supports) = &o.supports {
        inputs.push(("--supports", supports));
    }
    inputs
}

/// The lines about the input: sizes, welding, plan repairs.
fn print_model(m: &model::Model) {
    let mesh = m.mesh();
    say!(
        "{} ({}): {}, {}, {}, {}, {} anchored",
        m.name,
        m.read.source,
        count(mesh.n_vertices(), "vertex", "vertices"),
        count(mesh.n_faces(), "face", "faces"),
        count(mesh.n_edges(), "edge", "edges"),
        count(mesh.holes().count(), "hole", "holes"),
        mesh.anchored().iter().filter(|a| **a).count()
    );
    if let Some(w) = m.read.weld.as_ref().filter(|w| w.merged > 0) {
        say!(
            "welded: {} of {} input vertices merged (closer than {:.3e}), {} collapsed",
            w.merged,
            w.input_vertices,
            w.tolerance,
            count(w.collapsed_faces.len(), "face", "faces")
        );
    }
    let repairs = &m.read.repairs;
    if !repairs.is_empty() {
        let flips = repairs
            .iter()
            .filter(|r| matches!(r, voussoir::PlanRepair::Flip { .. }))
            .count();
        say!(
            "plan repaired: {}, {} (listed in the report; --strict rejects instead)",
            count(flips, "edge flip", "edge flips"),
            count(repairs.len() - flips, "vertex nudge", "vertex nudges")
        );
    }
}

/// Why a state balanced vertically is not a converged answer (docs/method.md §13.1).
fn uncertified(report: &Value, outcome: &run::Outcome) -> String {
    match report["horizontal_imbalance"].as_f64() {
        Some(h) if h < outcome.tolerance => "its forces fall outside their bounds, or its QP \
            stopped short of the optimum"
            .into(),
        Some(h) => format!("its horizontal imbalance is {h:.2e} of the mean load"),
        None => "its horizontal imbalance is not a number".into(),
    }
}

fn print_summary(outcome: &run::Outcome, report: &Value) {
    print_model(&outcome.model);
    let s = &outcome.stress;
    match &outcome.termination {
        None => say!(
            "stress only ({}): ε∞ = {:.2e} (max |r_i| / mean load; below {:e} counts as balanced)",
            phrase(&report["stress_status"]),
            s.eps_inf,
            outcome.tolerance
        ),
        Some(_) => {
            say!(
                "{} after {} iterations: ε∞ = {:.2e} (tolerance {:e}), from {:.2e} at the input",
                phrase(&report["termination"]),
                outcome.iterations,
                s.eps_inf,
                outcome.tolerance,
                outcome.before.eps_inf
            );
            let ended = report["termination"].as_str().unwrap_or("");
            if !matches!(ended, "converged" | "cancelled") && s.eps_inf < outcome.tolerance {
                say!(
                    "  balanced vertically but not certified: {}",
                    uncertified(report, outcome)
                );
            }
            // A stall with no vertex to name has nothing to add to its own line.
            let vertices = &report["termination_vertices"];
            if vertices.as_array().is_some_and(|v| !v.is_empty()) {
                say!("  vertices: {vertices}");
            }
            if let Some(detail) = report["termination_detail"].as_str() {
                say!("  details: {detail}");
            }
            say!(
                "height change: max {:.3}%, area-weighted RMS {:.3}% of the plan diagonal; \
                 surface distance: Hausdorff {:.3}%, L2 {:.3}%",
                100.0 * outcome.max_change,
                100.0 * outcome.rms_change,
                100.0 * outcome.hausdorff,
                100.0 * outcome.l2
            );
        }
    }
    let tied = s.tau.iter().filter(|t| **t > 0.0).count();
    if tied > 0 {
        say!(
            "{} a tie or buttress (τ > 0; see the report)",
            match tied {
                1 => "1 free boundary vertex needs".to_string(),
                n => format!("{n} free boundary vertices need"),
            }
        );
    }
    say!(
        "time: stress {:.2} s, shape {:.2} s, total {:.2} s",
        outcome.stress_seconds,
        outcome.shape_seconds,
        outcome.total_seconds
    );
}
