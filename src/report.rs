//! The JSON report of a run, one schema for every command line (the formfind example and
//! `python -m voussoir`): every number computed, in the input's units, with the settings
//! used and how the input was read. Settings and enumerations carry the names of
//! `src/names.rs`, the names of Python's keyword settings. An assessment's report
//! ([`AssessmentReport`]) has the same layout and names, its figures under `assessment`.

use serde::Serialize;

use crate::io::{Model, UpAxis, WeldSummary};
use crate::mesh::repair::PlanRepair;
use crate::{FormFindResult, FormFindSettings, QpSolver, StressResult, StressStatus};

mod assessment;
pub use assessment::{
    AssessmentFigures, AssessmentReport, AssessmentSettings, Bounds, EnvelopeHeights, Excess,
    JointFigures, NeededScale,
};

/// What a run computed: the stress of the shape as it stands, or form finding.
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub enum Run<'a> {
    /// A stress analysis of the input shape.
    Analysis(&'a StressResult),
    /// Form finding from the input shape.
    FormFinding(&'a FormFindResult),
}

/// Wall time per part of a run, in seconds.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct Timings {
    /// Stress steps.
    pub stress: f64,
    /// Height steps.
    pub shape: f64,
    /// The whole run.
    pub total: f64,
}

/// The mesh's counts.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct MeshCounts {
    /// Vertices (unreferenced ones included).
    pub vertices: usize,
    /// Faces.
    pub faces: usize,
    /// Edges.
    pub edges: usize,
    /// Holes.
    pub holes: usize,
}

impl MeshCounts {
    /// The counts of `mesh`.
    pub(crate) fn of(mesh: &crate::Mesh) -> MeshCounts {
        MeshCounts {
            vertices: mesh.n_vertices(),
            faces: mesh.n_faces(),
            edges: mesh.n_edges(),
            holes: mesh.holes().count(),
        }
    }
}

/// The anchored vertices of `mesh`.
fn anchored(mesh: &crate::Mesh) -> Vec<u32> {
    (0..mesh.n_vertices() as u32)
        .filter(|&v| mesh.anchored[v as usize])
        .collect()
}

/// How the input was read, the first settings of every report: the read options and what
/// they did.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct ReadSettings {
    /// Where the mesh came from (its path).
    pub mesh: String,
    /// How the supports were chosen.
    pub supports: String,
    /// The welding; null when the file's vertices were kept as they are. Every vertex id of
    /// the report is a welded id (in the order of the first file vertex of each).
    pub weld: Option<WeldSummary>,
    /// The plan repair tolerance (0: slivers were rejected, not mended).
    pub repair_tolerance: f64,
    /// The input's up axis (positions here are Z-up).
    pub up: UpAxis,
    /// The number of polygon diagonals, which q_min does not bind.
    pub polygon_diagonals: usize,
}

impl ReadSettings {
    /// The read settings of `model`.
    pub(crate) fn of(model: &Model) -> ReadSettings {
        ReadSettings {
            mesh: model.source.clone(),
            supports: model.options.supports.to_string(),
            weld: model.weld.clone(),
            repair_tolerance: model.options.repair_tolerance,
            up: model.options.up,
            polygon_diagonals: model.diagonals.len(),
        }
    }
}

/// How a run ended, in every report.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct Ending {
    /// The termination's name ([`crate::Termination::name`]), or `stress_only`.
    pub termination: &'static str,
    /// The termination as a sentence.
    pub termination_message: String,
    /// The vertices a `stalled` or `blocked` termination lists.
    pub termination_vertices: Vec<u32>,
    /// The constraint to relax (`infeasible`), the failure (`numerical_error`) or what blocks
    /// (`blocked`).
    pub termination_detail: Option<String>,
}

impl Ending {
    /// The ending of a form finding or an assessment: the vertices a `stalled` or `blocked`
    /// termination lists, the constraint to relax, the failure or what blocks.
    pub(crate) fn of(t: &crate::Termination) -> Ending {
        use crate::Termination::*;
        let (vertices, detail) = match t {
            Stalled { vertices } => (vertices.clone(), None),
            Blocked { vertices, hint } => (vertices.clone(), Some(hint.clone())),
            Infeasible { constraint } => (vec![], Some(constraint.clone())),
            NumericalError { what } => (vec![], Some(what.clone())),
            _ => (vec![], None),
        };
        Ending {
            termination: t.name(),
            termination_message: t.to_string(),
            termination_vertices: vertices,
            termination_detail: detail,
        }
    }

