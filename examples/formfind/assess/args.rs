//! The options of `--assess`: the analysis, the envelope (a thickness or intrados and
//! extrados files), the unit weight, fixed supports, the live load pattern and the section
//! drawn; and the checks of their combinations with each other and with form finding's.

use std::path::PathBuf;

use voussoir::Objective;

use crate::args::{Options, SolidThickness};

/// The options of an assessment (all `None` / false without `--assess`).
#[derive(Debug, Clone, Default)]
pub struct AssessOptions {
    pub objective: Option<Objective>,
    /// `--thickness T` or `--thickness density`.
    pub thickness: Option<SolidThickness>,
    pub intrados: Option<PathBuf>,
    pub extrados: Option<PathBuf>,
    pub unit_weight: Option<f64>,
    pub fixed_supports: bool,
    pub load_pattern: Option<PathBuf>,
    pub section: Option<Section>,
    /// `--springing Z`: the springing plane's height at every free support.
    pub springing: Option<f64>,
    /// `--reach B`: the springing joint's reach at every free support (`inf`: none).
    pub reach: Option<f64>,
}

/// The vertical plane of the section picture: `axis` = `at` (`None`: the plan's centre).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// 0 for a plane x = const (the section runs along y), 1 for y = const (along x).
    pub axis: usize,
    pub at: Option<f64>,
}

impl Default for Section {
    /// Through the plan's centre, along x.
    fn default() -> Section {
        Section { axis: 1, at: None }
    }
}

impl Section {
    pub fn axis_name(&self) -> &'static str {
        ["x", "y"][self.axis]
    }
}

/// The options of form finding that an assessment does not use.
const FORM_FINDING_ONLY: [&str; 15] = [
    "--stress-only",
    "--method",
    "--fairness",
    "--max-height-change",
    "--solver",
    "--qp",
    "--qmin-scope",
    "--qmax",
    "--tau",
    "--holes",
    "--dual-smoothing",
    "--smoothing-decay",
    "--odt",
    "--solid",
    "--solid-unit-weight",
];

/// The options that only an assessment uses.
const ASSESSMENT_ONLY: [&str; 9] = [
    "--thickness",
    "--intrados",
    "--extrados",
    "--unit-weight",
    "--fixed-supports",
    "--load-pattern",
    "--section",
    "--springing",
    "--reach",
];

fn positive(flag: &str, text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!(
            "{flag}: expected a finite number > 0, got `{text}`"
        )),
    }
}

/// `x`, `y`, `x=VALUE` or `y=VALUE`.
fn section(text: &str) -> Result<Section, String> {
    let (axis, at) = match text.split_once('=') {
        Some((a, v)) => (a, Some(v)),
        None => (text, None),
    };
    let axis = match axis.trim() {
        "x" => 0,
        "y" => 1,
        _ => {
            return Err(format!(
            "--section: expected x, y, x=VALUE or y=VALUE (the vertical plane drawn), got `{text}`"
        ))
        }
    };
    let at = match at {
        None => None,
        Some(v) => match v.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Some(v),
            _ => {
                return Err(format!(
                    "--section: expected a number after `=`, got `{text}`"
                ))
            }
        },
    };
    Ok(Section { axis, at })
}

