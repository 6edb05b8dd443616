//! The paper's timing table (de Goes et al. 2013, Figure 7.7) with our figures beside it, every
//! shared model, then scaling to 100k vertices. Prints tables; asserts nothing.
//!
//!     cargo bench --bench stress              # the paper's rows, the shared models, scaling to 50k
//!     cargo bench --bench stress -- --large   # also 100k vertices
//!     cargo bench --bench stress -- --large --large-ff   # and the whole form finding at 100k
//!
//! Every paper row's stress step is timed four ways: reduced (de Goes) and edge-based (VHWP12)
//! unknowns, each with the native structured interior-point solver and with clarabel (the
//! reference); every shared model and every scaling dome in both formulations with the native
//! solver. Steps under a second are timed as the median of 5–21 runs (see `MIN_RUNS`); a step
//! that did not end `Solved` shows its status and gets no ratio.
//! Rows without a shared model use generated stand-ins of the paper's size and kind.

#[path = "../tests/common/models.rs"]
mod models;

use std::path::Path;
use std::time::Instant;
use voussoir::generate::{self, Domain};
use voussoir::{
    analyse, form_find, FormFindSettings, Formulation, Mesh, Problem, QpSolver, StressSettings,
    StressStatus,
};

/// Peak resident memory of this process so far, in MiB.
fn peak_rss_mib() -> f64 {
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: getrusage writes into the struct we own.
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    usage.ru_maxrss as f64 / 1024.0
}

/// Target triangle area for about `n` vertices on a domain of plan area `area`.
fn max_area(area: f64, n: usize) -> f64 {
    1.6 * area / (2.0 * n as f64)
}

/// A spherical dome over the unit disk with an off-centre free hole; rim anchored.
fn dome_with_hole(n: usize) -> Mesh {
    generate::dome_with_hole(n).expect("dome")
}

/// A barrel vault over 2 × 3 whose crown is shifted off the centre line, anchored along its
/// long sides, gables free.
fn shifted_barrel_vault(n: usize) -> Mesh {
    let k = ((n as f64) / 6.0).sqrt();
    let domain = Domain {
        outer: generate::rectangle(-1.0, -1.5, 1.0, 1.5, (2.0 * k) as usize, (3.0 * k) as usize),
        holes: vec![],
    };
    let (p, t) = generate::triangulate(&domain, max_area(6.0, n)).expect("domain");
    generate::lift(
        &p,
        &t,
        |u| (1.3f64 * 1.3 - (u[0] - 0.2).powi(2)).sqrt() - 0.5,
        |u, _| (u[0].abs() - 1.0).abs() < 1e-9,
    )
    .expect("barrel vault")
}

/// A groin vault: two crossing barrels over the square [−1, 1]², the lower of the two at each
/// point; boundary anchored.
fn groin_vault(n: usize) -> Mesh {
    let k = (n as f64).sqrt();
    let domain = Domain {
        outer: generate::rectangle(-1.0, -1.0, 1.0, 1.0, k as usize, k as usize),
        holes: vec![],
    };
    let (p, t) = generate::triangulate(&domain, max_area(4.0, n)).expect("domain");
    let barrel = |s: f64| (1.2f64 * 1.2 - s * s).sqrt() - (1.2f64 * 1.2 - 1.0).sqrt();
    generate::lift(&p, &t, |u| barrel(u[0]).min(barrel(u[1])), |_, outer| outer)
        .expect("groin vault")
}

/// A 40° cap dome whose faces within half the radius carry five times the load.
fn variable_load_dome(n: usize) -> Problem {
    let domain = Domain {
        outer: generate::circle([0.0, 0.0], 1.0, ((n as f64).sqrt() * 3.5) as usize),
        holes: vec![],
    };
    let (p, t) = generate::triangulate(&domain, max_area(std::f64::consts::PI, n)).expect("domain");
    let mesh = generate::lift(
        &p,
        &t,
        |u| generate::spherical_cap(1.0, 0.7, u[0].hypot(u[1])),
        |_, outer| outer,
    )
    .expect("dome");
    let mut problem = Problem::new(mesh);
    for (f, face) in problem.mesh.faces().iter().enumerate() {
        let c = face.iter().fold([0.0, 0.0], |c, &v| {
            let p = problem.mesh.positions()[v as usize];
            [c[0] + p[0] / 3.0, c[1] + p[1] / 3.0]
        });
        if c[0].hypot(c[1]) < 0.5 {
            problem.face_density[f] = 5.0;
        }
    }
    problem
}

