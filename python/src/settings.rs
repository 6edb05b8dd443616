//! Keyword settings → `FormFindSettings`, validated one by one as the C API's setters do (same
//! checks, same messages, the argument named by its keyword), starting from the Rust defaults.

use crate::errors::{invalid, not_finite};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use voussoir::{
    EdgeScope, FormFindSettings, FormMethod, Formulation, HoleMode, LoadRule, QBound, QpSolver,
    TauMode,
};

/// The Python spelling of each enumerated value.
const METHODS: [(&str, FormMethod); 2] = [
    ("nearest", FormMethod::Nearest),
    ("paper", FormMethod::Paper),
];
const TAUS: [(&str, TauMode); 3] = [
    ("optimized", TauMode::Optimized),
    ("zero", TauMode::Zero),
    ("prescribed", TauMode::Prescribed),
];
const HOLES: [(&str, HoleMode); 2] = [
    ("affine", HoleMode::Affine),
    ("constant", HoleMode::Constant),
];
const LOAD_RULES: [(&str, LoadRule); 3] = [
    ("barycentric", LoadRule::Barycentric),
    ("voronoi", LoadRule::Voronoi),
    ("plan_area", LoadRule::PlanArea),
];
const FORMULATIONS: [(&str, Formulation); 2] = [
    ("reduced", Formulation::Reduced),
    ("edge_based", Formulation::EdgeBased),
];
pub const QP_SOLVERS: [(&str, QpSolver); 2] = [
    ("native", QpSolver::Native),
    ("clarabel", QpSolver::Clarabel),
];
const SCOPES: [(&str, EdgeScope); 2] = [("all", EdgeScope::All), ("interior", EdgeScope::Interior)];
const KINDS: [(&str, bool); 2] = [("relative", true), ("absolute", false)];

