//! Inputs at the edges of what double precision carries: models in extreme units either give
//! the scaled answer (every reported figure finite) or are rejected with a message saying that
//! they cannot be represented; weightless problems are rejected as having nothing to balance.

mod common;
use common::polar_cap;
use voussoir::*;

/// The 45° polar cap (rim anchored) with every coordinate multiplied by `s`.
fn scaled_cap(s: f64) -> Result<Mesh> {
    let cap = polar_cap(4, 45f64.to_radians());
    let positions = cap.positions().iter().map(|p| p.map(|c| c * s)).collect();
    let anchored: Vec<u32> = (0..cap.n_vertices() as u32)
        .filter(|&v| cap.anchored()[v as usize])
        .collect();
    Mesh::new(positions, cap.faces().to_vec(), &anchored)
}

fn analysed(s: f64) -> Result<StressResult> {
    analyse(&Problem::new(scaled_cap(s)?), &StressSettings::default())
}

fn all_finite(r: &StressResult) -> bool {
    let scalars = [r.eps_inf, r.objective];
    let arrays = [
        &r.force_densities,
        &r.loads,
        &r.residuals,
        &r.airy,
        &r.weights,
        &r.tau,
    ];
    scalars.iter().all(|x| x.is_finite()) && arrays.iter().all(|a| a.iter().all(|x| x.is_finite()))
}

/// Powers of two far from 1 give the unit answer scaled: the same ε∞, the objective times s⁴.
#[test]
fn extreme_but_representable_units_give_the_scaled_answer() {
    let unit = analysed(1.0).unwrap();
    for e in [-200, 200] {
        let s = 2f64.powi(e);
        let r = analysed(s).unwrap_or_else(|err| panic!("2^{e}: {err}"));
        assert!(r.status.is_solved(), "2^{e}: {:?}", r.status);
        assert!(all_finite(&r), "2^{e}: a non-finite figure");
        assert!(
            (r.eps_inf - unit.eps_inf).abs() <= 1e-9 * unit.eps_inf.max(1e-12),
            "2^{e}: ε∞ {} against {}",
            r.eps_inf,
            unit.eps_inf
        );
        let objective = unit.objective * s.powi(4);
        assert!(
            (r.objective - objective).abs() <= 1e-6 * objective,
            "2^{e}: objective {:e} against {objective:e}",
            r.objective
        );
    }
}

/// Loads whose squares overflow or underflow (coordinates of 1e78 or 1e-100: areas and loads
/// of 1e156 or 1e-200) are rejected by the solve, coordinates of 1e200 by the mesh itself.
#[test]
fn unrepresentable_units_are_rejected_saying_so() {
    for s in [1e78, 1e-100] {
        let err = analysed(s).expect_err("accepted");
        let text = err.to_string();
        assert!(
            matches!(err, Error::InvalidArgument { name: "loads", .. })
                && text.contains("cannot be represented in double precision"),
            "×{s:e}: {text}"
        );
        let mesh = scaled_cap(s).unwrap();
        let found = form_find(&Problem::new(mesh), &FormFindSettings::default(), None);
        assert!(found.is_err(), "×{s:e}: form finding accepted it");
    }
    let err = scaled_cap(1e200).expect_err("accepted");
    let text = err.to_string();
    assert!(
        matches!(
            err,
            Error::InvalidArgument {
                name: "positions",
                ..
            }
        ) && text.contains("cannot be represented in double precision")
            && text.contains("vertex"),
        "{text}"
    );
    let err = scaled_cap(1e-160).expect_err("accepted");
    assert!(err.to_string().contains("cannot be represented"), "{err}");
}

/// Density 0 everywhere and no extra load: nothing to balance, said so (not a silent ε∞
/// relative to an invented unit load); weight on some faces only is fine.
#[test]
fn a_weightless_problem_is_rejected() {
    let mesh = scaled_cap(1.0).unwrap();
    let n_faces = mesh.n_faces();
    let weightless = Problem::new(mesh.clone())
        .with_face_density(vec![0.0; n_faces])
        .unwrap();
    let err = analyse(&weightless, &StressSettings::default()).expect_err("accepted");
    assert!(
        matches!(err, Error::InvalidArgument { name: "loads", .. })
            && err.to_string().contains("no weight to balance"),
        "{err}"
    );
    assert!(form_find(&weightless, &FormFindSettings::default(), None).is_err());
    let lifted = Problem::new(mesh.clone())
        .with_face_density(vec![0.0; n_faces])
        .unwrap()
        .with_extra_loads(vec![-1.0; mesh.n_vertices()])
        .unwrap();
    let err = analyse(&lifted, &StressSettings::default()).expect_err("accepted");
    assert!(err.to_string().contains("upwards"), "{err}");
    let mut half = vec![0.0; n_faces];
    half.iter_mut().step_by(2).for_each(|d| *d = 1.0);
    let partly = Problem::new(mesh).with_face_density(half).unwrap();
    assert!(analyse(&partly, &StressSettings::default()).is_ok());
}
