//! Runs the solver on a model: form finding (with a progress bar on a terminal) or a single
//! stress analysis, plus a stress analysis of the input for the "before" picture.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};
use voussoir::{analyse, form_find, Problem, QpSolver, StressResult, Termination};

use crate::args::Options;
use crate::model::Model;

/// Everything a run produced.
pub struct Outcome {
    pub model: Model,
    /// None for `--stress-only`.
    pub termination: Option<Termination>,
    pub positions: Vec<[f64; 3]>,
    /// The forces the run ended with, at `positions` (see `FormFindResult::stress`).
    pub stress: StressResult,
    /// Stress analysis of the input shape.
    pub before: StressResult,
    /// ε∞ per stress step (plus the final certificate, see `FormFindResult::history`).
    pub history: Vec<f64>,
    /// Stress steps taken.
    pub iterations: usize,
    /// The QP solver that answered each stress step (see `FormFindResult::solvers`).
    pub solvers: Vec<QpSolver>,
    pub hausdorff: f64,
    pub l2: f64,
    /// Area-weighted RMS and largest height change over the plan diagonal.
    pub rms_change: f64,
    pub max_change: f64,
    pub stress_seconds: f64,
    pub shape_seconds: f64,
    pub total_seconds: f64,
    /// Mean load over non-anchored vertices, and p̄ / L₀ (the unit of relative q bounds).
    pub p_bar: f64,
    pub q_unit: f64,
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

/// Mean load over non-anchored vertices (1 when there is none, as the library does).
pub fn mean_load(model: &Model, loads: &[f64]) -> f64 {
    let mesh = &model.mesh;
    let free: Vec<f64> = (0..mesh.n_vertices())
        .filter(|&v| mesh.is_non_anchored(v))
        .map(|v| loads[v])
        .collect();
    let mean = free.iter().sum::<f64>() / free.len().max(1) as f64;
    if mean > 0.0 {
        mean
    } else {
        1.0
    }
}

pub fn run(model: Model, o: &Options) -> voussoir::Result<Outcome> {
    let density = vec![o.density; model.mesh.n_faces()];
    let problem = Problem::new(model.mesh.clone())
        .with_face_density(density)?
        .with_polygon_diagonals(&model.diagonals)?;
    let settings = &o.settings;
    let before = analyse(&problem, &settings.stress)?;
    let mut outcome = if o.stress_only {
        Outcome {
            termination: None,
            positions: model.mesh.positions.clone(),
            stress: before.clone(),
            history: vec![before.eps_inf],
            iterations: 1,
            solvers: vec![before.solver],
            hausdorff: 0.0,
            l2: 0.0,
            rms_change: 0.0,
            max_change: 0.0,
            stress_seconds: before.seconds,
            shape_seconds: 0.0,
            total_seconds: before.seconds,
            before,
            p_bar: 0.0,
            q_unit: 0.0,
            tolerance: settings.tolerance,
            model,
        }
    } else {
        let bar = progress_bar(settings.max_iterations, "form finding", "ε∞");
        let mut report = |k: usize, eps: f64| {
            if let Some(bar) = &bar {
                bar.set_position(k as u64 + 1);
                bar.set_message(format!("{eps:.2e}"));
            }
            true
        };
        let result = form_find(&problem, settings, Some(&mut report));
        if let Some(bar) = &bar {
            bar.finish_and_clear();
        }
        let r = result?;
        Outcome {
            termination: Some(r.termination),
            positions: r.positions,
            stress: r.stress,
            before,
            history: r.history,
            iterations: r.iterations,
            solvers: r.solvers,
            hausdorff: r.hausdorff,
            l2: r.l2,
            rms_change: r.rms_change,
            max_change: r.max_change,
            stress_seconds: r.stress_seconds,
            shape_seconds: r.shape_seconds,
            total_seconds: r.total_seconds,
            p_bar: 0.0,
            q_unit: 0.0,
            tolerance: settings.tolerance,
            model,
        }
    };
    outcome.p_bar = mean_load(&outcome.model, &outcome.stress.loads);
    outcome.q_unit = outcome.p_bar / outcome.model.mesh.plan_scale(&outcome.positions);
    Ok(outcome)
}
