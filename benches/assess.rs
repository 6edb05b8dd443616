//! Masonry assessment (docs/method.md §16). Prints tables; asserts nothing.
//!
//!     cargo bench --bench assess                   # hemispheres by mesh size, shared models
//!     cargo bench --bench assess -- --hemisphere   # hemispheres only
//!     cargo bench --bench assess -- --models       # shared models only
//!
//! Hemispheres: radius 1 on `generate::polar_disk` meshes, rim anchored, thickness 0.1 along
//! the normal (docs/method.md §16.1), every analysis; t_min/R = s × 0.1. Shared models: each
//! with a uniform normal thickness of 2 % of its plan diagonal, fit and least thickness.

use std::path::PathBuf;
use voussoir::{assess, generate, AssessSettings, Envelope, Mesh, Objective, Problem, Thickness};

fn hemisphere(rings: usize) -> Mesh {
    let (p, t) = generate::polar_disk(rings);
    let height = |u: [f64; 2]| (1.0 - u[0] * u[0] - u[1] * u[1]).max(0.0).sqrt();
    generate::lift(&p, &t, height, |_, outer| outer).unwrap()
}

fn row(name: &str, mesh: &Mesh, thickness: f64, objective: Objective) {
    let envelope = Envelope::from_thickness(mesh, &Thickness::Uniform(thickness)).unwrap();
    let problem = Problem::new(mesh.clone());
    let settings = AssessSettings::default().with_objective(objective);
    let r = assess(&problem, &envelope, &settings, None).unwrap();
    let total: f64 = r.loads.iter().sum();
    let end = format!("{:?}", r.termination);
    println!(
        "| {name} | {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.1e} | {:.2} |",
        mesh.positions.len(),
        objective.as_str(),
        end.split([' ', '{']).next().unwrap_or(""),
        r.feasible,
        r.iterations,
        r.thickness_scale * thickness,
        r.thrust_horizontal / total,
        r.eps_inf,
        r.seconds
    );
}

fn header(what: &str) {
    println!("\n{what}\n");
    println!("| model | V | analysis | end | certified | steps | t at s (t_min) | thrust / weight | eps_inf | s |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
}

fn hemispheres() {
    header("Hemisphere R = 1, t = 0.1 (normal thickness, tangent-plane vertical reading)");
    for rings in [6, 10, 14, 20] {
        let mesh = hemisphere(rings);
        for objective in [
            Objective::MinThickness,
            Objective::MinThrust,
            Objective::MaxThrust,
        ] {
            row(&format!("hemisphere {rings} rings"), &mesh, 0.1, objective);
        }
    }
}

fn models() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data/models");
    if !dir.is_dir() {
        println!("\nshared models: {} not found", dir.display());
        return;
    }
    header("Shared models, uniform thickness 2 % of the plan diagonal");
    for name in [
        "free_vault",
        "dome_with_doors",
        "neumunster",
        "vault_pq",
        "three_pillar",
        "hex",
        "lilium",
    ] {
        let mesh = voussoir::io::load_model(
            &dir.join(format!("{name}.obj")),
            &dir.join(format!("{name}.json")),
        )
        .unwrap()
        .mesh;
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &mesh.positions {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        let t = 0.02 * (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
        for objective in [Objective::Fit, Objective::MinThickness] {
            row(name, &mesh, t, objective);
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let has = |f: &str| args.iter().any(|a| a == f);
    if !has("--models") {
        hemispheres();
    }
    if !has("--hemisphere") {
        models();
    }
}
