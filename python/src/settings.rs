//! Keyword settings → `FormFindSettings`, starting from the Rust defaults: each value is
//! converted here, then the whole is checked by the library's `FormFindSettings::validate`
//! (the checks of the C API's setters, same messages), the setting named by its keyword.

use crate::errors::invalid;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::str::FromStr;
use voussoir::io::UpAxis;
use voussoir::{
    EdgeScope, FormFindSettings, FormMethod, Formulation, HoleMode, LoadRule, Objective, QBound,
    QpSolver, TauMode,
};

const KINDS: [(&str, bool); 2] = [("relative", true), ("absolute", false)];

/// The relative/absolute kind of a bound, by name (true: relative).
pub fn kind(name: &str, value: &Bound<'_, PyAny>) -> PyResult<bool> {
    choice(name, value, &KINDS)
}

fn choice(name: &str, value: &Bound<'_, PyAny>, table: &[(&str, bool)]) -> PyResult<bool> {
    let text = string(name, value)?;
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

fn string(name: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    value.extract().map_err(|_| {
        invalid(
            name,
            format_args!(
                "{} is not a string",
                value.repr().map_or("?".into(), |r| r.to_string())
            ),
        )
    })
}

/// An enumerated setting by its library name (`FromStr` of the library's enums).
pub fn named<T: FromStr<Err = voussoir::Error>>(
    name: &str,
    value: &Bound<'_, PyAny>,
) -> PyResult<T> {
    string(name, value)?.parse().map_err(|e| match e {
        voussoir::Error::InvalidArgument { reason, .. } => invalid(name, reason),
        e => invalid(name, e),
    })
}

/// The names of every enumerated setting's values, from the library (`python -m voussoir`'s
/// choices).
#[pyfunction]
pub fn choices(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    fn names<T: Copy + std::fmt::Display>(all: &[T]) -> Vec<String> {
        all.iter().map(|v| v.to_string()).collect()
    }
    let d = PyDict::new(py);
    d.set_item("method", names(FormMethod::ALL))?;
    d.set_item("formulation", names(Formulation::ALL))?;
    d.set_item("qp_solver", names(QpSolver::ALL))?;
    d.set_item("q_min_scope", names(EdgeScope::ALL))?;
    d.set_item("tau", names(TauMode::ALL))?;
    d.set_item("holes", names(HoleMode::ALL))?;
    d.set_item("load_rule", names(LoadRule::ALL))?;
    d.set_item("up", names(UpAxis::ALL))?;
    d.set_item("objective", names(Objective::ALL))?;
    let kinds: Vec<&str> = KINDS.iter().map(|k| k.0).collect();
    d.set_item("q_min_kind", kinds.clone())?;
    d.set_item("q_max_kind", kinds)?;
    Ok(d)
}

/// A number, converted only (the library's `validate` checks its range).
pub fn number(name: &str, value: &Bound<'_, PyAny>) -> PyResult<f64> {
    value
        .extract::<f64>()
        .map_err(|_| invalid(name, "is not a number"))
}

/// A count: an integer >= 0, converted only.
pub fn count(name: &str, value: &Bound<'_, PyAny>) -> PyResult<usize> {
    let n: i64 = value
        .extract()
        .map_err(|_| invalid(name, "is not an integer"))?;
    usize::try_from(n).map_err(|_| invalid(name, format_args!("{n} is negative")))
}

/// A flag: True or False.
pub fn flag(name: &str, value: &Bound<'_, PyAny>) -> PyResult<bool> {
    value
        .extract::<bool>()
        .map_err(|_| invalid(name, "is not True or False"))
}

/// Where a scalar setting lives in `FormFindSettings`.
enum Slot {
    Number(fn(&mut FormFindSettings) -> &mut f64),
    Count(fn(&mut FormFindSettings) -> &mut usize),
    Flag(fn(&mut FormFindSettings) -> &mut bool),
}

/// The scalar settings by keyword, read by [`from_kwargs`] and [`defaults`]: adding a scalar
/// setting to the Rust settings adds one row here (its range is checked by
/// `FormFindSettings::validate`).
const SCALARS: &[(&str, Slot)] = &[
    ("fairness", Slot::Number(|f| &mut f.fairness)),
    (
        "max_height_change",
        Slot::Number(|f| &mut f.max_height_change),
    ),
    ("tolerance", Slot::Number(|f| &mut f.tolerance)),
    ("max_iterations", Slot::Count(|f| &mut f.max_iterations)),
    ("stall_window", Slot::Count(|f| &mut f.stall_window)),
    ("odt_iterations", Slot::Count(|f| &mut f.odt_iterations)),
    (
        "odt_free_boundary",
        Slot::Flag(|f| &mut f.odt_free_boundary),
    ),
    ("proximal_weight", Slot::Number(|f| &mut f.proximal_weight)),
    ("smoothing_decay", Slot::Number(|f| &mut f.smoothing_decay)),
    ("schedule_mu0", Slot::Number(|f| &mut f.schedule.mu0)),
    ("schedule_beta", Slot::Number(|f| &mut f.schedule.beta)),
    ("schedule_mu_min", Slot::Number(|f| &mut f.schedule.mu_min)),
    ("schedule_eta", Slot::Number(|f| &mut f.schedule.eta)),
    ("schedule_pull", Slot::Number(|f| &mut f.schedule.pull)),
    (
        "regularisation",
        Slot::Number(|f| &mut f.stress.regularisation),
    ),
    (
        "dual_length_smoothing",
        Slot::Number(|f| &mut f.stress.dual_length_smoothing),
    ),
];

impl Slot {
    /// Stores `v`, converted (not range-checked: `FormFindSettings::validate` does that).
    fn set(&self, f: &mut FormFindSettings, name: &str, v: &Bound<'_, PyAny>) -> PyResult<()> {
        match self {
            Slot::Number(at) => *at(f) = number(name, v)?,
            Slot::Count(at) => *at(f) = count(name, v)?,
            Slot::Flag(at) => *at(f) = flag(name, v)?,
        }
        Ok(())
    }

    /// The setting's value in `f`.
    fn get<'py>(&self, py: Python<'py>, f: &FormFindSettings) -> PyResult<Bound<'py, PyAny>> {
        let mut f = f.clone();
        Ok(match self {
            Slot::Number(at) => (*at(&mut f)).into_pyobject(py)?.into_any(),
            Slot::Count(at) => (*at(&mut f)).into_pyobject(py)?.into_any(),
            Slot::Flag(at) => (*at(&mut f)).into_pyobject(py)?.to_owned().into_any(),
        })
    }
}

