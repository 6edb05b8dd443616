mod common;
use voussoir::*;
#[test]
fn scratch() {
    for name in ["four_holes", "hex", "cheese"] {
    let mesh = common::load_model(name).unwrap();
    let pb = Problem::new(mesh);
    for f in [Formulation::Reduced, Formulation::EdgeBased] {
    for holes in [HoleMode::Constant, HoleMode::Affine] { for tau in [TauMode::Optimized, TauMode::Zero] {
        let r = analyse(&pb, &StressSettings { holes, tau, formulation: f, ..Default::default() }).unwrap();
        println!("{name} {f:?} {holes:?} {tau:?}: {:?} it={} obj={:e} eps={:.3e}", r.status, r.iterations, r.objective, r.eps_inf);
    }}}}
}
