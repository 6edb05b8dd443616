//! A model lifted by 10⁷ (heights in a survey's datum, say) form-finds as it does where it is:
//! the solvers take heights relative to the supports, so the lift costs only the digits the
//! returned heights themselves cannot hold.

mod common;
use common::load_model;
use voussoir::{form_find, FormFindSettings, Mesh, Problem, Termination};

const LIFT: f64 = 1e7;

fn lifted(mesh: &Mesh) -> Mesh {
    let z: Vec<f64> = mesh.positions().iter().map(|p| p[2] + LIFT).collect();
    mesh.clone().with_heights(&z).unwrap()
}

/// hex and vault_pq lifted by 10⁷ converge (they stalled at ε∞ 7e-6 and 1.4e-6) to the shape
/// found where they are, to 1e-5 of the plan diagonal, with the same height change.
#[test]
fn shared_models_lifted_by_ten_million_converge_to_the_same_shape() {
    for name in ["hex", "vault_pq"] {
        let Some(mesh) = load_model(name) else { return };
        let settings = FormFindSettings::default();
        let here = form_find(&Problem::new(mesh.clone()), &settings, None).unwrap();
        let up = form_find(&Problem::new(lifted(&mesh)), &settings, None).unwrap();
        assert_eq!(here.termination, Termination::Converged, "{name}");
        assert_eq!(up.termination, Termination::Converged, "{name}: lifted");
        let (lo, hi) = mesh.positions().iter().fold(
            ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
            |(lo, hi), p| {
                (
                    [lo[0].min(p[0]), lo[1].min(p[1])],
                    [hi[0].max(p[0]), hi[1].max(p[1])],
                )
            },
        );
        let diagonal = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
        let apart = (here.positions.iter().zip(&up.positions))
            .map(|(a, b)| (b[2] - LIFT - a[2]).abs() / diagonal)
            .fold(0.0, f64::max);
        assert!(
            apart <= 1e-5,
            "{name}: lifted shape {apart:e} diagonals apart"
        );
        // The changes agree as the shapes do: to 1e-5 of the plan diagonal.
        assert!(
            (here.max_change - up.max_change).abs() <= 1e-5 * diagonal
                && (here.rms_change - up.rms_change).abs() <= 1e-5 * diagonal,
            "{name}: changes {} {} against {} {}",
            here.max_change,
            here.rms_change,
            up.max_change,
            up.rms_change
        );
    }
}