/// Runs of a stress step timed for its median when one run takes less than a second: at least
/// `MIN_RUNS`, then more until the runs add up to a second or number `MAX_RUNS`, because single
/// runs of a short step spread widely on a shared machine.
const MIN_RUNS: usize = 5;
const MAX_RUNS: usize = 21;

/// One stress step as timed: the median seconds over its runs (one run when it takes a second
/// or more; see `MIN_RUNS`), and the last run's QP iterations, solver and status.
#[derive(Clone, Copy)]
struct Step {
    seconds: f64,
    iterations: u32,
    solver: QpSolver,
    status: StressStatus,
}

fn step(problem: &Problem, formulation: Formulation, solver: QpSolver) -> Step {
    let settings = StressSettings::default()
        .with_formulation(formulation)
        .with_solver(solver);
    let mut seconds = Vec::new();
    loop {
        let t = Instant::now();
        let r = analyse(problem, &settings).expect("valid problem");
        seconds.push(t.elapsed().as_secs_f64());
        let total: f64 = seconds.iter().sum();
        let enough = seconds.len() >= MIN_RUNS && (total >= 1.0 || seconds.len() == MAX_RUNS);
        if enough || seconds[0] >= 1.0 {
            seconds.sort_by(f64::total_cmp);
            return Step {
                seconds: seconds[seconds.len() / 2],
                iterations: r.iterations,
                solver: r.solver,
                status: r.status,
            };
        }
    }
}

/// "seconds (iterations)"; a native step that fell back to clarabel is marked with *, and a
/// step that did not end `Solved` names its status, so that its time is not read as a
/// solve's.
fn cell(step: Step, native: bool) -> String {
    let mark = if native && step.solver != QpSolver::Native {
        "*"
    } else {
        ""
    };
    let status = if step.status == StressStatus::Solved {
        String::new()
    } else {
        format!(", {:?}", step.status)
    };
    format!("{:.3}{mark} ({}{status})", step.seconds, step.iterations)
}

/// `value` with `decimals` decimals, or "—" when any of `steps` did not end `Solved` (a time
/// that is not a solve's makes no ratio).
fn if_solved(value: f64, decimals: usize, steps: &[Step]) -> String {
    if steps.iter().all(|s| s.status == StressStatus::Solved) {
        format!("{value:.decimals$}")
    } else {
        "—".to_string()
    }
}

/// A row of the paper's table: (name, V;E;F, VHWP12 s, de Goes s).
struct PaperRow {
    name: &'static str,
    size: &'static str,
    vhwp12: f64,
    de_goes: f64,
}

const PAPER: [PaperRow; 11] = [
    PaperRow {
        name: "Cheese-model",
        size: "2348;6218;3832",
        vhwp12: 13.078,
        de_goes: 9.8,
    },
    PaperRow {
        name: "Free vault",
        size: "360;1000;640",
        vhwp12: 0.387,
        de_goes: 0.18,
    },
    PaperRow {
        name: "Dome with doors",
        size: "577;1600;1024",
        vhwp12: 0.877,
        de_goes: 0.368,
    },
    PaperRow {
        name: "Video-surface",
        size: "1131;3194;2064",
        vhwp12: 3.55,
        de_goes: 0.98,
    },
    PaperRow {
        name: "Cas-model",
        size: "5951;17472;11520",
        vhwp12: 90.1,
        de_goes: 18.0,
    },
    PaperRow {
        name: "Lilium",
        size: "1201;3504;2304",
        vhwp12: 4.136,
        de_goes: 0.887,
    },
    PaperRow {
        name: "Variable load",
        size: "1156;3368;2213",
        vhwp12: 3.65,
        de_goes: 0.77,
    },
    PaperRow {
        name: "Shifted barrel vault",
        size: "310;836;527",
        vhwp12: 0.24,
        de_goes: 0.15,
    },
    PaperRow {
        name: "Moebius igloo",
        size: "702;2006;1304",
        vhwp12: 1.3,
        de_goes: 0.4,
    },
    PaperRow {
        name: "Dome with hole",
        size: "1656;4842;3186",
        vhwp12: 7.7,
        de_goes: 1.5,
    },
    PaperRow {
        name: "Groin vault",
        size: "2943;8569;5627",
        vhwp12: 23.6,
        de_goes: 4.1,
    },
];

