//! Voussoir from Rust: the dome of `examples/c/dome.c`, built from arrays, form found, its
//! residual printed. Run with `cargo run --example dome`; exits with status 1 unless form
//! finding converges.

use voussoir::{form_find, FormFindSettings, Mesh, Problem, StressStatus, Termination};

const RINGS: u32 = 6;
const SEGMENTS: u32 = 16;

fn vertex_id(ring: u32, m: u32) -> u32 {
    1 + (ring - 1) * SEGMENTS + m % SEGMENTS
}

/// A shallow cap over the unit disk (a 60° cap squashed to 30% of its height), odd rings
/// turned by half a step, the rim anchored.
fn dome() -> (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<u32>) {
    let angle = std::f64::consts::FRAC_PI_3;
    let sphere = 1.0 / angle.sin();
    let height = |r: f64| 0.3 * ((sphere * sphere - r * r).sqrt() - sphere * angle.cos());
    let mut positions = vec![[0.0, 0.0, height(0.0)]];
    for k in 1..=RINGS {
        let r = f64::from(k) / f64::from(RINGS);
        for m in 0..SEGMENTS {
            let a = std::f64::consts::TAU * (f64::from(m) + 0.5 * f64::from(k % 2))
                / f64::from(SEGMENTS);
            positions.push([r * a.cos(), r * a.sin(), height(r)]);
        }
    }
    let mut triangles: Vec<[u32; 3]> = (0..SEGMENTS)
        .map(|m| [0, vertex_id(1, m), vertex_id(1, m + 1)])
        .collect();
    for k in 1..RINGS {
        for m in 0..SEGMENTS {
            let (a0, a1) = (vertex_id(k, m), vertex_id(k, m + 1));
            let (b0, b1) = (vertex_id(k + 1, m), vertex_id(k + 1, m + 1));
            if k % 2 == 1 {
                triangles.extend([[b0, b1, a0], [a0, b1, a1]]);
            } else {
                triangles.extend([[a0, b0, a1], [a1, b0, b1]]);
            }
        }
    }
    let anchored = (0..SEGMENTS).map(|m| vertex_id(RINGS, m)).collect();
    (positions, triangles, anchored)
}

fn main() -> Result<(), voussoir::Error> {
    let (positions, triangles, anchored) = dome();
    println!(
        "form finding a dome: {} vertices, {} triangles, {} supports",
        positions.len(),
        triangles.len(),
        anchored.len()
    );
    let problem = Problem::new(Mesh::new(positions, triangles, &anchored)?);
    let settings = FormFindSettings::default()
        .with_tolerance(1e-6)
        .with_max_iterations(100);
    let mut progress = |k: usize, eps: f64| {
        println!("  iteration {k:2}  eps_inf = {eps:.3e}");
        true // continue
    };
    let result = form_find(&problem, &settings, Some(&mut progress))?;
    let max_residual = result
        .stress
        .residuals
        .iter()
        .fold(0.0f64, |m, r| m.max(r.abs()));
    println!(
        "{} after {} iterations",
        result.termination, result.iterations
    );
    println!(
        "eps_inf = {:.3e}, max |residual| = {:.3e}, sum of squares = {:.3e}",
        result.stress.eps_inf, max_residual, result.stress.objective
    );
    println!(
        "moved by at most {:.3e} (RMS {:.3e}) of the plan diagonal",
        result.hausdorff, result.l2
    );
    let ok = result.termination == Termination::Converged
        && result.stress.status == StressStatus::Solved;
    std::process::exit(if ok { 0 } else { 1 });
}
