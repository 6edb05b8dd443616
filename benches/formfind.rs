//! Form finding, nearest-shape method against the paper's loop. Prints tables; asserts nothing.
//!
//!     cargo bench --bench formfind                  # known-answer cases and the shared models
//!     cargo bench --bench formfind -- --known       # known-answer cases only
//!     cargo bench --bench formfind -- --models      # shared models only
//!     cargo bench --bench formfind -- --models cheese   # ... whose names contain "cheese"
//!     cargo bench --bench formfind -- --seeds 5     # more seeds per known-answer case
//!     cargo bench --bench formfind -- --large       # also the 97k-vertex dome
//!     cargo bench --bench formfind -- --warm        # warm re-solves only
//!     cargo bench --bench formfind -- --warm lilium # ... of the models whose names contain it
//!
//! Known-answer cases: a self-supporting vault (the truth, `generate::self_supporting`) is
//! perturbed (`generate::perturb`); the truth is a feasible answer for the perturbed input, so
//! the nearest self-supporting shape is at least as near the input as the truth is. The table
//! gives the area-weighted RMS and the largest height change of the result over the truth's.

#[path = "../tests/common/models.rs"]
mod models;

use std::time::Instant;
use voussoir::generate::{self, KnownPlan, Perturbation};
use voussoir::{
    form_find, form_find_from, FormFindResult, FormFindSettings, FormMethod, Mesh, Problem,
    QpSolver,
};

/// Area-weighted RMS and largest height difference between two position sets of `mesh`,
/// non-anchored vertices only (plan area shares as weights), computed here independently of
/// the library.
fn height_difference(mesh: &Mesh, a: &[[f64; 3]], b: &[[f64; 3]]) -> (f64, f64) {
    let mut share = vec![0.0; a.len()];
    for f in mesh.faces() {
        let [p, q, r] = f.map(|v| mesh.positions()[v as usize]);
        let area = ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])).abs() / 6.0;
        f.iter().for_each(|&v| share[v as usize] += area);
    }
    let (mut sum, mut total, mut max) = (0.0, 0.0, 0.0f64);
    for v in (0..a.len()).filter(|&v| mesh.is_non_anchored(v)) {
        let d = a[v][2] - b[v][2];
        sum += share[v] * d * d;
        total += share[v];
        max = max.max(d.abs());
    }
    ((sum / total).sqrt(), max)
}

fn method_name(m: FormMethod) -> &'static str {
    match m {
        FormMethod::Nearest => "nearest",
        FormMethod::Paper => "paper",
        _ => "other",
    }
}

fn outcome(r: &FormFindResult) -> String {
    let t = format!("{:?}", r.termination);
    t.split([' ', '{']).next().unwrap_or("").to_string()
}

