//! Hubs: a wheel of n spokes (a centre at height 0.5 joined to n anchored rim vertices on the
//! unit circle, issue 48) analysed with the native solver and with clarabel, n = 1k, 10k, 100k.
//! Prints a table (time, status, who answered, peak resident memory so far); asserts nothing.
//!
//!     cargo bench --bench wheel
//!     cargo bench --bench wheel -- --clarabel   # clarabel's row too (slow at 100k)

use std::time::Instant;
use voussoir::{analyse, Mesh, Problem, QpSolver, StressSettings};

/// Peak resident memory of this process so far, in MiB.
fn peak_rss_mib() -> f64 {
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: getrusage writes into the struct we own.
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    usage.ru_maxrss as f64 / 1024.0
}

fn wheel(n: usize) -> Mesh {
    let mut positions = vec![[0.0, 0.0, 0.5]];
    positions.extend((0..n).map(|k| {
        let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
        [a.cos(), a.sin(), 0.0]
    }));
    let faces = (0..n as u32)
        .map(|k| [0, k + 1, (k + 1) % n as u32 + 1])
        .collect();
    let rim: Vec<u32> = (1..=n as u32).collect();
    Mesh::new(positions, faces, &rim).expect("wheel")
}

fn main() {
    let clarabel = std::env::args().any(|a| a == "--clarabel");
    println!("| spokes | solver | seconds | status | answered by | formulation | peak RSS MiB |");
    println!("|---:|---|---:|---|---|---|---:|");
    for n in [1_000, 10_000, 100_000] {
        let problem = Problem::new(wheel(n));
        let solvers: &[QpSolver] = if clarabel {
            &[QpSolver::Native, QpSolver::Clarabel]
        } else {
            &[QpSolver::Native]
        };
        for &solver in solvers {
            let settings = StressSettings::default().with_solver(solver);
            let t = Instant::now();
            let r = analyse(&problem, &settings).expect("analysis");
            println!(
                "| {n} | {solver:?} | {:.3} | {:?} | {:?} | {:?} | {:.0} |",
                t.elapsed().as_secs_f64(),
                r.status,
                r.solver,
                r.formulation,
                peak_rss_mib()
            );
        }
    }
}