/// The name of `value` in `table`.
pub fn name_of<T: PartialEq + Copy>(table: &[(&'static str, T)], value: T) -> &'static str {
    table
        .iter()
        .find(|(_, v)| *v == value)
        .map_or("unknown", |(n, _)| n)
}

fn choice<T: Copy>(name: &str, value: &Bound<'_, PyAny>, table: &[(&str, T)]) -> PyResult<T> {
    let text: String = value.extract().map_err(|_| {
        invalid(
            name,
            format_args!(
                "{} is not a string",
                value.repr().map_or("?".into(), |r| r.to_string())
            ),
        )
    })?;
    table
        .iter()
        .find(|(n, _)| *n == text)
        .map(|(_, v)| *v)
        .ok_or_else(|| {
            let allowed: Vec<String> = table.iter().map(|(n, _)| format!("'{n}'")).collect();
            invalid(
                name,
                format_args!("'{text}' is not one of {}", allowed.join(", ")),
            )
        })
}

fn number(name: &str, value: &Bound<'_, PyAny>) -> PyResult<f64> {
    value
        .extract::<f64>()
        .map_err(|_| invalid(name, "is not a number"))
}

fn finite(name: &str, value: &Bound<'_, PyAny>) -> PyResult<f64> {
    let v = number(name, value)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(not_finite(name, v))
    }
}

/// The C API's `at_least`: finite and >= `min` (> `min` when `strict`).
fn at_least(name: &str, value: &Bound<'_, PyAny>, min: f64, strict: bool) -> PyResult<f64> {
    let v = finite(name, value)?;
    if v < min || (strict && v == min) {
        let op = if strict { ">" } else { ">=" };
        return Err(invalid(name, format_args!("{v} must be {op} {min}")));
    }
    Ok(v)
}

fn count(name: &str, value: &Bound<'_, PyAny>, min: usize) -> PyResult<usize> {
    let v: i64 = value
        .extract()
        .map_err(|_| invalid(name, "is not an integer"))?;
    if v < min as i64 {
        return Err(invalid(name, format_args!("must be >= {min}")));
    }
    usize::try_from(v).map_err(|_| invalid(name, "is too large"))
}

fn bound(value: f64, relative: bool) -> QBound {
    if relative {
        QBound::Relative(value)
    } else {
        QBound::Absolute(value)
    }
}

/// Settings from keyword arguments (only those given), on top of the Rust defaults.
pub fn from_kwargs(kwargs: &Bound<'_, PyDict>) -> PyResult<FormFindSettings> {
    let mut f = FormFindSettings::default();
    let get = |key: &str| kwargs.get_item(key);
    let q_min_relative = match get("q_min_kind")? {
        Some(v) => choice("q_min_kind", &v, &KINDS)?,
        None => matches!(f.stress.q_min, QBound::Relative(_)),
    };
    let q_max_relative = match get("q_max_kind")? {
        Some(v) => choice("q_max_kind", &v, &KINDS)?,
        None => !matches!(f.stress.q_max, Some(QBound::Absolute(_))),
    };
    for (key, value) in kwargs.iter() {
        let key: String = key.extract()?;
        apply(&mut f, &key, &value, q_min_relative, q_max_relative)?;
    }
    if get("q_min")?.is_none() && get("q_min_kind")?.is_some() {
        if let QBound::Absolute(v) | QBound::Relative(v) = f.stress.q_min {
            f.stress.q_min = bound(v, q_min_relative);
        }
    }
    f.stress.validate().map_err(|e| match e {
        voussoir::Error::InvalidArgument { name, reason } => invalid(name, reason),
        e => invalid("settings", e),
    })?;
    Ok(f)
}

/// Applies one setting, checked as its C setter checks it.
fn apply(
    f: &mut FormFindSettings,
    key: &str,
    v: &Bound<'_, PyAny>,
    q_min_relative: bool,
    q_max_relative: bool,
) -> PyResult<()> {
    let s = &mut f.stress;
    match key {
        "method" => f.method = choice(key, v, &METHODS)?,
        "fairness" => f.fairness = at_least(key, v, 0.0, false)?,
        "max_height_change" => f.max_height_change = at_least(key, v, 0.0, true)?,
        "tolerance" => f.tolerance = at_least(key, v, 0.0, true)?,
        "max_iterations" => f.max_iterations = count(key, v, 1)?,
        "stall_window" => f.stall_window = count(key, v, 1)?,
        "odt_iterations" => f.odt_iterations = count(key, v, 0)?,
        "odt_free_boundary" => {
            f.odt_free_boundary = v
                .extract::<bool>()
                .map_err(|_| invalid(key, "is not True or False"))?
        }
        "proximal_weight" => f.proximal_weight = at_least(key, v, 0.0, false)?,
        "smoothing_decay" => {
            let d = at_least(key, v, 0.0, false)?;
            if d >= 1.0 {
                return Err(invalid(key, format_args!("{d} must be < 1")));
            }
            f.smoothing_decay = d;
        }
        "schedule_mu0" => f.schedule.mu0 = at_least(key, v, 0.0, false)?,
        "schedule_beta" => {
            let b = at_least(key, v, 0.0, false)?;
            if b > 1.0 {
                return Err(invalid(key, format_args!("{b} must be <= 1")));
            }
            f.schedule.beta = b;
        }
        "schedule_mu_min" => f.schedule.mu_min = at_least(key, v, 0.0, false)?,
        "schedule_eta" => f.schedule.eta = at_least(key, v, 0.0, true)?,
        "schedule_pull" => f.schedule.pull = at_least(key, v, 0.0, false)?,
        "q_min" => s.q_min = bound(at_least(key, v, 0.0, false)?, q_min_relative),
        "q_max" => {
            s.q_max = if v.is_none() || number(key, v)? == f64::INFINITY {
                None
            } else {
                Some(bound(at_least(key, v, 0.0, true)?, q_max_relative))
            }
        }
        "q_min_kind" | "q_max_kind" => {}
        "q_min_scope" => s.q_min_scope = choice(key, v, &SCOPES)?,
        "tau" => s.tau = choice(key, v, &TAUS)?,
        "holes" => s.holes = choice(key, v, &HOLES)?,
        "load_rule" => s.load_rule = choice(key, v, &LOAD_RULES)?,
        "formulation" => s.formulation = choice(key, v, &FORMULATIONS)?,
        "qp_solver" => s.solver = choice(key, v, &QP_SOLVERS)?,
        "regularisation" => s.regularisation = at_least(key, v, 0.0, false)?,
        "dual_length_smoothing" => s.dual_length_smoothing = at_least(key, v, 0.0, false)?,
        "dual_length_bounds" => s.dual_length_bounds = dual_bounds(v)?,
        _ => return Err(invalid(key, "is not a setting (see voussoir.defaults())")),
    }
    Ok(())
}

/// `None` or `(lo, hi)`, checked as `vsr_settings_set_dual_length_bounds` checks them.
fn dual_bounds(v: &Bound<'_, PyAny>) -> PyResult<Option<(f64, f64)>> {
    if v.is_none() {
        return Ok(None);
    }
    let (lo, hi): (Bound<'_, PyAny>, Bound<'_, PyAny>) = v
        .extract()
        .map_err(|_| invalid("dual_length_bounds", "is not None or a pair (lo, hi)"))?;
    let lo = at_least("dual_length_bounds", &lo, 0.0, false)?;
    let hi = number("dual_length_bounds", &hi)?;
    if hi.is_nan() || hi <= lo {
        return Err(invalid(
            "dual_length_bounds",
            format_args!("{hi} must be > lo ({lo})"),
        ));
    }
    Ok((lo > 0.0 || hi.is_finite()).then_some((lo, hi)))
}

/// Every setting with its default, from `FormFindSettings::default()`.
#[pyfunction]
pub fn defaults(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let f = FormFindSettings::default();
    let s = &f.stress;
    let d = PyDict::new(py);
    let (q_min, q_min_kind) = split(Some(s.q_min));
    let (q_max, q_max_kind) = split(s.q_max);
    d.set_item("method", name_of(&METHODS, f.method))?;
    d.set_item("fairness", f.fairness)?;
    d.set_item("max_height_change", f.max_height_change)?;
    d.set_item("tolerance", f.tolerance)?;
    d.set_item("max_iterations", f.max_iterations)?;
    d.set_item("stall_window", f.stall_window)?;
    d.set_item("odt_iterations", f.odt_iterations)?;
    d.set_item("odt_free_boundary", f.odt_free_boundary)?;
    d.set_item("proximal_weight", f.proximal_weight)?;
    d.set_item("smoothing_decay", f.smoothing_decay)?;
    d.set_item("schedule_mu0", f.schedule.mu0)?;
    d.set_item("schedule_beta", f.schedule.beta)?;
    d.set_item("schedule_mu_min", f.schedule.mu_min)?;
    d.set_item("schedule_eta", f.schedule.eta)?;
    d.set_item("schedule_pull", f.schedule.pull)?;
    d.set_item("q_min", q_min)?;
    d.set_item("q_min_kind", q_min_kind)?;
    d.set_item("q_max", q_max)?;
    d.set_item("q_max_kind", q_max_kind)?;
    d.set_item("q_min_scope", name_of(&SCOPES, s.q_min_scope))?;
    d.set_item("tau", name_of(&TAUS, s.tau))?;
    d.set_item("holes", name_of(&HOLES, s.holes))?;
    d.set_item("load_rule", name_of(&LOAD_RULES, s.load_rule))?;
    d.set_item("formulation", name_of(&FORMULATIONS, s.formulation))?;
    d.set_item("qp_solver", name_of(&QP_SOLVERS, s.solver))?;
    d.set_item("regularisation", s.regularisation)?;
    d.set_item("dual_length_smoothing", s.dual_length_smoothing)?;
    d.set_item("dual_length_bounds", s.dual_length_bounds)?;
    Ok(d)
}

/// A bound as (value or None, kind name).
fn split(b: Option<QBound>) -> (Option<f64>, &'static str) {
    match b {
        None => (None, "relative"),
        Some(QBound::Relative(v)) => (Some(v), "relative"),
        Some(QBound::Absolute(v)) => (Some(v), "absolute"),
        Some(_) => (None, "other"),
    }
}

/// The names of enumerated result values.
pub fn formulation_name(f: Formulation) -> &'static str {
    name_of(&FORMULATIONS, f)
}