fn known(seeds: u64, sizes: &[usize]) {
    println!("\nKnown-answer cases: result-to-input over truth-to-input (RMS, largest change)\n");
    println!(
        "| plan | n | change | seed | method | end | steps | s | RMS ratio | max ratio | truth RMS/diag |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let settings = FormFindSettings::default();
    let mut worst = [(0.0f64, 0.0f64); 2];
    for &n in sizes {
        for plan in KnownPlan::ALL {
            let truth = match generate::self_supporting(plan, n, &settings) {
                Ok(t) => t,
                Err(e) => {
                    println!("| {plan:?} | {n} | – | – | – | truth failed: {e} |");
                    continue;
                }
            };
            let diag = plan_diagonal(&truth);
            for kind in Perturbation::ALL {
                for seed in 0..seeds {
                    let input = generate::perturb(&truth, kind, seed);
                    let (truth_rms, truth_max) =
                        height_difference(&input, truth.positions(), input.positions());
                    for (k, method) in [FormMethod::Nearest, FormMethod::Paper]
                        .into_iter()
                        .enumerate()
                    {
                        let s = settings.clone().with_method(method);
                        let t = Instant::now();
                        let problem = Problem::new(input.clone());
                        let r = form_find(&problem, &s, None).expect("form finding");
                        let secs = t.elapsed().as_secs_f64();
                        let (rms, max) = height_difference(&input, &r.positions, input.positions());
                        let (ra, rm) = (rms / truth_rms, max / truth_max);
                        if outcome(&r) == "Converged" {
                            worst[k] = (worst[k].0.max(ra), worst[k].1.max(rm));
                        }
                        println!(
                            "| {plan:?} | {} | {kind:?} | {seed} | {} | {} | {} | {secs:.2} | {ra:.3} | {rm:.3} | {:.4} |",
                            input.positions().len(),
                            method_name(method),
                            outcome(&r),
                            r.iterations,
                            truth_rms / diag,
                        );
                    }
                }
            }
        }
    }
    println!(
        "\nworst converged ratios: nearest RMS {:.3}, max {:.3}; paper RMS {:.3}, max {:.3}",
        worst[0].0, worst[0].1, worst[1].0, worst[1].1
    );
}

fn plan_diagonal(mesh: &Mesh) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for (p, _) in mesh
        .positions()
        .iter()
        .zip(mesh.referenced())
        .filter(|(_, r)| **r)
    {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (hi[0] - lo[0]).hypot(hi[1] - lo[1])
}

/// Runs of the cold stress step timed for its median: at least `MIN_RUNS`, then more until
/// they add up to a second or number `MAX_RUNS` (one run when it takes a second or more).
const MIN_RUNS: usize = 5;
const MAX_RUNS: usize = 21;

/// One cold stress step of the input (default stress settings, no cache): median seconds and
/// the QP iterations of the last run.
fn cold_step(problem: &Problem) -> (f64, u32) {
    let settings = FormFindSettings::default().stress;
    let mut seconds = Vec::new();
    loop {
        let t = Instant::now();
        let r = voussoir::analyse(problem, &settings).expect("valid problem");
        seconds.push(t.elapsed().as_secs_f64());
        let total: f64 = seconds.iter().sum();
        let enough = seconds.len() >= MIN_RUNS && (total >= 1.0 || seconds.len() == MAX_RUNS);
        if enough || seconds[0] >= 1.0 {
            seconds.sort_by(f64::total_cmp);
            return (seconds[seconds.len() / 2], r.iterations);
        }
    }
}

/// "n native, m clarabel" over the stress steps of a form finding.
fn solver_counts(r: &FormFindResult) -> String {
    let native = r.solvers.iter().filter(|s| **s == QpSolver::Native).count();
    let other = r.solvers.len() - native;
    if other == 0 {
        format!("{native} native")
    } else {
        format!("{native} native, {other} clarabel")
    }
}

/// The models of the form-finding table: the shared ones (when found), the generated
/// Cas-size stand-in and, with `--large`, the 97k-vertex dome.
fn model_list(large: bool) -> Vec<(String, Problem)> {
    let mut list = Vec::new();
    if let Some(dir) = models::models_dir() {
        for name in models::MODELS {
            let problem = models::read_shared(&dir, name).expect("model");
            list.push((name.to_string(), problem));
        }
    }
    let mut generated = vec![5951];
    if large {
        generated.push(100_000);
    }
    for n in generated {
        let mesh = generate::dome_with_hole(n).expect("dome");
        let name = format!("gen. dome_with_hole {}", mesh.positions().len());
        list.push((name, Problem::new(mesh)));
    }
    list
}

fn models(large: bool, only: Option<&str>) {
    println!("\nForm finding, default settings (distances over the plan diagonal; \"/ cold\": the form finding's time over one cold stress step of the input)\n");
    println!("| model | V | cold step s (QP its) | method | end | steps | QP its | from last answer | solvers | s | / cold | Hausdorff | L2 | RMS change | max change |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (name, problem) in model_list(large) {
        if only.is_some_and(|o| !name.contains(o)) {
            continue;
        }
        let (cold, cold_its) = cold_step(&problem);
        for method in [FormMethod::Nearest, FormMethod::Paper] {
            let s = FormFindSettings::default().with_method(method);
            let t = Instant::now();
            let r = form_find(&problem, &s, None).expect("form finding");
            let secs = t.elapsed().as_secs_f64();
            let its: u32 = r.qp_iterations.iter().sum();
            let warm = r.qp_iterations.iter().filter(|&&k| k == 0).count();
            println!(
                "| {name} | {} | {cold:.4} ({cold_its}) | {} | {} | {} | {its} | {warm} | {} | {secs:.2} | {:.1} | {:.4} | {:.4} | {:.4} | {:.4} |",
                problem.mesh.positions().len(),
                method_name(method),
                outcome(&r),
                r.iterations,
                solver_counts(&r),
                secs / cold,
                r.hausdorff,
                r.l2,
                r.rms_change,
                r.max_change,
            );
            if name == "lilium" {
                println!("|   lilium | | | | normalised Hausdorff {:.4} (the paper: 0.04975) | | | | | | | | | | |", r.hausdorff);
            }
        }
    }
}

/// The two edits of the warm table: the central vertex raised by 1% of the plan diagonal, and
/// one more support (the lowest-numbered free vertex beside one).
fn edits(problem: &Problem) -> [(&'static str, Problem); 2] {
    let mesh = &problem.mesh;
    let v = models::central_vertex(mesh);
    let mut heights: Vec<f64> = mesh.positions().iter().map(|p| p[2]).collect();
    heights[v] += 0.01 * plan_diagonal(mesh);
    let mut moved = problem.clone();
    moved.mesh = mesh.clone().with_heights(&heights).expect("heights");
    let s = (0..mesh.positions().len())
        .find(|&v| {
            mesh.is_non_anchored(v)
                && mesh.edges_at(v).iter().any(|&e| {
                    let [a, b] = mesh.edges()[e as usize].v;
                    mesh.anchored()[a as usize] || mesh.anchored()[b as usize]
                })
        })
        .expect("a free vertex beside a support");
    let mut anchored = mesh.anchored_ids();
    anchored.push(s as u32);
    let mut supported = problem.clone();
    supported.mesh =
        Mesh::new(mesh.positions().to_vec(), mesh.faces().to_vec(), &anchored).expect("mesh");
    [("1% vertex", moved), ("+1 support", supported)]
}

/// Warm re-solves (`form_find_from`) from the cold answer after each edit, against a cold
/// form finding of the edited problem: seconds over one cold stress step of the input, stress
/// steps and RMS changes.
fn warm(large: bool, only: Option<&str>) {
    println!("\nWarm re-solve after an edit, default settings (\"/ cold step\": seconds over one cold stress step of the input)\n");
    println!("| model | V | cold step s | edit | warm end | warm steps | warm solvers | warm s | warm / cold step | cold steps | cold / cold step | warm RMS | cold RMS |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let s = FormFindSettings::default();
    for (name, problem) in model_list(large) {
        if only.is_some_and(|o| !name.contains(o)) {
            continue;
        }
        let (cold_step, _) = cold_step(&problem);
        let previous = form_find(&problem, &s, None).expect("form finding");
        for (edit, edited) in edits(&problem) {
            let t = Instant::now();
            let w = form_find_from(&edited, &s, &previous, None).expect("warm re-solve");
            let warm_s = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let c = form_find(&edited, &s, None).expect("form finding");
            let cold_s = t.elapsed().as_secs_f64();
            println!(
                "| {name} | {} | {cold_step:.4} | {edit} | {} | {} | {} | {warm_s:.2} | {:.1} | {} | {:.1} | {:.4} | {:.4} |",
                problem.mesh.positions().len(),
                outcome(&w),
                w.iterations,
                solver_counts(&w),
                warm_s / cold_step,
                c.iterations,
                cold_s / cold_step,
                w.rms_change,
                c.rms_change,
            );
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let has = |f: &str| args.iter().any(|a| a == f);
    let seeds = args
        .iter()
        .position(|a| a == "--seeds")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(2);
    if let Some(i) = args.iter().position(|a| a == "--warm") {
        let only = args.get(i + 1).filter(|a| !a.starts_with("--"));
        warm(has("--large"), only.map(String::as_str));
        return;
    }
    let (only_known, only_models) = (has("--known"), has("--models"));
    let only = (args.iter().position(|a| a == "--models"))
        .and_then(|i| args.get(i + 1))
        .filter(|a| !a.starts_with("--"));
    if !only_models {
        known(seeds, &[400, 1500]);
    }
    if !only_known {
        models(has("--large"), only.map(String::as_str));
        warm(has("--large"), only.map(String::as_str));
    }
}
