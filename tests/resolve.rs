//! A warm re-solve after an edit: `form_find_from` starts from the previous answer and its
//! multipliers, and reaches the same certified tolerance with fewer stress steps than a cold
//! form finding of the edited problem, about as near the edited input.

use voussoir::generate::{self, KnownPlan, Perturbation};
use voussoir::*;

/// ε∞ recomputed here from positions, force densities and 3-D barycentric loads.
fn recomputed_eps(problem: &Problem, r: &FormFindResult) -> f64 {
    let mesh = &problem.mesh;
    let (x, q) = (&r.positions, &r.stress.force_densities);
    let mut load = problem.extra_loads.clone();
    for (t, f) in mesh.faces.iter().enumerate() {
        let [a, b, c] = f.map(|v| x[v as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let cr = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        let area = (cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]).sqrt() / 2.0;
        f.iter()
            .for_each(|&v| load[v as usize] += problem.face_density[t] * area / 3.0);
    }
    let mut r_vert: Vec<f64> = load.iter().map(|p| -p).collect();
    for (e, edge) in mesh.edges.iter().enumerate() {
        assert!(q[e] >= 0.0, "tension on edge {e}");
        let [i, j] = edge.v.map(|v| v as usize);
        r_vert[i] += q[e] * (x[i][2] - x[j][2]);
        r_vert[j] += q[e] * (x[j][2] - x[i][2]);
    }
    let free: Vec<usize> = (0..x.len())
        .filter(|&v| mesh.referenced[v] && !mesh.anchored[v])
        .collect();
    let p_bar = free.iter().map(|&v| load[v]).sum::<f64>() / free.len() as f64;
    free.iter()
        .map(|&v| r_vert[v].abs() / p_bar)
        .fold(0.0, f64::max)
}

fn plan_diagonal(mesh: &Mesh) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &mesh.positions {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (hi[0] - lo[0]).hypot(hi[1] - lo[1])
}

#[test]
fn a_re_solve_after_moving_one_vertex_takes_fewer_stress_steps() {
    let settings = FormFindSettings::default();
    for (plan, kind) in [
        (KnownPlan::Disk, Perturbation::Dent),
        (KnownPlan::Square, Perturbation::Noise),
    ] {
        let truth = generate::self_supporting(plan, 400, &settings).unwrap();
        let input = generate::perturb(&truth, kind, 0);
        let before = form_find(&Problem::new(input.clone()), &settings, None).unwrap();
        assert_eq!(before.termination, Termination::Converged, "{plan:?}");
        // Raise the non-anchored vertex nearest the plan's centre by 1% of the plan diagonal.
        let n = input.positions.len();
        let centre = input.positions.iter().fold([0.0; 2], |c, p| {
            [c[0] + p[0] / n as f64, c[1] + p[1] / n as f64]
        });
        let moved = (0..n)
            .filter(|&v| input.referenced[v] && !input.anchored[v])
            .min_by(|&a, &b| {
                let d = |v: usize| {
                    let p = input.positions[v];
                    (p[0] - centre[0]).hypot(p[1] - centre[1])
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        let mut edited = input.clone();
        edited.positions[moved][2] += 0.01 * plan_diagonal(&input);
        let problem = Problem::new(edited);
        let cold = form_find(&problem, &settings, None).unwrap();
        let warm = form_find_from(&problem, &settings, &before, None).unwrap();
        assert_eq!(cold.termination, Termination::Converged, "{plan:?}");
        assert_eq!(warm.termination, Termination::Converged, "{plan:?}");
        let eps = recomputed_eps(&problem, &warm);
        assert!(eps < settings.tolerance, "{plan:?}: re-solve ε∞ {eps:e}");
        assert!(
            warm.iterations < cold.iterations,
            "{plan:?}: re-solve {} stress steps, cold {}",
            warm.iterations,
            cold.iterations
        );
        // Near, not nearest: the continuation restarts from the previous multipliers, so the
        // re-solve may settle on an equilibrium a few per cent less near than a cold one
        // (measured: +8% on the disk, −13% on the square).
        assert!(
            warm.rms_change <= 1.1 * cold.rms_change,
            "{plan:?}: re-solve RMS change {:.6}, cold {:.6}",
            warm.rms_change,
            cold.rms_change
        );
        println!(
            "{plan:?}: cold {} steps RMS {:.6} max {:.6}; re-solve {} steps RMS {:.6} max {:.6}",
            cold.iterations,
            cold.rms_change,
            cold.max_change,
            warm.iterations,
            warm.rms_change,
            warm.max_change
        );
    }
}
