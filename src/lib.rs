//! Voussoir: self-supporting masonry shapes (de Goes et al. 2013).
//!
//! A vault is a [`Mesh`] (a triangle mesh over a plan with anchored vertices) wrapped in a
//! [`Problem`] (loads, prescribed forces). [`analyse`] answers whether it can stand: the best
//! compressive stress for the shape, its force diagram and the residual per vertex.
//! [`form_find`] finds the nearest shape that can. Meshes are read and written with [`io`];
//! [`generate`] builds test shapes with known answers; [`capi`] is the C ABI.
//!
//! ```
//! use voussoir::{form_find, generate, FormFindSettings, Problem, Termination};
//!
//! let mesh = generate::cap_dome(0.8, 200)?;
//! let result = form_find(&Problem::new(mesh), &FormFindSettings::default(), None)?;
//! assert_eq!(result.termination, Termination::Converged);
//! # Ok::<(), voussoir::Error>(())
//! ```
#![deny(unsafe_code)]
#![warn(missing_docs)]

mod assess;
pub mod capi;
mod error;
pub mod generate;
mod geometry;
pub mod interrupt;
pub mod io;
mod mesh;
mod names;
mod problem;
pub mod report;
mod setters;
mod shape;
mod smooth;
mod solid;
mod solve;
mod stress;
mod validate;

pub use assess::{
    assess, min_thickness_of_family, AssessResult, AssessSettings, Envelope, FamilyThickness,
    Objective, SpringingJoint,
};
pub use error::{Error, Result};
pub use geometry::dual::ForceDiagram;
pub use geometry::loads::LoadRule;
pub use mesh::repair::{repair_plan, PlanRepair, DEFAULT_REPAIR_TOLERANCE};
pub use mesh::{BoundaryLoop, Edge, Mesh, Side, MAX_COORDINATE, MIN_PLAN_EXTENT};
pub use problem::Problem;
pub use shape::Schedule;
pub use solid::{signed_volume, thicken, Solid, Thickness};
pub use solve::{
    form_find, form_find_from, FormFindResult, FormFindSettings, FormMethod, Progress, Termination,
};
pub use stress::airy::HoleMode;
pub use stress::{
    analyse, EdgeScope, Formulation, QBound, QpSolver, StressResult, StressSettings, StressStatus,
    TauMode, MAX_MEAN_LOAD, MIN_MEAN_LOAD,
};

/// Internals that the integration tests check against independent mathematics. Not part of
/// the API: compiled only with the `internals` feature, which this package's tests enable.
#[cfg(feature = "internals")]
#[doc(hidden)]
pub mod internals {
    pub use crate::geometry::dual::{edge_normal, power_centre};
    pub use crate::geometry::{Frame, Plan};
    pub use crate::stress::airy::AiryOperator;
    pub use crate::stress::holes::cut_holes;
    pub use crate::stress::{analyse_cached, StressCache};
}
