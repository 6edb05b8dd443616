//! The stress constraints of a plan as plain linear data, for solvers that move heights and
//! forces together (the assessment, docs/method.md §16): q = S y with the reduced operator,
//! the hard horizontal balance rows and the force-density bounds (no τ: free edges are free), all in frame
//! units, as the stress step of §8 sees them.

use super::airy::AiryOperator;
use super::attempts::{force_model, ForceMap};
use super::framed::{boundary_normals, edge_bounds, horizontal_terms, non_anchored};
use super::sparse::Csr;
use super::{Formulation, StressSettings};
use crate::error::Result;
use crate::geometry::{Frame, Plan};
use crate::problem::Problem;

/// The stress unknowns' constraints of one plan, in frame units (q′ = q L₀/p̄, forces / p̄).
pub(crate) struct LinearStress {
    pub frame: Frame,
    pub plan: Plan,
    /// The reduced operator: q = S y, one row per mesh edge.
    pub airy: AiryOperator,
    /// Vertices with hard horizontal balance rows (the free boundary vertices).
    pub balance: Vec<u32>,
    /// External horizontal force per vertex (prescribed τ included).
    pub external: Vec<[f64; 2]>,
    /// Per edge: None for an edge without force, else (lower, upper) on q.
    pub bounds: Vec<Option<(f64, f64)>>,
}

impl LinearStress {
    /// The constraints at the plan of `positions` for mean load `p_bar` (the unit of forces).
    pub fn new(
        problem: &Problem,
        positions: &[[f64; 3]],
        settings: &StressSettings,
        p_bar: f64,
    ) -> Result<LinearStress> {
        let mesh = &problem.mesh;
        let frame = Frame::of(mesh, positions);
        let plan = Plan::new(mesh, positions, &frame);
        let unit = p_bar / frame.scale;
        let normal = boundary_normals(mesh, &plan.u);
        let (external, _) = horizontal_terms(problem, settings, &normal, p_bar);
        let bounds = edge_bounds(problem, &plan, settings, unit);
        let free: Vec<u32> = non_anchored(mesh);
        let (map, balance) = force_model(
            mesh,
            &plan,
            settings.holes,
            Formulation::Reduced,
            &bounds,
            &free,
            None,
        )?;
        let airy = match map {
            ForceMap::Airy(op) => op,
            ForceMap::Selection(_) => unreachable!("the reduced formulation has an Airy map"),
        };
        Ok(LinearStress {
            frame,
            plan,
            airy,
            balance,
            external,
            bounds,
        })
    }

    pub fn s(&self) -> &Csr {
        &self.airy.s
    }
}