/// Our model for a paper row: the shared model where there is one, else a generated stand-in
/// ("gen."), else none (no model of that kind).
fn model_for(row: &PaperRow, dir: Option<&Path>) -> Option<(String, Problem)> {
    let shared = |name: &str| dir.and_then(|d| models::read_shared(d, name).ok());
    let generated = |p: Problem| Some(("gen.".to_string(), p));
    match row.name {
        "Cheese-model" => shared("cheese").map(|p| ("cheese".to_string(), p)),
        "Free vault" => shared("free_vault").map(|p| ("free_vault".to_string(), p)),
        "Dome with doors" => shared("dome_with_doors").map(|p| ("dome_with_doors".to_string(), p)),
        "Lilium" => shared("lilium").map(|p| ("lilium".to_string(), p)),
        "Cas-model" => generated(Problem::new(dome_with_hole(5951))),
        "Variable load" => generated(variable_load_dome(1156)),
        "Shifted barrel vault" => generated(Problem::new(shifted_barrel_vault(310))),
        "Dome with hole" => generated(Problem::new(dome_with_hole(1656))),
        "Groin vault" => generated(Problem::new(groin_vault(2943))),
        _ => None,
    }
}

fn paper_table(dir: Option<&Path>) {
    println!(
        "Stress step (seconds, QP iterations in brackets; * = native solver fell back to clarabel)"
    );
    println!();
    println!("| paper row | V;E;F (paper) | ours | V;E;F (ours) | reduced native | reduced clarabel | edge native | edge clarabel | edge/reduced native | edge/reduced clarabel | paper dG / VHWP12 | × faster than paper dG | form finding its, s |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for row in &PAPER {
        let Some((ours, problem)) = model_for(row, dir) else {
            println!(
                "| {} | {} | — (no model of this kind) | | | | | | | | {} / {} | | |",
                row.name, row.size, row.de_goes, row.vhwp12
            );
            continue;
        };
        let m = &problem.mesh;
        let size = format!(
            "{};{};{}",
            m.positions().len(),
            m.edges().len(),
            m.faces().len()
        );
        let rn = step(&problem, Formulation::Reduced, QpSolver::Native);
        let rc = step(&problem, Formulation::Reduced, QpSolver::Clarabel);
        let en = step(&problem, Formulation::EdgeBased, QpSolver::Native);
        let ec = step(&problem, Formulation::EdgeBased, QpSolver::Clarabel);
        let t = Instant::now();
        let ff = form_find(&problem, &FormFindSettings::default(), None).expect("valid problem");
        let ff_s = t.elapsed().as_secs_f64();
        println!(
            "| {} | {} | {ours} | {size} | {} | {} | {} | {} | {} | {} | {} / {} | {} | {} ({:?}), {ff_s:.2} |",
            row.name,
            row.size,
            cell(rn, true),
            cell(rc, false),
            cell(en, true),
            cell(ec, false),
            if_solved(en.seconds / rn.seconds, 1, &[en, rn]),
            if_solved(ec.seconds / rc.seconds, 1, &[ec, rc]),
            row.de_goes,
            row.vhwp12,
            if_solved(row.de_goes / rn.seconds, 0, &[rn]),
            ff.iterations,
            ff.termination,
        );
    }
}

