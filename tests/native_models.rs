//! Every stress step of a default form finding of the nine shared models is answered by the
//! native interior-point solver: none falls back to clarabel (docs/solver.md §5).
//!
//! The models are required here whatever the environment says: a missing folder fails the
//! test instead of letting it pass without checking anything. The nine form findings take
//! about 10 s in a debug build and 7 s in a release one.

mod common;
use common::{find_models, MODELS};
use std::path::PathBuf;
use voussoir::{form_find, FormFindSettings, QpSolver, Termination};

/// The shared models' folder (`common::models_dir`'s), required: panics when it is absent.
fn shared_models() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data/models");
    find_models(dir, true).expect("required")
}

#[test]
fn default_form_finding_of_every_shared_model_is_answered_by_the_native_solver() {
    let dir = shared_models();
    let settings = FormFindSettings::default();
    let mut fallbacks = Vec::new();
    for name in MODELS {
        let problem = common::read_shared(&dir, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        let r = form_find(&problem, &settings, None).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(r.termination, Termination::Converged, "{name}");
        assert_eq!(r.solvers.len(), r.iterations, "{name}");
        let steps: Vec<usize> = (0..r.solvers.len())
            .filter(|&k| r.solvers[k] != QpSolver::Native)
            .collect();
        println!(
            "{name}: {} steps, QP iterations {:?}, clarabel at steps {steps:?}",
            r.iterations, r.qp_iterations
        );
        if !steps.is_empty() {
            fallbacks.push((name, steps));
        }
    }
    assert!(
        fallbacks.is_empty(),
        "stress steps answered by clarabel (model, step indices): {fallbacks:?}"
    );
}