fn bound(value: f64, relative: bool) -> QBound {
    if relative {
        QBound::Relative(value)
    } else {
        QBound::Absolute(value)
    }
}

/// The keyword of a setting the library names by its field (`schedule.mu0`, `solver`).
fn keyword(field: &str) -> String {
    match field {
        "solver" => "qp_solver".into(),
        f if f.starts_with("dual_length_bounds") => "dual_length_bounds".into(),
        f => f.replace('.', "_"),
    }
}

/// Settings from keyword arguments (only those given), on top of the Rust defaults, checked
/// by the library's `FormFindSettings::validate`.
pub fn from_kwargs(kwargs: &Bound<'_, PyDict>) -> PyResult<FormFindSettings> {
    let mut f = FormFindSettings::default();
    let get = |key: &str| kwargs.get_item(key);
    let q_min_relative = match get("q_min_kind")? {
        Some(v) => kind("q_min_kind", &v)?,
        None => matches!(f.stress.q_min, QBound::Relative(_)),
    };
    let q_max_relative = match get("q_max_kind")? {
        Some(v) => kind("q_max_kind", &v)?,
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
    f.validate().map_err(|e| match e {
        voussoir::Error::InvalidArgument { name, reason } => invalid(&keyword(name), reason),
        e => invalid("settings", e),
    })?;
    Ok(f)
}

/// Stores one setting, converted from its Python value.
fn apply(
    f: &mut FormFindSettings,
    key: &str,
    v: &Bound<'_, PyAny>,
    q_min_relative: bool,
    q_max_relative: bool,
) -> PyResult<()> {
    if let Some((_, slot)) = SCALARS.iter().find(|(k, _)| *k == key) {
        return slot.set(f, key, v);
    }
    let s = &mut f.stress;
    match key {
        "method" => f.method = named(key, v)?,
        "q_min" => s.q_min = bound(number(key, v)?, q_min_relative),
        "q_max" => {
            s.q_max = if v.is_none() || number(key, v)? == f64::INFINITY {
                None
            } else {
                Some(bound(number(key, v)?, q_max_relative))
            }
        }
        "q_min_kind" | "q_max_kind" => {}
        "q_min_scope" => s.q_min_scope = named(key, v)?,
        "tau" => s.tau = named(key, v)?,
        "holes" => s.holes = named(key, v)?,
        "load_rule" => s.load_rule = named(key, v)?,
        "formulation" => s.formulation = named(key, v)?,
        "qp_solver" => s.solver = named(key, v)?,
        "dual_length_bounds" => s.dual_length_bounds = dual_bounds(v)?,
        _ => return Err(invalid(key, "is not a setting (see voussoir.defaults())")),
    }
    Ok(())
}

/// `None` or `(lo, hi)`; `(0, inf)` is no bounds, as in `vsr_settings_set_dual_length_bounds`.
fn dual_bounds(v: &Bound<'_, PyAny>) -> PyResult<Option<(f64, f64)>> {
    if v.is_none() {
        return Ok(None);
    }
    let (lo, hi): (Bound<'_, PyAny>, Bound<'_, PyAny>) = v
        .extract()
        .map_err(|_| invalid("dual_length_bounds", "is not None or a pair (lo, hi)"))?;
    let lo = number("dual_length_bounds", &lo)?;
    let hi = number("dual_length_bounds", &hi)?;
    Ok((lo != 0.0 || hi != f64::INFINITY).then_some((lo, hi)))
}

/// Every setting with its default, from `FormFindSettings::default()`.
#[pyfunction]
pub fn defaults(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let f = FormFindSettings::default();
    let s = &f.stress;
    let d = PyDict::new(py);
    let (q_min, q_min_kind) = split(Some(s.q_min));
    let (q_max, q_max_kind) = split(s.q_max);
    d.set_item("method", f.method.as_str())?;
    for (key, slot) in SCALARS {
        d.set_item(key, slot.get(py, &f)?)?;
    }
    d.set_item("q_min", q_min)?;
    d.set_item("q_min_kind", q_min_kind)?;
    d.set_item("q_max", q_max)?;
    d.set_item("q_max_kind", q_max_kind)?;
    d.set_item("q_min_scope", s.q_min_scope.as_str())?;
    d.set_item("tau", s.tau.as_str())?;
    d.set_item("holes", s.holes.as_str())?;
    d.set_item("load_rule", s.load_rule.as_str())?;
    d.set_item("formulation", s.formulation.as_str())?;
    d.set_item("qp_solver", s.solver.as_str())?;
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
