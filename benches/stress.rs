//! Stress step, reduced (de Goes et al.) and edge-based (VHWP12) side by side, on the shared
//! real models and generated domes with a hole. Prints a table; asserts nothing.
//!
//!     cargo bench --bench stress              # models + generated domes of ~1.6k and ~6k vertices
//!     cargo bench --bench stress -- --large   # also ~20k and ~50k vertices (slow)
//!
//! A second table gives the whole form-finding loop with default settings per model.

use std::path::PathBuf;
use std::time::Instant;
use voussoir::generate::{self, Domain};
use voussoir::{
    analyse, form_find, FormFindSettings, Formulation, HoleMode, Mesh, Problem, StressSettings,
};

fn generated(n: usize) -> Mesh {
    let domain = Domain {
        outer: generate::circle([0.0, 0.0], 1.0, ((n as f64).sqrt() * 3.5) as usize),
        holes: vec![generate::circle(
            [0.35, 0.1],
            0.2,
            ((n as f64).sqrt() * 0.8) as usize,
        )],
    };
    let area = 0.95 * std::f64::consts::PI / (2.0 * n as f64);
    let (p, t) = generate::triangulate(&domain, area).expect("domain");
    generate::lift(
        &p,
        &t,
        |u| generate::spherical_cap(1.0, 0.9, u[0].hypot(u[1])),
        |_, outer| outer,
    )
    .expect("dome")
}

const MODELS: [&str; 9] = [
    "free_vault",
    "dome_with_doors",
    "lilium",
    "cheese",
    "four_holes",
    "neumunster",
    "hex",
    "three_pillar",
    "vault_pq",
];

fn shared_model(dir: &std::path::Path, name: &str) -> Mesh {
    voussoir::io::load_model(
        &dir.join(format!("{name}.obj")),
        &dir.join(format!("{name}.json")),
    )
    .expect("shared model")
}

/// The paper's timing table (de Goes et al. 2013, 2.2 GHz laptop): (VHWP12 s, de Goes s) for
/// the rows that are shared models.
fn paper(name: &str) -> Option<(f64, f64)> {
    match name {
        "free_vault" => Some((0.387, 0.18)),
        "dome_with_doors" => Some((0.877, 0.368)),
        "lilium" => Some((4.136, 0.887)),
        "cheese" => Some((13.078, 9.8)),
        _ => None,
    }
}

/// Peak resident memory of this process so far, in MiB.
fn peak_rss_mib() -> f64 {
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: getrusage writes into the struct we own.
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    usage.ru_maxrss as f64 / 1024.0
}

fn row(name: &str, mesh: Mesh) {
    let (v, e, f) = (mesh.positions.len(), mesh.edges.len(), mesh.faces.len());
    let problem = Problem::new(mesh);
    let mut cells = Vec::new();
    for formulation in [Formulation::Reduced, Formulation::EdgeBased] {
        let settings = StressSettings {
            formulation,
            holes: HoleMode::Affine,
            ..Default::default()
        };
        let t = Instant::now();
        let r = analyse(&problem, &settings).expect("valid problem");
        cells.push((
            t.elapsed().as_secs_f64(),
            r.iterations,
            r.eps_inf,
            format!("{:?}", r.status),
        ));
    }
    let (red, edge) = (&cells[0], &cells[1]);
    let paper = paper(name).map_or("—".to_string(), |(vh, dg)| format!("{dg} / {vh}"));
    println!(
        "| {name:<16} | {v:>6} | {e:>6} | {f:>6} | {:>8.3} ({:>2} it) | {:>8.3} ({:>2} it) | {:>5.2} | {paper:>14} | {:>9.3e} | {} / {} |",
        red.0,
        red.1,
        edge.0,
        edge.1,
        edge.0 / red.0,
        red.2,
        red.3,
        edge.3
    );
}

fn main() {
    let large = std::env::args().any(|a| a == "--large");
    println!("| model            |      V |      E |      F | reduced s (iters) | edge-based s (iters) | ratio | paper dG / VHWP12 s | eps_inf   | status |");
    println!("|------------------|--------|--------|--------|-------------------|----------------------|-------|---------------------|-----------|--------|");
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data/models");
    if dir.is_dir() {
        for name in MODELS {
            let mesh = shared_model(&dir, name);
            row(name, mesh);
        }
    } else {
        println!("skipped: {} not found", dir.display());
    }
    let sizes: &[usize] = if large {
        &[1000, 4000, 12000, 30000]
    } else {
        &[1000, 4000]
    };
    for &n in sizes {
        let mesh = generated(n);
        row(&format!("dome+hole {}", mesh.positions.len()), mesh);
    }
    println!();
    println!("| model            |      V | form finding: termination | iterations | eps_inf   | total s | stress s | hausdorff | l2     |");
    println!("|------------------|--------|---------------------------|------------|-----------|---------|----------|-----------|--------|");
    if dir.is_dir() {
        for name in MODELS {
            let mesh = shared_model(&dir, name);
            let v = mesh.positions.len();
            let r = form_find(&Problem::new(mesh), &FormFindSettings::default(), None)
                .expect("valid problem");
            println!(
                "| {name:<16} | {v:>6} | {:<25} | {:>10} | {:>9.2e} | {:>7.2} | {:>8.2} | {:>9.4} | {:>6.4} |",
                format!("{:?}", r.termination).chars().take(25).collect::<String>(),
                r.iterations,
                r.stress.eps_inf,
                r.total_seconds,
                r.stress_seconds,
                r.hausdorff,
                r.l2
            );
        }
    }
    println!();
    println!(
        "peak resident memory of the whole run: {:.0} MiB",
        peak_rss_mib()
    );
}
