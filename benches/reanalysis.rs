//! Re-analysis of form-found shapes: each shared model is form-found with default settings,
//! written as OBJ, read back and analysed afresh by each formulation and solver. Prints a
//! table; asserts nothing.
//!
//!     cargo bench --bench reanalysis                      # every shared model
//!     cargo bench --bench reanalysis -- four_holes cheese # some of them
//!
//! The form-found forces certify ε∞ < 1e-6 at the written heights, and they are feasible for
//! the fresh stress QP (same plan, loads, bounds), so its optimum has Σ r² no larger than
//! theirs: a fresh answer whose Σ r² (column "Σr²/p̄²") exceeds the form finding's stopped
//! short of the optimum. ε∞ and the horizontal imbalance (largest, over p̄) are recomputed here
//! from the returned positions and force densities.

#[path = "../tests/common/models.rs"]
mod models;

use std::path::Path;
use voussoir::{
    analyse, form_find, io, FormFindSettings, Formulation, Problem, QpSolver, StressResult,
    StressSettings,
};

/// ε∞, largest horizontal imbalance and Σ r², all over powers of p̄, recomputed from the
/// positions, force densities, loads and external forces of `s`.
fn certificate(problem: &Problem, x: &[[f64; 3]], s: &StressResult) -> (f64, f64, f64) {
    let mesh = &problem.mesh;
    let q = &s.force_densities;
    let n = x.len();
    let (mut rv, mut rh) = (vec![0.0; n], vec![[0.0; 2]; n]);
    for (e, edge) in mesh.edges().iter().enumerate() {
        let [i, j] = edge.v.map(|v| v as usize);
        for (a, b) in [(i, j), (j, i)] {
            rv[a] += q[e] * (x[a][2] - x[b][2]);
            rh[a][0] += q[e] * (x[a][0] - x[b][0]);
            rh[a][1] += q[e] * (x[a][1] - x[b][1]);
        }
    }
    let free: Vec<usize> = (0..n)
        .filter(|&v| mesh.referenced()[v] && !mesh.anchored()[v])
        .collect();
    let p_bar = free.iter().map(|&v| s.loads[v]).sum::<f64>() / free.len() as f64;
    let (mut eps, mut h, mut sum) = (0.0f64, 0.0f64, 0.0);
    for &v in &free {
        let r = (rv[v] - s.loads[v]) / p_bar;
        eps = eps.max(r.abs());
        sum += r * r;
        let ext = s.external_horizontal[v];
        h = h.max((rh[v][0] + ext[0]).abs().max((rh[v][1] + ext[1]).abs()) / p_bar);
    }
    (eps, h, sum)
}

fn row(label: &str, how: &str, problem: &Problem, x: &[[f64; 3]], s: &StressResult) {
    let (eps, h, sum) = certificate(problem, x, s);
    println!(
        "| {label} | {how} | {:?} | {:?} {:?} | {} | {eps:.2e} | {h:.2e} | {sum:.2e} | {:.3} |",
        s.status, s.solver, s.formulation, s.iterations, s.seconds
    );
}

fn settings(solver: QpSolver, formulation: Formulation) -> StressSettings {
    let mut s = StressSettings::default();
    s.solver = solver;
    s.formulation = formulation;
    s
}

fn main() {
    let Some(dir) = models::models_dir() else {
        println!("skipped: the shared models were not found");
        return;
    };
    let asked: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let out = std::env::temp_dir().join(format!("voussoir-reanalysis-{}", std::process::id()));
    std::fs::create_dir_all(&out).expect("temporary folder");
    println!("| model | answer | status | solver | its | ε∞ | horizontal | Σr²/p̄² | s |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for name in models::MODELS
        .iter()
        .filter(|m| asked.is_empty() || asked.iter().any(|a| a == *m))
    {
        let supports = dir.join(format!("{name}.json"));
        let problem = models::read_shared(&dir, name).expect(name);
        let r = form_find(&problem, &FormFindSettings::default(), None).expect(name);
        let clarabel = r
            .solvers
            .iter()
            .filter(|&&s| s == QpSolver::Clarabel)
            .count();
        let how = format!(
            "form finding: {:?}, {} steps, {clarabel} by clarabel",
            r.termination, r.iterations
        );
        row(name, &how, &problem, &r.positions, &r.stress);
        let path = out.join(format!("{name}.obj"));
        io::write_obj(&path, &r.positions, problem.mesh.faces()).expect("written");
        let back = io::load_model(Path::new(&path), &supports).expect("read back");
        let x = &back.mesh.positions();
        for (how, solver, formulation) in [
            ("afresh, default", QpSolver::Native, Formulation::Reduced),
            (
                "afresh, edge-based native",
                QpSolver::Native,
                Formulation::EdgeBased,
            ),
            (
                "afresh, reduced clarabel",
                QpSolver::Clarabel,
                Formulation::Reduced,
            ),
            (
                "afresh, edge-based clarabel",
                QpSolver::Clarabel,
                Formulation::EdgeBased,
            ),
        ] {
            let s = analyse(&back, &settings(solver, formulation)).expect(name);
            row(name, how, &back, x, &s);
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}
