//! The one set of names of the enumerated settings and outcomes, used by the command lines,
//! Python's keyword settings and results, and the report: `as_str`, `Display`, `FromStr`
//! (which takes `-` and `_` alike, so `edge-based` is `edge_based` and `min_thickness` is
//! `min-thickness`) and `Serialize` as the name.

use crate::error::{Error, Result};

/// Names the variants of an enum: `names!(Type, "setting" { Variant => "name", ... })`, in the
/// order `ALL` lists them (the order of the error message of `from_str`).
macro_rules! names {
    ($ty:ty, $setting:literal { $($variant:ident => $name:literal),* $(,)? }) => {
        impl $ty {
            /// Every value, in the order of their names in error messages.
            pub const ALL: &'static [$ty] = &[$(<$ty>::$variant),*];

            /// The value's name, as the command lines, Python and the report spell it.
            pub fn as_str(self) -> &'static str {
                match self {
                    $(Self::$variant => $name),*
                }
            }
        }

        impl std::fmt::Display for $ty {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.as_str())
            }
        }

        impl std::str::FromStr for $ty {
            type Err = Error;

            /// The value named `text` (`-` and `_` alike); otherwise an
            /// [`Error::InvalidArgument`] listing the names.
            fn from_str(text: &str) -> Result<$ty> {
                parse(text, $setting, Self::ALL, |v| v.as_str())
            }
        }

        impl serde::Serialize for $ty {
            fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
                s.serialize_str(self.as_str())
            }
        }
    };
}

/// The value of `all` whose name is `text`.
fn parse<T: Copy>(
    text: &str,
    setting: &'static str,
    all: &[T],
    name: impl Fn(T) -> &'static str,
) -> Result<T> {
    let key = |name: &str| name.replace('-', "_");
    all.iter()
        .copied()
        .find(|&v| key(name(v)) == key(text))
        .ok_or_else(|| {
            let names: Vec<String> = all.iter().map(|&v| format!("'{}'", name(v))).collect();
            Error::InvalidArgument {
                name: setting,
                reason: format!("'{text}' is not one of {}", names.join(", ")),
            }
        })
}

names!(crate::FormMethod, "method" { Nearest => "nearest", Paper => "paper" });
names!(crate::Formulation, "formulation" { Reduced => "reduced", EdgeBased => "edge_based" });
names!(crate::QpSolver, "qp_solver" { Native => "native", Clarabel => "clarabel" });
names!(crate::EdgeScope, "q_min_scope" { All => "all", Interior => "interior" });
names!(crate::TauMode, "tau" {
    Optimized => "optimized",
    Zero => "zero",
    Prescribed => "prescribed",
});
names!(crate::HoleMode, "holes" { Affine => "affine", Constant => "constant" });
names!(crate::LoadRule, "load_rule" {
    Barycentric => "barycentric",
    Voronoi => "voronoi",
    PlanArea => "plan_area",
});
names!(crate::StressStatus, "status" {
    Solved => "solved",
    AlmostSolved => "almost_solved",
    Infeasible => "infeasible",
    MaxIterations => "max_iterations",
    NumericalError => "numerical_error",
});
names!(crate::io::UpAxis, "up" { Z => "z", Y => "y" });
names!(crate::Objective, "objective" {
    Fit => "fit",
    MinThickness => "min-thickness",
    MinThrust => "min-thrust",
    MaxThrust => "max-thrust",
    MaxLoad => "max-load",
});

impl crate::Termination {
    /// The termination's name (snake_case), as Python and the report spell it; its
    /// `Display` is a sentence.
    pub fn name(&self) -> &'static str {
        use crate::Termination::*;
        match self {
            Converged => "converged",
            MaxIterations => "max_iterations",
            Stalled { .. } => "stalled",
            Infeasible { .. } => "infeasible",
            NumericalError { .. } => "numerical_error",
            Cancelled => "cancelled",
            Blocked { .. } => "blocked",
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::{EdgeScope, Error, Formulation, LoadRule, Objective, QpSolver, TauMode};

    #[test]
    fn names_read_back_and_list_the_choices() {
        for &f in Formulation::ALL {
            assert_eq!(f.as_str().parse::<Formulation>(), Ok(f));
            assert_eq!(f.to_string(), f.as_str());
        }
        assert_eq!("edge-based".parse(), Ok(Formulation::EdgeBased));
        assert_eq!("plan_area".parse(), Ok(LoadRule::PlanArea));
        assert_eq!(
            serde_json::to_string(&[QpSolver::Native, QpSolver::Clarabel]).unwrap(),
            r#"["native","clarabel"]"#
        );
        match "sideways".parse::<TauMode>() {
            Err(Error::InvalidArgument { name, reason }) => {
                assert_eq!(name, "tau");
                assert_eq!(
                    reason,
                    "'sideways' is not one of 'optimized', 'zero', 'prescribed'"
                );
            }
            other => panic!("{other:?}"),
        }
        assert!("All".parse::<EdgeScope>().is_err());
    }

    /// The assessment's objectives keep their hyphens, and read back either way.
    #[test]
    fn objectives_are_hyphenated() {
        let names: Vec<&str> = Objective::ALL.iter().map(|o| o.as_str()).collect();
        assert_eq!(
            names,
            [
                "fit",
                "min-thickness",
                "min-thrust",
                "max-thrust",
                "max-load"
            ]
        );
        for &o in Objective::ALL {
            assert_eq!(o.as_str().parse::<Objective>(), Ok(o));
        }
        assert_eq!("min_thickness".parse(), Ok(Objective::MinThickness));
        assert_eq!(
            serde_json::to_string(&Objective::MaxLoad).unwrap(),
            r#""max-load""#
        );
        match "least".parse::<Objective>() {
            Err(Error::InvalidArgument { name, reason }) => {
                assert_eq!(name, "objective");
                assert_eq!(
                    reason,
                    "'least' is not one of 'fit', 'min-thickness', 'min-thrust', 'max-thrust', \
                     'max-load'"
                );
            }
            other => panic!("{other:?}"),
        }
    }
}
