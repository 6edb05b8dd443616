//! Enum arguments of the C API (`uint32_t` in C) checked and turned into the library's
//! enums: an unknown value is `VSR_STATUS_INVALID_ENUM`, naming the argument and the
//! allowed constants.

use super::boundary::{CResult, Failure};
use super::status::VsrStatus;
use crate::assess::Objective;
use crate::geometry::loads::LoadRule;
use crate::stress::airy::HoleMode;
use crate::stress::{EdgeScope, Formulation, QpSolver, TauMode};
use crate::FormMethod;

fn bad_enum(name: &str, value: u32, allowed: &str) -> Failure {
    Failure::new(
        VsrStatus::InvalidEnum,
        format!("argument `{name}`: {value} is not one of {allowed}"),
    )
}

pub(crate) fn tau_mode(name: &str, v: u32) -> CResult<TauMode> {
    Ok(match v {
        0 => TauMode::Optimized,
        1 => TauMode::Zero,
        2 => TauMode::Prescribed,
        _ => {
            return Err(bad_enum(
                name,
                v,
                "VSR_TAU_MODE_OPTIMIZED (0), VSR_TAU_MODE_ZERO (1), VSR_TAU_MODE_PRESCRIBED (2)",
            ))
        }
    })
}

pub(crate) fn method(name: &str, v: u32) -> CResult<FormMethod> {
    Ok(match v {
        0 => FormMethod::Nearest,
        1 => FormMethod::Paper,
        _ => {
            return Err(bad_enum(
                name,
                v,
                "VSR_METHOD_NEAREST (0), VSR_METHOD_PAPER (1)",
            ))
        }
    })
}

pub(crate) fn hole_mode(name: &str, v: u32) -> CResult<HoleMode> {
    Ok(match v {
        0 => HoleMode::Constant,
        1 => HoleMode::Affine,
        _ => {
            return Err(bad_enum(
                name,
                v,
                "VSR_HOLE_MODE_CONSTANT (0), VSR_HOLE_MODE_AFFINE (1)",
            ))
        }
    })
}

pub(crate) fn load_rule(name: &str, v: u32) -> CResult<LoadRule> {
    Ok(match v {
        0 => LoadRule::Barycentric,
        1 => LoadRule::Voronoi,
        2 => LoadRule::PlanArea,
        _ => return Err(bad_enum(
            name,
            v,
            "VSR_LOAD_RULE_BARYCENTRIC (0), VSR_LOAD_RULE_VORONOI (1), VSR_LOAD_RULE_PLAN_AREA (2)",
        )),
    })
}

pub(crate) fn qp_solver(name: &str, v: u32) -> CResult<QpSolver> {
    Ok(match v {
        0 => QpSolver::Native,
        1 => QpSolver::Clarabel,
        _ => {
            return Err(bad_enum(
                name,
                v,
                "VSR_QP_SOLVER_NATIVE (0), VSR_QP_SOLVER_CLARABEL (1)",
            ))
        }
    })
}

pub(crate) fn formulation(name: &str, v: u32) -> CResult<Formulation> {
    Ok(match v {
        0 => Formulation::Reduced,
        1 => Formulation::EdgeBased,
        _ => {
            return Err(bad_enum(
                name,
                v,
                "VSR_FORMULATION_REDUCED (0), VSR_FORMULATION_EDGE_BASED (1)",
            ))
        }
    })
}

pub(crate) fn edge_scope(name: &str, v: u32) -> CResult<EdgeScope> {
    Ok(match v {
        0 => EdgeScope::Interior,
        1 => EdgeScope::All,
        _ => {
            return Err(bad_enum(
                name,
                v,
                "VSR_EDGE_SCOPE_INTERIOR (0), VSR_EDGE_SCOPE_ALL (1)",
            ))
        }
    })
}

/// True for `VSR_BOUND_KIND_RELATIVE`.
pub(crate) fn bound_kind(name: &str, v: u32) -> CResult<bool> {
    match v {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err(bad_enum(
            name,
            v,
            "VSR_BOUND_KIND_ABSOLUTE (0), VSR_BOUND_KIND_RELATIVE (1)",
        )),
    }
}

/// The analysis of `vsr_assess_settings_set_objective`.
pub(crate) fn objective(name: &str, v: u32) -> CResult<Objective> {
    match v {
        0 => Ok(Objective::Fit),
        1 => Ok(Objective::MinThickness),
        2 => Ok(Objective::MinThrust),
        3 => Ok(Objective::MaxThrust),
        4 => Ok(Objective::MaxLoad),
        _ => Err(bad_enum(
            name,
            v,
            "VSR_OBJECTIVE_FIT (0), VSR_OBJECTIVE_MIN_THICKNESS (1), VSR_OBJECTIVE_MIN_THRUST \
             (2), VSR_OBJECTIVE_MAX_THRUST (3), VSR_OBJECTIVE_MAX_LOAD (4)",
        )),
    }
}