/// Every shared model, reduced and edge-based side by side (native solver, default settings).
fn shared_models_table(dir: &Path) {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(|e| {
                    let path = e.ok()?.path();
                    let name = path.file_stem()?.to_str()?.to_string();
                    (path.extension()? == "obj" && dir.join(format!("{name}.json")).is_file())
                        .then_some(name)
                })
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    println!();
    println!(
        "Stress step on every shared model, native solver (seconds, QP iterations in brackets)"
    );
    println!();
    println!("| model | V;E;F | holes | reduced | edge-based | edge/reduced |");
    println!("|---|---|---|---|---|---|");
    for name in names {
        let Some(problem) = models::read_shared(dir, &name).ok() else {
            println!("| {name} | could not be read | | | | |");
            continue;
        };
        let m = &problem.mesh;
        let rn = step(&problem, Formulation::Reduced, QpSolver::Native);
        let en = step(&problem, Formulation::EdgeBased, QpSolver::Native);
        println!(
            "| {name} | {};{};{} | {} | {} | {} | {} |",
            m.positions().len(),
            m.edges().len(),
            m.faces().len(),
            m.holes().count(),
            cell(rn, true),
            cell(en, true),
            if_solved(en.seconds / rn.seconds, 1, &[en, rn]),
        );
    }
}

/// Least-squares slope of log(t) against log(n).
fn exponent(points: &[(f64, f64)]) -> f64 {
    let k = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (n, t)| (a + n.ln(), b + t.ln()));
    let (mx, my) = (sx / k, sy / k);
    let (num, den) = points.iter().fold((0.0, 0.0), |(a, b), (n, t)| {
        (a + (n.ln() - mx) * (t.ln() - my), b + (n.ln() - mx).powi(2))
    });
    num / den
}

fn scaling(large: bool, large_ff: bool) {
    let sizes: &[usize] = if large {
        &[10_000, 50_000, 100_000]
    } else {
        &[10_000, 50_000]
    };
    println!();
    println!("Scaling: generated domes with a free hole, reduced unknowns, native solver");
    println!();
    println!("| V | E | stress step s (QP its) | solver | peak RSS after step MiB | form finding its, s |");
    println!("|---|---|---|---|---|---|");
    let mut points = Vec::new();
    let mut reduced = Vec::new();
    for &n in sizes {
        let problem = Problem::new(dome_with_hole(n));
        let v = problem.mesh.positions().len();
        let rn = step(&problem, Formulation::Reduced, QpSolver::Native);
        let rss = peak_rss_mib();
        points.push((v as f64, rn.seconds));
        reduced.push(rn);
        // The whole loop only where asked for: it dominates the run at 100k.
        let ff = if large_ff && n == *sizes.last().expect("sizes") {
            let t = Instant::now();
            let r = form_find(&problem, &FormFindSettings::default(), None).expect("valid");
            format!(
                "{} ({:?}), {:.1}",
                r.iterations,
                r.termination,
                t.elapsed().as_secs_f64()
            )
        } else {
            "—".to_string()
        };
        println!(
            "| {v} | {} | {} | {:?} | {rss:.0} | {ff} |",
            problem.mesh.edges().len(),
            cell(rn, true),
            rn.solver,
        );
    }
    println!();
    println!(
        "fitted growth exponent of the stress step: t ∝ V^{:.2}",
        exponent(&points)
    );

    // After the reduced rows, so that their peak memory is their own.
    println!();
    println!("The same domes, reduced and edge-based side by side (native solver; the edge-based steps run after all reduced ones, so their memory is the process's peak so far)");
    println!();
    println!("| V | reduced s (QP its) | edge-based s (QP its) | edge/reduced | peak RSS after edge-based step MiB |");
    println!("|---|---|---|---|---|");
    for (&n, &rn) in sizes.iter().zip(&reduced) {
        let problem = Problem::new(dome_with_hole(n));
        let en = step(&problem, Formulation::EdgeBased, QpSolver::Native);
        println!(
            "| {} | {} | {} | {} | {:.0} |",
            problem.mesh.positions().len(),
            cell(rn, true),
            cell(en, true),
            if_solved(en.seconds / rn.seconds, 1, &[en, rn]),
            peak_rss_mib(),
        );
    }
}

fn main() {
    let large = std::env::args().any(|a| a == "--large");
    let large_ff = large && std::env::args().any(|a| a == "--large-ff");
    let dir = models::models_dir();
    paper_table(dir.as_deref());
    if let Some(dir) = dir.as_deref() {
        shared_models_table(dir);
    }
    scaling(large, large_ff);
    println!();
    println!(
        "peak resident memory of the whole run: {:.0} MiB",
        peak_rss_mib()
    );
}
