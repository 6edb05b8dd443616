//! The report of a masonry assessment ([`crate::assess()`]), for every command line: the
//! figures and certificate under `assessment`, then the thrust surface's forces, the mesh and
//! the settings, with the names and layout of [`super::Report`].

use serde::Serialize;

use super::{anchored, Ending, MeshCounts, ReadSettings};
use crate::io::Model;
use crate::mesh::repair::PlanRepair;
use crate::{AssessResult, AssessSettings, Envelope, LoadRule, QBound};

/// A height's largest excess over its bound, and where.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct Excess {
    /// The excess (0 when every height is inside).
    pub excess: f64,
    /// Its vertex (null when there is none).
    pub vertex: Option<u32>,
}

/// The least thickness scale at which a thrust surface fits, and the vertex where that
/// surface leaves the given envelope most.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct NeededScale {
    /// The scale of the envelope's half extents (above 1: the envelope is too thin).
    pub scale: f64,
    /// The vertex (null when there is none).
    pub vertex: Option<u32>,
}

/// Lower and upper heights per vertex.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct Bounds {
    /// The lower heights.
    pub lower: Vec<f64>,
    /// The upper heights.
    pub upper: Vec<f64>,
}

/// The masonry's envelope as given: intrados, extrados and middle heights per vertex, and
/// the thickness per face.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct EnvelopeHeights {
    /// Intrados height per vertex.
    pub lower: Vec<f64>,
    /// Extrados height per vertex.
    pub upper: Vec<f64>,
    /// Middle surface height per vertex.
    pub middle: Vec<f64>,
    /// Thickness per face along the middle surface's normal.
    pub face_thickness: Vec<f64>,
}

/// Where a free support's reaction meets its springing plane ([`crate::SpringingJoint`]).
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct JointFigures {
    /// The support vertex.
    pub vertex: u32,
    /// Height of the springing plane at the reported scale.
    pub springing: f64,
    /// The joint's reach at the reported scale.
    pub reach: f64,
    /// Where the reaction's line through the support meets the springing plane (null
    /// coordinates where the vertical reaction is not downward).
    pub point: [f64; 3],
    /// Plan distance of `point` from the support (null where infinite).
    pub offset: f64,
}

/// What an assessment found, at which thickness, and its certificate.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct AssessmentFigures {
    /// The analysis ([`crate::Objective::as_str`]).
    pub objective: &'static str,
    /// Whether the thrust surface is certified inside the envelope.
    pub feasible: bool,
    /// How the search ended.
    #[serde(flatten)]
    pub ending: Ending,
    /// Sequential QP iterations.
    pub iterations: usize,
    /// Wall time, seconds.
    pub seconds: f64,
    /// The uniform thickness the envelope was made from (null for other envelopes).
    pub thickness: Option<f64>,
    /// The thickness of `bounds` (the least one for `min-thickness`), when uniform and the
    /// surface is certified (null otherwise: no thickness is proven).
    pub thickness_min: Option<f64>,
    /// The scale of the envelope's half extents that `bounds` holds.
    pub thickness_scale: f64,
    /// 1 / `thickness_scale`.
    pub safety_factor: f64,
    /// Σ over the supports of |horizontal reaction|.
    pub thrust_horizontal: f64,
    /// λ of `max-load` (0 otherwise).
    pub load_factor: f64,
    /// `max-thrust`, `max-load`: the objective has no bound (`thrust_horizontal` or
    /// `load_factor` is a value reached); false otherwise.
    pub unbounded: bool,
    /// max |r| / mean load over the non-anchored vertices.
    pub eps_inf: f64,
    /// Largest horizontal imbalance at a non-anchored vertex over the mean load.
    pub horizontal_imbalance: f64,
    /// The largest excess of a height over its bound.
    pub worst_bound: Excess,
    /// The largest residual's vertex.
    pub worst_residual_vertex: Option<u32>,
    /// Per free support, where its reaction meets the springing plane (empty with fixed
    /// supports).
    pub joints: Vec<JointFigures>,
    /// The largest joint excess over the reach × the mean load, and its support.
    pub worst_joint: Excess,
    /// Without a certified surface (but for `min-thickness`): the least thickness scale that
    /// holds one and the vertex where it leaves the envelope most; else null.
    pub needed_scale: Option<NeededScale>,
    /// The vertices that no compressive state joins to a support: where there are any, no
    /// surface exists in any envelope (docs/method.md §16.3).
    pub stranded: Vec<u32>,
    /// The envelope at `thickness_scale`: the heights the thrust surface keeps within.
    pub bounds: Bounds,
    /// The envelope as given.
    pub envelope: EnvelopeHeights,
    /// `[vertex, x, y]` for each vertex with a non-zero horizontal reaction.
    pub reactions: Vec<(u32, f64, f64)>,
    /// The load per vertex that `max-load` multiplies (null otherwise).
    pub load_pattern: Option<Vec<f64>>,
}

/// How the input was read and the assessment's settings, under Python's keyword names.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct AssessmentSettings {
    /// How the input was read.
    #[serde(flatten)]
    pub read: ReadSettings,
    /// The analysis.
    pub objective: &'static str,
    /// The uniform thickness (null for a per-face one or intrados and extrados).
    pub thickness: Option<f64>,
    /// The intrados file, when the envelope was read from files (set by the command line).
    pub intrados: Option<String>,
    /// The extrados file (set by the command line).
    pub extrados: Option<String>,
    /// The load pattern's file (set by the command line).
    pub load_pattern: Option<String>,
    /// Weight per unit volume.
    pub unit_weight: f64,
    /// Whether the supports kept the mesh's heights.
    pub fixed_supports: bool,
    /// How a face's weight is shared among its corners.
    pub load_rule: LoadRule,
    /// Lower bound on the force densities.
    pub q_min: QBound,
    /// Largest ε∞ of a certified surface.
    pub tolerance: f64,
    /// Sequential QP iterations at most.
    pub max_iterations: usize,
}

