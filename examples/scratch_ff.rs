use std::time::Instant;
use voussoir::generate::{self, Domain};
use voussoir::{form_find, FormFindSettings, Mesh, Problem, QBound};

fn dome_with_hole(n: usize) -> Mesh {
    let domain = Domain {
        outer: generate::circle([0.0, 0.0], 1.0, ((n as f64).sqrt() * 3.5) as usize),
        holes: vec![generate::circle(
            [0.35, 0.1],
            0.2,
            ((n as f64).sqrt() * 0.8) as usize,
        )],
    };
    let area = std::f64::consts::PI * (1.0 - 0.04);
    let (p, t) = generate::triangulate(&domain, 1.6 * area / (2.0 * n as f64)).expect("domain");
    generate::lift(
        &p,
        &t,
        |u| generate::spherical_cap(1.0, 0.9, u[0].hypot(u[1])),
        |_, outer| outer,
    )
    .expect("dome")
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args[1].parse().unwrap();
    if args.get(2).map(|s| s.as_str()) == Some("an") {
        let problem = Problem::new(dome_with_hole(n));
        for _ in 0..2 {
            let t = Instant::now();
            let r = voussoir::analyse(&problem, &voussoir::StressSettings::default()).unwrap();
            println!(
                "analyse V {} its {} {:?} t {:.2}",
                problem.mesh.positions.len(),
                r.iterations,
                r.status,
                t.elapsed().as_secs_f64()
            );
        }
        return;
    }
    let qmin: f64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(0.05);
    let problem = Problem::new(dome_with_hole(n));
    let mut s = FormFindSettings::default();
    s.stress.q_min = QBound::Relative(qmin);
    if let Some(k) = args.get(3) {
        s.max_iterations = k.parse().unwrap();
    }
    let t = Instant::now();
    let mut cb = |k: usize, e: f64| {
        eprintln!("step {k} eps {e:.3e} t {:.1}", t.elapsed().as_secs_f64());
        true
    };
    let r = form_find(&problem, &s, Some(&mut cb)).unwrap();
    let qs = &r.stress.force_densities;
    let mut sorted = qs.clone();
    sorted.sort_by(|a, b| a.partial_cmp(b).unwrap());
    println!(
        "stress {:.1} shape {:.1} V {} qmin {qmin} term {:?} its {} time {:.1} haus {:.4} l2 {:.4} minq {:.2e} medq {:.3}",
        r.stress_seconds, r.shape_seconds, problem.mesh.positions.len(), r.termination, r.iterations, t.elapsed().as_secs_f64(), r.hausdorff, r.l2,
        sorted[0], sorted[sorted.len() / 2]
    );
    inspect(&problem, &r);
}

#[allow(dead_code)]
pub fn inspect(problem: &Problem, r: &voussoir::FormFindResult) {
    let m = &problem.mesh;
    let res = &r.stress.residuals;
    let mut order: Vec<usize> = (0..res.len()).collect();
    order.sort_by(|&a, &b| res[b].abs().partial_cmp(&res[a].abs()).unwrap());
    let pbar = r.stress.loads.iter().sum::<f64>() / r.stress.loads.len() as f64;
    for &v in order.iter().take(5) {
        let p = r.positions[v];
        let mut zs = 0.0;
        let mut qs = Vec::new();
        let mut ls = 0.0;
        let es = m.edges_at(v);
        for &e in es {
            let ed = &m.edges[e as usize];
            let o = if ed.v[0] as usize == v {
                ed.v[1]
            } else {
                ed.v[0]
            } as usize;
            zs += r.positions[o][2];
            let d = [r.positions[o][0] - p[0], r.positions[o][1] - p[1]];
            ls += d[0].hypot(d[1]);
            qs.push(r.stress.force_densities[e as usize]);
        }
        let k = es.len() as f64;
        println!(
            "v {v} at ({:.3},{:.3}) r/pbar {:.3} dent (z - mean nb)/L {:.3e} L {:.3e} free {} q {:?}",
            p[0], p[1], res[v] / pbar, (p[2] - zs / k) / (ls / k), ls / k,
            m.is_free_boundary(v), qs.iter().map(|q| format!("{q:.2e}")).collect::<Vec<_>>()
        );
    }
}
