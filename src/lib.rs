//! Voussoir: self-supporting masonry shapes (de Goes et al. 2013).
#![deny(unsafe_code)]

pub mod capi;
pub mod error;
pub mod generate;
pub mod geometry;
pub mod io;
pub mod mesh;
pub mod problem;
pub mod shape;
pub mod smooth;
mod solid;
pub mod solve;
pub mod stress;

pub use error::{Error, Result};
pub use geometry::loads::LoadRule;
pub use mesh::Mesh;
pub use problem::Problem;
pub use solid::{signed_volume, thicken, Solid, Thickness};
pub use solve::{form_find, FormFindResult, FormFindSettings, FormMethod, Termination};
pub use stress::airy::HoleMode;
pub use stress::{
    analyse, EdgeScope, Formulation, QBound, QpSolver, StressResult, StressSettings, StressStatus,
    TauMode,
};
