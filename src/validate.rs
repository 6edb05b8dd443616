//! The range checks of the settings' `validate` methods: one wording for every layer (the C
//! API and Python report these reasons under their own argument names).

use crate::error::{Error, Result};

/// The end of the reason of a number that must be finite and is not.
const NOT_FINITE: &str = "is not finite";

fn invalid(name: &'static str, reason: String) -> Error {
    Error::InvalidArgument { name, reason }
}

fn finite(name: &'static str, v: f64) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(invalid(name, format!("{v} {NOT_FINITE}")))
    }
}

/// `v` finite and >= `min`.
pub(crate) fn at_least(name: &'static str, v: f64, min: f64) -> Result<()> {
    finite(name, v)?;
    if v < min {
        return Err(invalid(name, format!("{v} must be >= {min}")));
    }
    Ok(())
}

/// `v` finite and > `min`.
pub(crate) fn above(name: &'static str, v: f64, min: f64) -> Result<()> {
    finite(name, v)?;
    if v <= min {
        return Err(invalid(name, format!("{v} must be > {min}")));
    }
    Ok(())
}

/// `v` finite, in [`min`, `max`] (`max` included unless `open`).
pub(crate) fn within(name: &'static str, v: f64, min: f64, max: f64, open: bool) -> Result<()> {
    at_least(name, v, min)?;
    if v > max || (open && v == max) {
        let op = if open { "<" } else { "<=" };
        return Err(invalid(name, format!("{v} must be {op} {max}")));
    }
    Ok(())
}

/// Every entry of `values` finite: the first that is not is named as `what` and its index
/// (`vertex 3: NaN is not finite`).
pub(crate) fn all_finite(name: &'static str, values: &[f64], what: &str) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(k) => Err(invalid(
            name,
            format!("{what} {k}: {} {NOT_FINITE}", values[k]),
        )),
    }
}

/// One entry per vertex of a mesh with `n` vertices: `len` of them.
pub(crate) fn one_per_vertex(name: &'static str, len: usize, n: usize) -> Result<()> {
    if len != n {
        return Err(invalid(
            name,
            format!("has {len} entries, expected one per vertex ({n})"),
        ));
    }
    Ok(())
}

/// A count of at least `min`.
pub(crate) fn count(name: &'static str, n: usize, min: usize) -> Result<()> {
    if n < min {
        return Err(invalid(name, format!("must be >= {min}")));
    }
    Ok(())
}

/// `name` below the setting `other` that it must not be below: a relation between two
/// settings, which the C setters report under the setting's own name.
pub(crate) fn below_other(name: &'static str, other: &str) -> Error {
    invalid(name, format!("{RELATION}{other}"))
}

/// The start of the reason of [`below_other`].
const RELATION: &str = "must be >= ";

/// Whether `e` is a relation between two settings ([`below_other`]).
pub(crate) fn is_relation(e: &Error) -> bool {
    matches!(e, Error::InvalidArgument { reason, .. }
        if reason.strip_prefix(RELATION).is_some_and(|r| r.starts_with(char::is_alphabetic)))
}

/// Whether `e` is a setting that must be finite and is NaN or infinite (the C API's
/// `VSR_STATUS_NON_FINITE`).
pub(crate) fn is_not_finite(e: &Error) -> bool {
    matches!(e, Error::InvalidArgument { reason, .. } if reason.ends_with(NOT_FINITE))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reason(r: Result<()>) -> String {
        match r {
            Err(Error::InvalidArgument { reason, .. }) => reason,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn reasons_name_the_value_and_the_bound() {
        assert_eq!(reason(at_least("x", -1.0, 0.0)), "-1 must be >= 0");
        assert_eq!(reason(above("x", 0.0, 0.0)), "0 must be > 0");
        assert_eq!(reason(within("x", 2.0, 0.0, 1.0, false)), "2 must be <= 1");
        assert_eq!(reason(within("x", 1.0, 0.0, 1.0, true)), "1 must be < 1");
        assert_eq!(reason(count("x", 0, 1)), "must be >= 1");
        assert_eq!(reason(above("x", f64::NAN, 0.0)), "NaN is not finite");
        assert!(is_not_finite(
            &at_least("x", f64::INFINITY, 0.0).unwrap_err()
        ));
        assert!(!is_not_finite(&at_least("x", -1.0, 0.0).unwrap_err()));
        assert!(within("x", 1.0, 0.0, 1.0, false).is_ok() && count("x", 1, 1).is_ok());
        assert_eq!(reason(Err(below_other("x", "y"))), "must be >= y");
        let all = all_finite("x", &[1.0, f64::INFINITY], "vertex");
        assert_eq!(reason(all.clone()), "vertex 1: inf is not finite");
        assert!(is_not_finite(&all.unwrap_err()) && all_finite("x", &[1.0], "v").is_ok());
        assert!(is_relation(&below_other("x", "y")));
        assert!(!is_relation(&count("x", 0, 1).unwrap_err()));
    }
}
