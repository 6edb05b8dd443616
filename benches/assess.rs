//! Masonry assessment (docs/method.md §16). Prints tables; asserts nothing.
//!
//!     cargo bench --bench assess                   # hemispheres by mesh size, shared models
//!     cargo bench --bench assess -- --hemisphere [--only TEXT]   # hemispheres only
//!     cargo bench --bench assess -- --models       # shared models only
//!     cargo bench --bench assess -- --heyman       # least thickness on Heyman's terms
//!     cargo bench --bench assess -- --heyman --barrels   # its barrels only
//!     cargo bench --bench assess -- --large [--budget S] [--only TEXT]   # ~5k vertices
//!
//! Hemispheres: radius 1 on `generate::polar_disk` meshes and on radial form diagrams
//! ("radial"), rim anchored, thickness 0.1 along the normal (docs/method.md §16.1), every
//! analysis; t_min/R = s × 0.1. Shared models: each
//! with a uniform normal thickness of 2 % of its plan diagonal, fit and least thickness.
//! Heyman: the least thickness of a hemispherical dome (on zipped rings and on a radial form
//! diagram) and of a semicircular barrel (an arch strip with free sides) over the family of
//! shells R ± t/2 read vertically (`min_thickness_of_family`), free supports on the classical
//! springing joint (the plane z = 0, reach t/2: `Envelope::from_bounds`' defaults), against
//! Heyman's t/R ≈ 0.042 and Milankovitch's 0.1075 (radial joints) and the continuum values of
//! this convention (docs/benchmarks.md).
//! Large: a hemispherical dome (4921 vertices) and a cross vault (5041) of radius 1 between
//! the shells R ± t/2 read vertically (t = 0.1; the cross vault's as compas_tno's
//! `apply_envelope`: the intersection of two semicircular barrels), classical springing
//! joints, every analysis but max-load; each search is cancelled after `--budget` seconds
//! of steps (default 600; the `fit` start of the other analyses is not cancelled).
//! `--only TEXT` (with `--hemisphere`, `--models`, `--heyman` or `--large`) keeps the rows
//! whose "model analysis" (with `--heyman`, "model") contains TEXT.

#[path = "../tests/common/models.rs"]
mod models;
#[path = "../tests/common/assess.rs"]
mod shells;

use shells::{barrel, distance_from_middle, hemisphere_by_angle, hemisphere_meridians, shell};

use voussoir::{
    assess, generate, min_thickness_of_family, AssessSettings, Envelope, Mesh, Objective, Problem,
    Thickness,
};

fn hemisphere(rings: usize) -> Mesh {
    let (p, t) = generate::polar_disk(rings);
    let height = |u: [f64; 2]| (1.0 - u[0] * u[0] - u[1] * u[1]).max(0.0).sqrt();
    generate::lift(&p, &t, height, |_, outer| outer).unwrap()
}

/// The value of `--only`: rows whose "model analysis" does not contain it are skipped.
fn only() -> String {
    let args: Vec<String> = std::env::args().collect();
    let k = args.iter().position(|a| a == "--only");
    k.and_then(|k| args.get(k + 1).cloned()).unwrap_or_default()
}

fn row(name: &str, mesh: &Mesh, thickness: f64, objective: Objective) {
    if !format!("{name} {}", objective.as_str()).contains(&only()) {
        return;
    }
    let envelope = Envelope::from_thickness(mesh, &Thickness::Uniform(thickness)).unwrap();
    let problem = Problem::new(mesh.clone());
    let settings = AssessSettings::default().with_objective(objective);
    let r = assess(&problem, &envelope, &settings, None).unwrap();
    let total: f64 = r.loads.iter().sum();
    let end = format!("{:?}", r.termination);
    println!(
        "| {name} | {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.4e} | {:.1e} | {:.2} |",
        mesh.positions().len(),
        objective.as_str(),
        end.split([' ', '{']).next().unwrap_or(""),
        r.feasible,
        r.iterations,
        r.thickness_scale * thickness,
        r.thrust_horizontal / total,
        distance_from_middle(mesh, &envelope.middle, &r.positions),
        r.eps_inf,
        r.seconds
    );
}