/// Parses one assessment flag; `Ok(false)` when `flag` is not one of them.
pub fn flag(
    flag: &str,
    value: &mut dyn FnMut() -> Result<String, String>,
    a: &mut AssessOptions,
) -> Result<bool, String> {
    match flag {
        "--assess" => {
            let text = value()?;
            let objective = text.parse::<Objective>().map_err(|_| {
                let (last, others) = Objective::ALL.split_last().expect("objectives");
                let others: Vec<&str> = others.iter().map(|o| o.as_str()).collect();
                format!(
                    "--assess: expected {} or {last}, got `{text}`",
                    others.join(", ")
                )
            })?;
            a.objective = Some(objective);
        }
        "--thickness" => {
            let text = value()?;
            a.thickness = Some(if text == "density" {
                SolidThickness::FromDensity
            } else {
                SolidThickness::Uniform(positive(flag, &text).map_err(|_| {
                    format!("--thickness: expected a thickness > 0 or `density`, got `{text}`")
                })?)
            });
        }
        "--intrados" => a.intrados = Some(value()?.into()),
        "--extrados" => a.extrados = Some(value()?.into()),
        // The range is the core's (`AssessSettings::validate`); 0 means no self-weight.
        "--unit-weight" => a.unit_weight = Some(crate::args::number(flag, &value()?)?),
        "--fixed-supports" => a.fixed_supports = true,
        "--load-pattern" => a.load_pattern = Some(value()?.into()),
        "--section" => a.section = Some(section(&value()?)?),
        "--springing" => a.springing = Some(crate::args::number(flag, &value()?)?),
        // `inf` drops the joint; the range (>= 0) is the core's (`Envelope::with_springing`).
        "--reach" => {
            let text = value()?;
            a.reach = Some(match text.trim().parse::<f64>() {
                Ok(b) if !b.is_nan() => b,
                _ => return Err(format!("--reach: expected a length or `inf`, got `{text}`")),
            });
        }
        _ => return Ok(false),
    }
    Ok(true)
}

/// Combinations that cannot work: assessment options without `--assess`, form-finding ones
/// with it, an envelope given twice or not at all, a load pattern without max-load.
pub fn check(o: &Options, given: &[String]) -> Result<(), String> {
    let a = &o.assess;
    let Some(objective) = a.objective else {
        if let Some(f) = ASSESSMENT_ONLY
            .iter()
            .find(|f| given.iter().any(|g| g == *f))
        {
            return Err(format!("{f} needs --assess ANALYSIS"));
        }
        return Ok(());
    };
    if let Some(f) = FORM_FINDING_ONLY
        .iter()
        .find(|f| given.iter().any(|g| g == *f))
    {
        return Err(format!("{f} is an option of form finding, not of --assess"));
    }
    match (&a.thickness, &a.intrados, &a.extrados) {
        (Some(_), None, None) | (None, Some(_), Some(_)) => {}
        (None, None, None) => return Err(
            "--assess needs the masonry's envelope: --thickness T, or --intrados A --extrados B"
                .into(),
        ),
        (Some(_), _, _) => {
            return Err("give --thickness or --intrados and --extrados, not both".into())
        }
        (None, Some(_), None) => return Err("--intrados needs --extrados B".into()),
        (None, None, Some(_)) => return Err("--extrados needs --intrados A".into()),
    }
    if a.fixed_supports {
        if let Some(f) = ["--springing", "--reach"]
            .iter()
            .find(|f| given.iter().any(|g| g == *f))
        {
            return Err(format!(
                "{f} sets the joint of free supports: it does not go with --fixed-supports"
            ));
        }
    }
    let density_thickness = a.thickness == Some(SolidThickness::FromDensity);
    match a.unit_weight {
        None if density_thickness => {
            return Err(
                "--thickness density needs --unit-weight W (thickness = --density / W)".into(),
            )
        }
        Some(w) if density_thickness && w <= 0.0 => {
            return Err(format!(
                "--unit-weight: {w} must be > 0 with --thickness density (thickness = \
                 --density / W)"
            ))
        }
        _ => {}
    }
    if given.iter().any(|g| g == "--density") && !density_thickness {
        return Err(
            "--density goes with --thickness density under --assess: the envelope's thickness \
             sets the self-weight"
                .into(),
        );
    }
    match (objective, &a.load_pattern) {
        (Objective::MaxLoad, None) => {
            Err("--assess max-load needs --load-pattern L.json (the load to multiply)".into())
        }
        (Objective::MaxLoad, Some(_)) | (_, None) => Ok(()),
        (other, Some(_)) => Err(format!(
            "--load-pattern goes with --assess max-load, not with --assess {}",
            other.as_str()
        )),
    }
}

/// The thickness of `--thickness`, if given.
pub fn thickness(o: &Options) -> Option<voussoir::Thickness> {
    match o.assess.thickness? {
        SolidThickness::Uniform(t) => Some(voussoir::Thickness::Uniform(t)),
        SolidThickness::FromDensity => Some(voussoir::Thickness::Uniform(
            o.density / o.assess.unit_weight?,
        )),
    }
}
