//! Runs the solver on a model: form finding (with a progress bar on a terminal) or a single
//! stress analysis, plus a stress analysis of the input for the "before" picture.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};
use voussoir::report::{Report, Run};
use voussoir::{analyse, form_find, FormFindResult, StressResult, Termination};

use crate::args::Options;
use crate::model::Model;

/// Everything a run produced.
pub struct Outcome {
    pub model: Model,
    /// The form finding (None for `--stress-only`).
    pub found: Option<FormFindResult>,
    /// None for `--stress-only`.
    pub termination: Option<Termination>,
    pub positions: Vec<[f64; 3]>,
    /// The forces the run ended with, at `positions` (see `FormFindResult::stress`).
    pub stress: StressResult,
    /// Stress analysis of the input shape.
    pub before: StressResult,
    /// Stress steps taken.
    pub iterations: usize,
    pub hausdorff: f64,
    pub l2: f64,
    /// Area-weighted RMS and largest height change over the plan diagonal.
    pub rms_change: f64,
    pub max_change: f64,
    pub stress_seconds: f64,
    pub shape_seconds: f64,
    pub total_seconds: f64,
    /// The stopping tolerance used.
    pub tolerance: f64,
}

impl Outcome {
    /// Converged form finding, or a solved stress analysis with `--stress-only`.
    pub fn succeeded(&self) -> bool {
        match &self.termination {
            Some(t) => *t == Termination::Converged,
            None => self.stress.status.is_solved(),
        }
    }

    /// The library's report of the run (its settings section names the supports as the
    /// model does).
    pub fn report(&self, settings: &voussoir::FormFindSettings) -> Report {
        let run = match &self.found {
            Some(found) => Run::FormFinding(found),
            None => Run::Analysis(&self.before),
        };
        let mut report = Report::new(&self.model.read, settings, run);
        report.settings.read.supports = self.model.supports.clone();
        report
    }
}

/// A progress bar on a terminal: `what` is the run ("form finding"), `figure` the number
/// shown per iteration ("ε∞").
pub fn progress_bar(max_iterations: usize, what: &str, figure: &str) -> Option<ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::new(max_iterations as u64);
    let style = ProgressStyle::with_template(&format!(
        "{{spinner}} {what} [{{bar:30}}] iteration {{pos}}/{{len}}  {figure} {{msg}}  {{elapsed}}"
    ))
    .expect("valid template")
    .progress_chars("=> ");
    bar.set_style(style);
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    Some(bar)
}

pub fn run(mut model: Model, o: &Options) -> voussoir::Result<Outcome> {
    let density = vec![o.density; model.mesh().n_faces()];
    model.read.problem = model.read.problem.clone().with_face_density(density)?;
    let problem = &model.read.problem;
    let settings = &o.settings;
    let before = analyse(problem, &settings.stress)?;
    if o.stress_only {
        return Ok(Outcome {
            found: None,
            termination: None,
            positions: problem.mesh.positions().to_vec(),
            stress: before.clone(),
            iterations: 1,
            hausdorff: 0.0,
            l2: 0.0,
            rms_change: 0.0,
            max_change: 0.0,
            stress_seconds: before.seconds,
            shape_seconds: 0.0,
            total_seconds: before.seconds,
            before,
            tolerance: settings.tolerance,
            model,
        });
    }
    let bar = progress_bar(settings.max_iterations, "form finding", "ε∞");
    let mut report = |k: usize, eps: f64| {
        if let Some(bar) = &bar {
            bar.set_position(k as u64 + 1);
            bar.set_message(format!("{eps:.2e}"));
        }
        true
    };
    let result = form_find(problem, settings, Some(&mut report));
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let r = result?;
    Ok(Outcome {
        termination: Some(r.termination.clone()),
        positions: r.positions.clone(),
        stress: r.stress.clone(),
        before,
        iterations: r.iterations,
        hausdorff: r.hausdorff,
        l2: r.l2,
        rms_change: r.rms_change,
        max_change: r.max_change,
        stress_seconds: r.stress_seconds,
        shape_seconds: r.shape_seconds,
        total_seconds: r.total_seconds,
        tolerance: settings.tolerance,
        found: Some(r),
        model,
    })
}
