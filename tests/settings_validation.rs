//! One validation: `FormFindSettings::validate` checks every setting, and the C setters report
//! its reasons under their own argument names (with `VSR_STATUS_NON_FINITE` for NaN and
//! infinities), so the layers cannot disagree about a range.

mod capi_support;

use capi_support::{assert_ok, last_error, settings};
use voussoir::capi::*;
use voussoir::{AssessSettings, Error, FormFindSettings, QBound, StressSettings};

type Setter = Box<dyn Fn(*mut VsrSettings) -> VsrStatus>;
type Change = Box<dyn Fn(FormFindSettings) -> FormFindSettings>;

/// (C argument, C call, the same change in Rust, the field Rust names).
fn cases() -> Vec<(&'static str, Setter, Change, &'static str)> {
    let stress = |f: fn(StressSettings) -> StressSettings| -> Change {
        Box::new(move |s: FormFindSettings| {
            let st = f(s.stress.clone());
            s.with_stress(st)
        })
    };
    let schedule = |f: fn(voussoir::Schedule) -> voussoir::Schedule| -> Change {
        Box::new(move |s: FormFindSettings| {
            let sc = f(s.schedule);
            s.with_schedule(sc)
        })
    };
    unsafe {
        vec![
            (
                "tolerance",
                Box::new(|s| vsr_settings_set_tolerance(s, -1.0)) as Setter,
                Box::new(|s: FormFindSettings| s.with_tolerance(-1.0)) as Change,
                "tolerance",
            ),
            (
                "tolerance",
                Box::new(|s| vsr_settings_set_tolerance(s, f64::NAN)),
                Box::new(|s: FormFindSettings| s.with_tolerance(f64::NAN)),
                "tolerance",
            ),
            (
                "max_iterations",
                Box::new(|s| vsr_settings_set_max_iterations(s, 0)),
                Box::new(|s: FormFindSettings| s.with_max_iterations(0)),
                "max_iterations",
            ),
            (
                "iterations",
                Box::new(|s| vsr_settings_set_stall_window(s, 0)),
                Box::new(|s: FormFindSettings| s.with_stall_window(0)),
                "stall_window",
            ),
            (
                "diagonals",
                Box::new(|s| vsr_settings_set_max_height_change(s, f64::INFINITY)),
                Box::new(|s: FormFindSettings| s.with_max_height_change(f64::INFINITY)),
                "max_height_change",
            ),
            (
                "gamma",
                Box::new(|s| vsr_settings_set_fairness(s, -0.5)),
                Box::new(|s: FormFindSettings| s.with_fairness(-0.5)),
                "fairness",
            ),
            (
                "weight",
                Box::new(|s| vsr_settings_set_proximal_weight(s, -1.0)),
                Box::new(|s: FormFindSettings| s.with_proximal_weight(-1.0)),
                "proximal_weight",
            ),
            (
                "decay",
                Box::new(|s| vsr_settings_set_dual_length_smoothing(s, 0.0, 1.0)),
                Box::new(|s: FormFindSettings| s.with_smoothing_decay(1.0)),
                "smoothing_decay",
            ),
            (
                "mu",
                Box::new(|s| vsr_settings_set_dual_length_smoothing(s, -1.0, 0.5)),
                stress(|s| s.with_dual_length_smoothing(-1.0)),
                "dual_length_smoothing",
            ),
            (
                "beta",
                Box::new(|s| vsr_settings_set_schedule_beta(s, 2.0)),
                schedule(|s| s.with_beta(2.0)),
                "schedule.beta",
            ),
            (
                "eta",
                Box::new(|s| vsr_settings_set_schedule_eta(s, 0.0)),
                schedule(|s| s.with_eta(0.0)),
                "schedule.eta",
            ),
            (
                "mu0",
                Box::new(|s| vsr_settings_set_schedule_mu0(s, f64::NEG_INFINITY)),
                schedule(|s| s.with_mu0(f64::NEG_INFINITY)),
                "schedule.mu0",
            ),
            (
                "mu_min",
                Box::new(|s| vsr_settings_set_schedule_mu_min(s, -1.0)),
                schedule(|s| s.with_mu_min(-1.0)),
                "schedule.mu_min",
            ),
            (
                "pull",
                Box::new(|s| vsr_settings_set_schedule_pull(s, -1.0)),
                schedule(|s| s.with_pull(-1.0)),
                "schedule.pull",
            ),
            (
                "epsilon",
                Box::new(|s| vsr_settings_set_regularisation(s, -1.0)),
                stress(|s| s.with_regularisation(-1.0)),
                "regularisation",
            ),
            (
                "value",
                Box::new(|s| vsr_settings_set_q_min(s, -0.5, VsrBoundKind::Absolute as u32)),
                stress(|s| s.with_q_min(QBound::Absolute(-0.5))),
                "q_min",
            ),
            (
                "value",
                Box::new(|s| vsr_settings_set_q_max(s, f64::NAN, VsrBoundKind::Relative as u32)),
                stress(|s| s.with_q_max(Some(QBound::Relative(f64::NAN)))),
                "q_max",
            ),
            (
                "lo",
                Box::new(|s| vsr_settings_set_dual_length_bounds(s, -1.0, 2.0)),
                stress(|s| s.with_dual_length_bounds(Some((-1.0, 2.0)))),
                "dual_length_bounds.lo",
            ),
            (
                "hi",
                Box::new(|s| vsr_settings_set_dual_length_bounds(s, 2.0, 1.0)),
                stress(|s| s.with_dual_length_bounds(Some((2.0, 1.0)))),
                "dual_length_bounds.hi",
            ),
        ]
    }
}

