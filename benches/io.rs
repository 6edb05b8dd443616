//! Reading long polygons: a regular n-gon in one OBJ face line (as CAD exports of flat caps
//! and fan-triangulated n-gons have), read, fan-split and plan-repaired. Prints a table; asserts
//! nothing. Both steps are about linear in n (the repair was quadratic: formfind spent 7 s
//! in it at n = 40k, 36 s at 80k).
//!
//!     cargo bench --bench io

use std::time::Instant;
use voussoir::io::parse_obj;
use voussoir::{repair_plan, DEFAULT_REPAIR_TOLERANCE};

/// A regular `n`-gon of radius 1 as OBJ text: n vertices and one face line.
fn polygon(n: usize) -> String {
    let mut text = String::with_capacity(40 * n);
    for k in 0..n {
        let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
        text.push_str(&format!("v {} {} 0\n", a.cos(), a.sin()));
    }
    text.push('f');
    for k in 1..=n {
        text.push_str(&format!(" {k}"));
    }
    text.push('\n');
    text
}

fn main() {
    println!(
        "{:>8} {:>10} {:>10} {:>10} {:>8}",
        "n", "line MB", "read s", "repair s", "repairs"
    );
    for n in [10_000, 40_000, 100_000, 400_000] {
        let text = polygon(n);
        let line = text.lines().last().map_or(0, str::len) as f64 / 1e6;
        let start = Instant::now();
        let (mut positions, mut faces) = parse_obj(&text, "polygon.obj").expect("a valid polygon");
        let read = start.elapsed().as_secs_f64();
        let anchored: Vec<u32> = (0..n as u32).collect();
        let start = Instant::now();
        let repairs = repair_plan(
            &mut positions,
            &mut faces,
            &anchored,
            DEFAULT_REPAIR_TOLERANCE,
        )
        .expect("valid indices");
        let repair = start.elapsed().as_secs_f64();
        println!(
            "{n:>8} {line:>10.2} {read:>10.3} {repair:>10.3} {:>8}",
            repairs.len()
        );
    }
}