fn header(what: &str) {
    println!("\n{what}\n");
    println!("| model | V | analysis | end | certified | steps | t at s (t_min) | thrust / weight | RMS from middle | eps_inf | s |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
}

fn hemispheres() {
    header("Hemisphere R = 1, t = 0.1 (normal thickness, tangent-plane vertical reading)");
    let zipped =
        [6, 10, 14, 20].map(|rings| (format!("hemisphere {rings} rings"), hemisphere(rings)));
    let radial = [(6, 16), (10, 24), (14, 32)].map(|(rings, meridians)| {
        let name = format!("radial hemisphere {rings} x {meridians}");
        (name, hemisphere_meridians(rings, meridians))
    });
    for (name, mesh) in zipped.iter().chain(&radial) {
        for objective in [
            Objective::Fit,
            Objective::MinThickness,
            Objective::MinThrust,
            Objective::MaxThrust,
        ] {
            row(name, mesh, 0.1, objective);
        }
    }
}

fn models() {
    let Some(dir) = models::models_dir() else {
        return;
    };
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
        let mesh = models::read_shared(&dir, name).unwrap().mesh;
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in mesh.positions() {
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

fn heyman_row(name: &str, mesh: &Mesh, radius: impl Fn([f64; 3]) -> f64, classical: f64) {
    if !name.contains(&only()) {
        return;
    }
    let problem = Problem::new(mesh.clone());
    let settings = AssessSettings::default();
    let family = |t: f64| shell(mesh, &radius, t);
    match min_thickness_of_family(&problem, family, 0.1, 1e-3, &settings) {
        Ok(f) => println!(
            "| {name} | {} | {:.4} | {classical} | {:+.1}% | {} | {} | {:.1e} | {:.1} |",
            mesh.positions().len(),
            f.thickness,
            100.0 * (f.thickness / classical - 1.0),
            f.rounds,
            f.converged,
            f.result.eps_inf,
            f.result.seconds
        ),
        Err(e) => println!("| {name} | {} | error: {e} |", mesh.positions().len()),
    }
}

fn heyman() {
    println!("\nLeast thickness over the shells R ± t/2 (R = 1) read vertically\n");
    println!("| model | V | t_min / R | classical | diff | rounds | converged | eps_inf | last round s |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let only_barrels = std::env::args().any(|a| a == "--barrels");
    for rings in [6, 10, 14].into_iter().filter(|_| !only_barrels) {
        let name = format!("hemisphere, zipped, {rings} rings");
        heyman_row(
            &name,
            &hemisphere_by_angle(rings),
            |p| p[0].hypot(p[1]),
            0.042,
        );
    }
    for (rings, meridians) in [(6, 16), (10, 24), (14, 32)]
        .into_iter()
        .filter(|_| !only_barrels)
    {
        let name = format!("hemisphere, radial, {rings} rings x {meridians}");
        heyman_row(
            &name,
            &hemisphere_meridians(rings, meridians),
            |p| p[0].hypot(p[1]),
            0.042,
        );
    }
    for nx in [16, 32, 64] {
        let name = format!("semicircular barrel, {nx} segments");
        heyman_row(&name, &barrel(nx, 2), |p| p[0].abs(), 0.1075);
    }
}

/// A cross vault over [-1, 1]²: two semicircular barrels of radius 1 intersecting, height
/// sqrt(1 − min(x², y²)), on an n × n grid whose diagonals run along the groins, anchored
/// at the four corners.
fn cross_vault(n: usize) -> Mesh {
    let at = |i: usize| -1.0 + 2.0 * i as f64 / n as f64;
    let points: Vec<[f64; 2]> = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| [at(i), at(j)]))
        .collect();
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let half = n / 2;
    let faces: Vec<[u32; 3]> = (0..n)
        .flat_map(|j| {
            (0..n).flat_map(move |i| {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                // The diagonal through the quad's corner nearest a groin line |x| = |y|.
                if (i < half) == (j < half) {
                    [[a, b, c], [a, c, d]]
                } else {
                    [[a, b, d], [b, c, d]]
                }
            })
        })
        .collect();
    let height = |u: [f64; 2]| (1.0 - (u[0] * u[0]).min(u[1] * u[1])).max(0.0).sqrt();
    let corner = |u: [f64; 2], _| u[0].abs() > 1.0 - 1e-9 && u[1].abs() > 1.0 - 1e-9;
    generate::lift(&points, &faces, height, corner).unwrap()
}

/// One analysis of a large model, cancelled after `budget` seconds of steps.
fn large_row(name: &str, mesh: &Mesh, envelope: &Envelope, objective: Objective, budget: f64) {
    let problem = Problem::new(mesh.clone());
    let settings = AssessSettings::default().with_objective(objective);
    let start = std::time::Instant::now();
    let mut within = |_: usize, _: f64| start.elapsed().as_secs_f64() < budget;
    let r = assess(&problem, envelope, &settings, Some(&mut within)).unwrap();
    let total: f64 = r.loads.iter().sum();
    let end = format!("{:?}", r.termination);
    let t_min = if objective == Objective::MinThickness {
        format!("{:.4}", r.thickness_scale * 0.1)
    } else {
        "—".into()
    };
    println!(
        "| {name} | {} | {} | {} | {} | {} | {t_min} | {:.4} | {:.1e} | {:.1} |",
        mesh.positions().len(),
        objective.as_str(),
        end.split([' ', '{']).next().unwrap_or(""),
        r.feasible,
        r.iterations,
        r.thrust_horizontal / total,
        r.eps_inf,
        r.seconds
    );
}

fn large() {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        let k = args.iter().position(|a| a == flag)?;
        args.get(k + 1).cloned()
    };
    let budget: f64 = value("--budget").map_or(600.0, |b| b.parse().unwrap());
    let only = only();
    println!(
        "\nLarge models, shells R ± t/2 read vertically (R = 1, t = 0.1), budget {budget} s\n"
    );
    println!("| model | V | analysis | end | certified | steps | t_min / R | thrust / weight | eps_inf | s |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let dome = hemisphere_by_angle(40);
    let dome_envelope = shell(&dome, |p| p[0].hypot(p[1]), 0.1).unwrap();
    let vault = cross_vault(70);
    let groin = |p: [f64; 3]| p[0].abs().min(p[1].abs());
    let vault_envelope = shell(&vault, groin, 0.1).unwrap();
    for (name, mesh, envelope) in [
        ("dome", &dome, &dome_envelope),
        ("cross vault", &vault, &vault_envelope),
    ] {
        for objective in [
            Objective::Fit,
            Objective::MinThrust,
            Objective::MaxThrust,
            Objective::MinThickness,
        ] {
            if format!("{name} {}", objective.as_str()).contains(&only) {
                large_row(name, mesh, envelope, objective, budget);
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let has = |f: &str| args.iter().any(|a| a == f);
    if has("--heyman") {
        return heyman();
    }
    if has("--large") {
        return large();
    }
    if !has("--models") {
        hemispheres();
    }
    if !has("--hemisphere") {
        models();
    }
}