    /// The ending of `run`: `stress_only` for an analysis.
    fn of_run(run: Run<'_>) -> Ending {
        match run {
            Run::Analysis(s) => Ending {
                termination: "stress_only",
                termination_message: format!("stress analysis: {}", s.status),
                termination_vertices: vec![],
                termination_detail: None,
            },
            Run::FormFinding(f) => Ending::of(&f.termination),
        }
    }
}

/// How the input was read and solved: the read options and what they did, then every solver
/// setting under its Python keyword name (`q_min`, `qp_solver`, `schedule`, ...).
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct ReportSettings {
    /// How the input was read.
    #[serde(flatten)]
    pub read: ReadSettings,
    /// Whether only the stress of the input shape was computed.
    pub stress_only: bool,
    /// The face density, when it is the same on every face (null otherwise).
    pub density: Option<f64>,
    /// Every solver setting (serialised flat).
    #[serde(flatten)]
    pub solver: FormFindSettings,
    /// The unit of relative force-density bounds at the final shape: mean load over
    /// non-anchored vertices / L₀ (half the plan diagonal).
    pub q_unit: f64,
    /// The regulariser the final stress step used (larger than `regularisation` after a
    /// numerical failure).
    pub regularisation_used: f64,
}

/// A run's report. Build with [`Report::new`], write with [`Report::to_json`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct Report {
    /// How the run ended.
    #[serde(flatten)]
    pub ending: Ending,
    /// How the final stress step ended.
    pub stress_status: StressStatus,
    /// The QP solver that produced the final forces.
    pub qp_solver_used: QpSolver,
    /// Stress steps taken.
    pub iterations: usize,
    /// The QP solver that answered each stress step.
    pub step_solvers: Vec<QpSolver>,
    /// ε∞ of the final forces: max |r_i| / mean load.
    pub eps_inf: f64,
    /// Largest horizontal imbalance at a non-anchored vertex over the mean load; a converged
    /// answer has it below the tolerance too.
    pub horizontal_imbalance: f64,
    /// ε∞ after each stress step (see [`FormFindResult::history`]).
    pub history: Vec<f64>,
    /// The final vertex positions (Z-up).
    pub positions: Vec<[f64; 3]>,
    /// Vertex pairs, smaller id first, sorted: the rows of the per-edge arrays.
    pub edges: Vec<[u32; 2]>,
    /// Force density per edge (force / length).
    pub force_densities: Vec<f64>,
    /// Vertical load per vertex.
    pub loads: Vec<f64>,
    /// `[vertex, x, y]` for each vertex with a non-zero external horizontal force.
    pub external_horizontal: Vec<(u32, f64, f64)>,
    /// Inward normal push per vertex (free boundary vertices).
    pub tau: Vec<f64>,
    /// Vertex weights of the power diagram (the force diagram).
    pub weights: Vec<f64>,
    /// Airy stress function per vertex.
    pub airy: Vec<f64>,
    /// The Airy function's jump around each hole, (c, a_x, a_y).
    pub hole_coefficients: Vec<[f64; 3]>,
    /// Vertical residual per vertex (0 at anchored ones).
    pub residuals: Vec<f64>,
    /// Σ r_i² over non-anchored vertices.
    pub objective: f64,
    /// Symmetric Hausdorff distance to the input surface / plan diagonal (0 for an analysis).
    pub hausdorff: f64,
    /// Area-weighted RMS distance to the input surface / plan diagonal.
    pub l2: f64,
    /// Area-weighted RMS height change / plan diagonal.
    pub rms_change: f64,
    /// Largest height change / plan diagonal.
    pub max_change: f64,
    /// Whether the input hangs below its supports and the answer is the nearest standing shape
    /// to its mirror image ([`crate::FormFindResult::mirrored`]; false for an analysis).
    pub mirrored: bool,
    /// Wall times, seconds.
    pub timings_s: Timings,
    /// The mesh's counts.
    pub mesh: MeshCounts,
    /// The anchored vertices.
    pub anchored: Vec<u32>,
    /// The plan repairs made while reading.
    pub plan_repairs: Vec<PlanRepair>,
    /// Vertices no face uses (ignored by the solvers).
    pub unreferenced: Vec<u32>,
    /// The units, in words.
    pub units: &'static str,
    /// How the input was read and solved.
    pub settings: ReportSettings,
    /// The library's version.
    pub voussoir_version: &'static str,
}

