//! The springing joint of free supports in the assessment (docs/method.md §16.1, §16.3):
//! Heyman's dome on the classical joint, certificates recomputed from the outputs alone
//! (the joint included), and a surface the vertical reading certified that the joint
//! refuses.

mod common;

use common::assess::{barrel, hemisphere_by_angle, hemisphere_meridians, reactions, shell};
use voussoir::{
    assess, min_thickness_of_family, AssessResult, AssessSettings, Envelope, Error,
    FamilyThickness, Mesh, Problem,
};

/// How far beyond its reach (σ b) each support's reaction line meets the springing plane
/// (σ-scaled about the middle), in plan distance; the largest over the supports.
fn joint_overshoot(mesh: &Mesh, envelope: &Envelope, r: &AssessResult) -> f64 {
    let s = r.thickness_scale;
    let mut worst = f64::NEG_INFINITY;
    for (a, reaction) in reactions(mesh, r).iter().enumerate() {
        let Some((h, v)) = reaction else { continue };
        let m = envelope.middle[a];
        let springing = m - s * (m - envelope.springing[a]);
        let w = r.positions[a][2] - springing;
        let hn = h[0].hypot(h[1]);
        let offset = if hn == 0.0 { 0.0 } else { w * hn / v };
        assert!(*v > 0.0 || hn == 0.0, "support {a}: V = {v}, |H| = {hn}");
        worst = worst.max(offset - s * envelope.reach[a]);
        worst = worst.max(springing - r.positions[a][2]);
    }
    worst
}

/// The certificate recomputed from the outputs alone (tests/common), with a joint at every
/// support: every support is free, every reach finite.
fn check_certificate(mesh: &Mesh, envelope: &Envelope, r: &AssessResult, tolerance: f64) {
    let supports = mesh.anchored().iter().filter(|&&a| a).count();
    assert_eq!(r.joints.len(), supports, "a joint per free support");
    common::assess::check_certificate(mesh, envelope, r, tolerance);
}

/// The least thickness over Heyman's shells of a hemisphere `mesh` (`min_thickness_of_family`
/// from t = 0.1, scale tolerance 1e-3), converged and certified with its joints; with the
/// envelope at that thickness.
fn least_heyman_shell(mesh: &Mesh) -> (FamilyThickness, Envelope) {
    let problem = Problem::new(mesh.clone());
    let envelope_at = |t: f64| shell(mesh, |p| p[0].hypot(p[1]), t);
    let settings = AssessSettings::default();
    let family = min_thickness_of_family(&problem, envelope_at, 0.1, 1e-3, &settings).unwrap();
    assert!(family.converged, "{} rounds", family.rounds);
    let envelope = envelope_at(family.thickness).unwrap();
    check_certificate(mesh, &envelope, &family.result, 1e-6);
    (family, envelope)
}

/// Heyman's hemispherical dome over the shells 1 ± t/2 read vertically, springing plane
/// z = 0 and reach t/2 (the defaults of `from_bounds`): on a 4-ring mesh the least
/// thickness is within 10 % of 0.059, what the 6- and 10-ring meshes of these zipped rings give
/// (docs/benchmarks.md: 0.0587 and 0.0609; the continuum's 0.0449 in this convention, which
/// the radial form diagram reaches, Heyman's 0.042 in his), more
/// than twice what the vertical reading gives on the same mesh, and its certificate, the
/// joints included, holds.
#[test]
fn heyman_dome_meets_the_classical_joint() {
    let mesh = hemisphere_by_angle(4);
    let (family, envelope) = least_heyman_shell(&mesh);
    let t = family.thickness;
    for a in (0..mesh.positions().len()).filter(|&v| mesh.anchored()[v]) {
        assert_eq!(envelope.springing[a], 0.0);
        assert!((envelope.reach[a] - 0.5 * t).abs() <= 1e-12);
    }
    assert!((t - 0.059).abs() <= 0.1 * 0.059, "t_min {t}");
    let n = mesh.positions().len();
    let vertical = |t: f64| {
        let e = shell(&mesh, |p| p[0].hypot(p[1]), t)?;
        let springing = e.springing.clone();
        e.with_springing(springing, vec![f64::INFINITY; n])
    };
    let problem = Problem::new(mesh.clone());
    let settings = AssessSettings::default();
    let old = min_thickness_of_family(&problem, vertical, 0.1, 1e-3, &settings).unwrap();
    assert!(old.result.joints.is_empty());
    assert!(
        old.thickness < 0.5 * t,
        "vertical reading {}",
        old.thickness
    );
}