/// An assessment's report. Build with [`AssessmentReport::new`], write with
/// [`AssessmentReport::to_json`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct AssessmentReport {
    /// The figures and the certificate.
    pub assessment: AssessmentFigures,
    /// The thrust surface's vertex positions (Z-up).
    pub positions: Vec<[f64; 3]>,
    /// Vertex pairs, smaller id first, sorted: the rows of the per-edge arrays.
    pub edges: Vec<[u32; 2]>,
    /// Force density per edge (force / length).
    pub force_densities: Vec<f64>,
    /// Vertical load per vertex.
    pub loads: Vec<f64>,
    /// Vertical residual per vertex.
    pub residuals: Vec<f64>,
    /// The mesh's counts.
    pub mesh: MeshCounts,
    /// The anchored vertices.
    pub anchored: Vec<u32>,
    /// The plan repairs made while reading.
    pub plan_repairs: Vec<PlanRepair>,
    /// Vertices no face uses.
    pub unreferenced: Vec<u32>,
    /// The units, in words.
    pub units: &'static str,
    /// How the input was read and assessed.
    pub settings: AssessmentSettings,
    /// The library's version.
    pub voussoir_version: &'static str,
}

impl AssessmentReport {
    /// The report of `result`, the assessment of `model` inside `envelope` with `settings`;
    /// `thickness` is the uniform thickness the envelope was made from, if it was.
    pub fn new(
        model: &Model,
        envelope: &Envelope,
        settings: &AssessSettings,
        result: &AssessResult,
        thickness: Option<f64>,
    ) -> AssessmentReport {
        let mesh = &model.problem.mesh;
        let r = result;
        AssessmentReport {
            assessment: figures(envelope, settings, r, thickness),
            positions: r.positions.clone(),
            edges: mesh.edges.iter().map(|e| e.v).collect(),
            // `+ 0.0` turns -0.0 (edges without force) into 0.
            force_densities: r.force_densities.iter().map(|q| q + 0.0).collect(),
            loads: r.loads.clone(),
            residuals: r.residuals.clone(),
            mesh: MeshCounts::of(mesh),
            anchored: anchored(mesh),
            plan_repairs: model.repairs.clone(),
            unreferenced: mesh.unreferenced.clone(),
            units: "input units: lengths as in the mesh, loads = unit weight x thickness x \
                    area (plus the load factor x the load pattern), force densities = force / \
                    length",
            settings: AssessmentSettings {
                read: ReadSettings::of(model),
                objective: settings.objective.as_str(),
                thickness,
                intrados: None,
                extrados: None,
                load_pattern: None,
                unit_weight: settings.unit_weight,
                fixed_supports: settings.fixed_supports,
                load_rule: settings.load_rule,
                q_min: settings.q_min,
                tolerance: settings.tolerance,
                max_iterations: settings.max_iterations,
            },
            voussoir_version: env!("CARGO_PKG_VERSION"),
        }
    }

    /// The report as JSON text (see [`super::json_text`]).
    pub fn to_json(&self) -> String {
        super::json_text(self)
    }
}

/// The `assessment` section.
fn figures(
    envelope: &Envelope,
    settings: &AssessSettings,
    r: &AssessResult,
    thickness: Option<f64>,
) -> AssessmentFigures {
    let excess = |(excess, vertex): (f64, Option<u32>)| Excess { excess, vertex };
    AssessmentFigures {
        objective: r.objective.as_str(),
        feasible: r.feasible,
        ending: Ending {
            termination_message: r.termination_message(),
            ..Ending::of(&r.termination)
        },
        iterations: r.iterations,
        seconds: r.seconds,
        thickness,
        thickness_min: thickness
            .filter(|_| r.feasible)
            .map(|t| r.thickness_scale * t),
        thickness_scale: r.thickness_scale,
        safety_factor: r.safety_factor,
        thrust_horizontal: r.thrust_horizontal,
        load_factor: r.load_factor,
        unbounded: r.unbounded,
        eps_inf: r.eps_inf,
        horizontal_imbalance: r.horizontal_imbalance,
        worst_bound: excess(r.worst_bound),
        worst_residual_vertex: r.worst_residual_vertex,
        joints: (r.joints.iter())
            .map(|j| JointFigures {
                vertex: j.vertex,
                springing: j.springing,
                reach: j.reach,
                point: j.point,
                offset: j.offset,
            })
            .collect(),
        worst_joint: excess(r.worst_joint),
        needed_scale: (r.needed_scale).map(|(scale, vertex)| NeededScale { scale, vertex }),
        stranded: r.stranded.clone(),
        bounds: Bounds {
            lower: r.lower.clone(),
            upper: r.upper.clone(),
        },
        envelope: EnvelopeHeights {
            lower: envelope.lower.clone(),
            upper: envelope.upper.clone(),
            middle: envelope.middle.clone(),
            face_thickness: envelope.face_thickness.clone(),
        },
        reactions: (r.reactions.iter().enumerate())
            .filter(|(_, f)| f[0] != 0.0 || f[1] != 0.0)
            .map(|(v, f)| (v as u32, f[0], f[1]))
            .collect(),
        load_pattern: settings.load_pattern.clone(),
    }
}