#[test]
fn c_setters_report_the_reasons_of_the_rust_validation() {
    for (arg, set, change, field) in cases() {
        let changed = change(FormFindSettings::default());
        let (name, reason) = match changed.validate() {
            Err(Error::InvalidArgument { name, reason }) => (name, reason),
            other => panic!("{field}: Rust accepted it: {other:?}"),
        };
        assert_eq!(name, field);
        let s = settings();
        let status = set(s);
        let expected = if reason.ends_with("is not finite") {
            VsrStatus::NonFinite
        } else {
            VsrStatus::InvalidArgument
        };
        assert_eq!(status, expected, "{field}: {}", last_error());
        assert_eq!(
            last_error(),
            format!("argument `{arg}`: {reason}"),
            "{field}"
        );
        // Form finding refuses the same settings (it validates them first).
        let problem = voussoir::Problem::new(voussoir::generate::cap_dome(0.8, 50).unwrap());
        assert!(
            voussoir::form_find(&problem, &changed, None).is_err(),
            "{field}"
        );
        unsafe { vsr_settings_destroy(s) };
    }
}

#[test]
fn a_bound_checked_against_the_other_keeps_its_own_name() {
    let s = settings();
    assert_ok(unsafe { vsr_settings_set_q_max(s, 1.0, VsrBoundKind::Absolute as u32) });
    let status = unsafe { vsr_settings_set_q_min(s, 2.0, VsrBoundKind::Absolute as u32) };
    assert_eq!(status, VsrStatus::InvalidArgument);
    assert_eq!(last_error(), "argument `q_max`: must be >= q_min");
    assert_ok(unsafe { vsr_settings_set_q_max(s, f64::INFINITY, 0) });
    assert_ok(unsafe { vsr_settings_set_q_min(s, 0.5, VsrBoundKind::Absolute as u32) });
    let status = unsafe { vsr_settings_set_q_max(s, 0.1, VsrBoundKind::Absolute as u32) };
    assert_eq!(status, VsrStatus::InvalidArgument);
    assert_eq!(last_error(), "argument `q_max`: must be >= q_min");
    // The failed calls changed nothing: a valid q_min is still accepted, and +INFINITY removes
    // the upper bound.
    assert_ok(unsafe { vsr_settings_set_q_min(s, 0.5, VsrBoundKind::Absolute as u32) });
    assert_ok(unsafe { vsr_settings_set_q_max(s, f64::INFINITY, 0) });
    assert_ok(unsafe { vsr_settings_set_dual_length_bounds(s, 0.0, f64::INFINITY) });
    unsafe { vsr_settings_destroy(s) };
}