/// The same shells on a radial form diagram (continuous meridians and hoops, 6 rings of 16):
/// the least thickness is within 5 % of 0.0449, the continuum's value in this convention
/// (`benches/heyman_continuum.py`: the axisymmetric funicular inside the same bounds with the
/// same joint; 0.0450 on these 6 rings), where the zipped rings of `hemisphere_by_angle` stay
/// about 30 % above it. Heyman's 0.042 is for his own convention (docs/benchmarks.md).
#[test]
fn heyman_dome_on_meridians_meets_the_continuum() {
    let (family, _) = least_heyman_shell(&hemisphere_meridians(6, 16));
    let t = family.thickness;
    assert!((t / 0.0449 - 1.0).abs() <= 0.05, "t_min {t}");
}

/// At t = 0.08 R the vertical reading (reach ∞) certifies a thrust line for the
/// semicircular arch whose reaction meets the springing plane beyond t/2 (it ends high on
/// the support's vertical), and the classical joint refuses every surface: the arch needs
/// about 0.11 R (docs/benchmarks.md).
#[test]
fn the_joint_refuses_what_the_vertical_reading_certified() {
    let mesh = barrel(16, 2);
    let t = 0.08;
    let joint = shell(&mesh, |p| p[0].abs(), t).unwrap();
    let n = mesh.positions().len();
    let vertical = (joint.clone())
        .with_springing(joint.springing.clone(), vec![f64::INFINITY; n])
        .unwrap();
    let problem = Problem::new(mesh.clone());
    let settings = AssessSettings::default();
    let old = assess(&problem, &vertical, &settings, None).unwrap();
    assert!(old.feasible && old.joints.is_empty());
    let overshoot = joint_overshoot(&mesh, &joint, &old);
    assert!(
        overshoot > 0.1 * t,
        "the vertical reading's overshoot {overshoot}"
    );
    let new = assess(&problem, &joint, &settings, None).unwrap();
    assert!(
        !new.feasible,
        "a surface fits the arch of thickness {t} on its joints"
    );
    assert_eq!(new.joints.len(), 6);
    let least = min_thickness_of_family(
        &problem,
        |t| shell(&mesh, |p| p[0].abs(), t),
        t,
        1e-3,
        &settings,
    )
    .unwrap();
    assert!(least.thickness > 0.1, "t_min {}", least.thickness);
    check_certificate(
        &mesh,
        &shell(&mesh, |p| p[0].abs(), least.thickness).unwrap(),
        &least.result,
        1e-6,
    );
}

#[test]
fn bad_springing_and_reach_are_named() {
    let mesh = barrel(8, 2);
    let envelope = shell(&mesh, |p| p[0].abs(), 0.1).unwrap();
    let n = mesh.positions().len();
    let name = |r: voussoir::Result<Envelope>| match r {
        Err(Error::InvalidArgument { name, .. }) => name,
        other => panic!("expected an error, got {other:?}"),
    };
    let e = envelope.clone();
    assert_eq!(
        name(e.clone().with_springing(vec![0.0; n - 1], vec![0.0; n])),
        "springing"
    );
    assert_eq!(
        name(e.clone().with_springing(vec![0.0; n], vec![0.0; 2])),
        "reach"
    );
    let mut high = vec![0.0; n];
    high[3] = 10.0;
    assert_eq!(
        name(e.clone().with_springing(high, vec![0.0; n])),
        "springing"
    );
    let mut bad = vec![0.0; n];
    bad[0] = f64::NAN;
    assert_eq!(name(e.clone().with_springing(vec![0.0; n], bad)), "reach");
    assert_eq!(name(e.with_springing(vec![0.0; n], vec![-1.0; n])), "reach");
}