impl Report {
    /// The report of `run` on `model` with `settings`.
    pub fn new(model: &Model, settings: &FormFindSettings, run: Run<'_>) -> Report {
        let p = &model.problem;
        let mesh = &p.mesh;
        let (stress, positions) = match run {
            Run::Analysis(s) => (s, &mesh.positions),
            Run::FormFinding(f) => (&f.stress, &f.positions),
        };
        let (history, iterations, solvers) = match run {
            Run::Analysis(s) => (vec![s.eps_inf], 1, vec![s.solver]),
            Run::FormFinding(f) => (f.history.clone(), f.iterations, f.solvers.clone()),
        };
        let (distances, timings) = match run {
            Run::Analysis(s) => ([0.0; 4], [s.seconds, 0.0, s.seconds]),
            Run::FormFinding(f) => (
                [f.hausdorff, f.l2, f.rms_change, f.max_change],
                [f.stress_seconds, f.shape_seconds, f.total_seconds],
            ),
        };
        let density = p.face_density.first().copied();
        let uniform = p.face_density.iter().all(|d| Some(*d) == density);
        let report_settings = ReportSettings {
            read: ReadSettings::of(model),
            stress_only: matches!(run, Run::Analysis(_)),
            density: density.filter(|_| uniform),
            solver: settings.clone(),
            q_unit: p.mean_load(&stress.loads) / mesh.plan_scale(positions),
            regularisation_used: stress.regularisation,
        };
        Report {
            ending: Ending::of_run(run),
            stress_status: stress.status,
            qp_solver_used: stress.solver,
            iterations,
            step_solvers: solvers,
            eps_inf: stress.eps_inf,
            horizontal_imbalance: crate::solve::horizontal_eps(p, stress),
            history,
            positions: positions.clone(),
            edges: mesh.edges.iter().map(|e| e.v).collect(),
            // `+ 0.0` turns -0.0 (edges without force) into 0.
            force_densities: stress.force_densities.iter().map(|q| q + 0.0).collect(),
            loads: stress.loads.clone(),
            external_horizontal: (stress.external_horizontal.iter().enumerate())
                .filter(|(_, f)| f[0] != 0.0 || f[1] != 0.0)
                .map(|(v, f)| (v as u32, f[0], f[1]))
                .collect(),
            tau: stress.tau.clone(),
            weights: stress.weights.clone(),
            airy: stress.airy.clone(),
            hole_coefficients: stress.hole_coefficients.clone(),
            residuals: stress.residuals.clone(),
            objective: stress.objective,
            hausdorff: distances[0],
            l2: distances[1],
            rms_change: distances[2],
            max_change: distances[3],
            mirrored: matches!(run, Run::FormFinding(f) if f.mirrored),
            timings_s: Timings {
                stress: timings[0],
                shape: timings[1],
                total: timings[2],
            },
            mesh: MeshCounts::of(mesh),
            anchored: anchored(mesh),
            plan_repairs: model.repairs.clone(),
            unreferenced: mesh.unreferenced.clone(),
            units: "input units: lengths as in the mesh file, loads = density x area, force \
                    densities = force / length; relative q bounds are multiples of \
                    settings.q_unit",
            settings: report_settings,
            voussoir_version: env!("CARGO_PKG_VERSION"),
        }
    }

    /// The report as JSON text (see [`json_text`]).
    pub fn to_json(&self) -> String {
        json_text(self)
    }
}

/// JSON text with one top-level key per line: objects indented, arrays on one line, numbers
/// as the shortest decimals that read back to the same doubles (non-finite ones as null).
/// The layout of [`Report::to_json`], for a report with sections added by a command line.
pub fn json_text<T: Serialize>(value: &T) -> String {
    let value = serde_json::to_value(value).expect("reports serialise");
    let serde_json::Value::Object(map) = &value else {
        return value.to_string();
    };
    let lines: Vec<String> = map
        .iter()
        .map(|(k, v)| {
            let text = match v {
                serde_json::Value::Object(_) => serde_json::to_string_pretty(v)
                    .expect("JSON values serialise")
                    .replace('\n', "\n  "),
                _ => v.to_string(),
            };
            format!("  {}: {text}", serde_json::Value::from(k.as_str()))
        })
        .collect();
    format!("{{\n{}\n}}\n", lines.join(",\n"))
}
