//! A search that stalls proves nothing: where the compression-only search stalls at a
//! thick envelope (a region left without stress), the analysis runs again from a surface
//! certified for a stricter problem, so a thicker envelope never loses the surface a
//! thinner one holds (docs/method.md §16.3).

mod common;

use common::assess::check_certificate;
use voussoir::io::{read_model, ReadOptions, Supports};
use voussoir::{
    assess, AssessSettings, Envelope, Mesh, Objective, Problem, Termination, Thickness,
};

/// A hemispherical cap of eight rings of twenty vertices, odd rings turned by half a step,
/// as a generator wrote it; its rim is anchored.
fn ring_dome() -> Mesh {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/assess_data/ring_dome_8x20.obj"
    );
    let options = ReadOptions::new(Supports::Boundary);
    read_model(std::path::Path::new(path), &options)
        .unwrap()
        .problem
        .mesh
}

fn analyse(mesh: &Mesh, t: f64, objective: Objective) -> (Envelope, voussoir::AssessResult) {
    let envelope = Envelope::from_thickness(mesh, &Thickness::Uniform(t)).unwrap();
    let settings = AssessSettings::default().with_objective(objective);
    let result = assess(&Problem::new(mesh.clone()), &envelope, &settings, None).unwrap();
    (envelope, result)
}

/// The surface a 0.4 envelope holds lies inside the 1.0 envelope about the same middle
/// surface (with the weight 2.5 times, the forces 2.5 times): the thick envelope is certified
/// too.
#[test]
fn a_thick_envelope_holds_a_thrust_surface_where_a_thinner_one_does() {
    let mesh = ring_dome();
    let (envelope, thick) = analyse(&mesh, 1.0, Objective::Fit);
    check_certificate(&mesh, &envelope, &thick, 1e-6);
}

/// The least thickness does not depend on the thickness given (self-weight scales with it,
/// and so do the forces of every surface), below the least thickness (0.05: no surface fits
/// the given envelope) or above it, and each search converges.
#[test]
fn the_least_thickness_does_not_depend_on_the_thickness_given() {
    let mesh = ring_dome();
    let t_min: Vec<f64> = [0.05, 0.4, 1.0]
        .iter()
        .map(|&t| {
            let (envelope, r) = analyse(&mesh, t, Objective::MinThickness);
            check_certificate(&mesh, &envelope, &r, 1e-6);
            assert_eq!(r.termination, Termination::Converged, "t = {t}");
            r.thickness_scale * t
        })
        .collect();
    for t in &t_min[1..] {
        assert!((t - t_min[0]).abs() <= 1e-3 * t_min[0], "t_min {t_min:?}");
    }
}