#[test]
fn the_defaults_are_valid_and_infinite_limits_are_not() {
    assert!(FormFindSettings::default().validate().is_ok());
    let limitless = FormFindSettings::default().with_max_height_change(f64::INFINITY);
    assert!(matches!(
        limitless.validate(),
        Err(Error::InvalidArgument {
            name: "max_height_change",
            ..
        })
    ));
}

/// A number of `tests/assess_data/bad_settings.json` (JSON has no NaN or infinity: strings).
fn number(v: &serde_json::Value) -> f64 {
    match v {
        serde_json::Value::String(s) => s.parse().expect("nan, inf or -inf"),
        v => v.as_f64().expect("a number"),
    }
}

/// The case's change to Rust settings, and the same change through the C setter.
fn assess_change(
    setting: &str,
    value: &serde_json::Value,
) -> (
    AssessSettings,
    Box<dyn Fn(*mut VsrAssessSettings) -> VsrStatus>,
) {
    let d = AssessSettings::default();
    let x = match value {
        serde_json::Value::Array(_) => 0.0,
        v => number(v),
    };
    let absolute = VsrBoundKind::Absolute as u32;
    unsafe {
        match setting {
            "unit_weight" => (
                d.with_unit_weight(x),
                Box::new(move |s| vsr_assess_settings_set_unit_weight(s, x)),
            ),
            "tolerance" => (
                d.with_tolerance(x),
                Box::new(move |s| vsr_assess_settings_set_tolerance(s, x)),
            ),
            "max_iterations" => (
                d.with_max_iterations(x as usize),
                Box::new(move |s| vsr_assess_settings_set_max_iterations(s, x as usize)),
            ),
            "q_min" => (
                d.with_q_min(QBound::Absolute(x)),
                Box::new(move |s| vsr_assess_settings_set_q_min(s, x, absolute)),
            ),
            "load_pattern" => {
                let p: Vec<f64> = value
                    .as_array()
                    .expect("a list")
                    .iter()
                    .map(number)
                    .collect();
                let c = p.clone();
                (
                    d.with_load_pattern(p),
                    Box::new(move |s| vsr_assess_settings_set_load_pattern(s, c.as_ptr(), c.len())),
                )
            }
            other => panic!("no case for the setting {other}"),
        }
    }
}

#[test]
fn assessment_settings_give_the_reasons_of_the_rust_validation_in_c_too() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/assess_data/bad_settings.json"
    );
    let data: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect(path)).expect(path);
    let cases = data["cases"].as_array().expect("cases");
    assert!(cases.len() >= 8);
    for case in cases {
        let text = |k: &str| case[k].as_str().expect(k).to_string();
        let (setting, reason) = (text("setting"), text("reason"));
        let (changed, set) = assess_change(&setting, &case["value"]);
        match changed.validate() {
            Err(Error::InvalidArgument { name, reason: r }) => {
                assert_eq!((name, r.as_str()), (setting.as_str(), reason.as_str()))
            }
            other => panic!("{setting}: Rust gave {other:?}"),
        }
        let mut s = std::ptr::null_mut();
        assert_ok(unsafe { vsr_assess_settings_create(&mut s) });
        let expected = if reason.ends_with("is not finite") {
            VsrStatus::NonFinite
        } else {
            VsrStatus::InvalidArgument
        };
        assert_eq!(set(s), expected, "{setting}: {}", last_error());
        let c = text("c_argument");
        assert_eq!(last_error(), format!("argument `{c}`: {reason}"));
        unsafe { vsr_assess_settings_destroy(s) };
    }
}
