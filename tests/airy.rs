//! docs/method.md §14 items 1 and 2: the closed forms of the reduced operator against force
//! diagrams built explicitly from power centres, and exact horizontal balance at interior
//! vertices.

mod common;
use common::{holed_disk, jiggle, Rng};
use voussoir::internals::{edge_normal, power_centre, AiryOperator, Frame, Plan};
use voussoir::{HoleMode, Mesh};

fn setup(mesh: &Mesh) -> Plan {
    Plan::new(mesh, mesh.positions(), &Frame::of(mesh, mesh.positions()))
}

/// (W) written out per edge from the cotangents of both faces.
fn closed_form_w(mesh: &Mesh, plan: &Plan, w: &[f64], e: usize) -> f64 {
    let edge = &mesh.edges()[e];
    let (t1, t2) = (edge.left.unwrap(), edge.right.unwrap());
    let [i, j] = edge.v;
    let l2 = plan.length[e].powi(2);
    let cot = |t: u32, v: u32| plan.cot_at(mesh, t, v);
    0.5 * (cot(t1.face, t1.opposite) + cot(t2.face, t2.opposite))
        + ((cot(t1.face, j) + cot(t2.face, j)) * w[i as usize]
            + (cot(t1.face, i) + cot(t2.face, i)) * w[j as usize])
            / (2.0 * l2)
        - w[t1.opposite as usize] / (4.0 * plan.area[t1.face as usize])
        - w[t2.opposite as usize] / (4.0 * plan.area[t2.face as usize])
}

#[test]
fn closed_forms_equal_power_centre_dual_lengths_on_non_delaunay_meshes() {
    for seed in 1..4 {
        let mesh = jiggle(&holed_disk(seed, 0.01, |_, outer| outer), seed, 0.3);
        let plan = setup(&mesh);
        let op = AiryOperator::new(&mesh, &plan, HoleMode::Constant).unwrap();
        let mut rng = Rng::new(seed);
        let mut y = vec![0.0; op.n_unknowns()];
        for c in op.phi_col.iter().flatten() {
            y[*c] = rng.uniform(-0.2, 0.2);
        }
        let phi = op.airy_values(&y);
        let q = op.s.mul(&y);
        let w: Vec<f64> = (0..phi.len())
            .map(|v| plan.u[v][0].powi(2) + plan.u[v][1].powi(2) - 2.0 * phi[v])
            .collect();
        let scale = q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut negative = 0;
        for (e, edge) in mesh.edges().iter().enumerate() {
            let (Some(t1), Some(t2)) = (edge.left, edge.right) else {
                continue;
            };
            let centre = |t: u32| {
                let f = mesh.faces()[t as usize];
                power_centre(f.map(|v| plan.u[v as usize]), f.map(|v| w[v as usize]))
            };
            let (c1, c2) = (centre(t1.face), centre(t2.face));
            let n = edge_normal(&mesh, &plan, e);
            let dual = ((c2[0] - c1[0]) * n[0] + (c2[1] - c1[1]) * n[1]) / plan.length[e];
            assert!(
                (q[e] - dual).abs() <= 1e-10 * scale,
                "edge {e}: (A) {} vs power centres {dual}",
                q[e]
            );
            let wq = closed_form_w(&mesh, &plan, &w, e);
            assert!(
                (q[e] - wq).abs() <= 1e-10 * scale,
                "edge {e}: (A) {} vs (W) {wq}",
                q[e]
            );
            negative += (dual < 0.0) as usize;
        }
        // The weights are random: the check covers edges of both signs (not locally regular).
        assert!(
            negative > 0,
            "seed {seed}: no negative dual length, the test would be too easy"
        );
    }
}

#[test]
fn interior_vertices_balance_exactly_for_random_airy_values_and_hole_jumps() {
    for mode in [HoleMode::Constant, HoleMode::Affine] {
        for seed in 1..4 {
            // Hole loop free in one case, anchored in the other: the cut is built either way.
            let anchor_hole = seed % 2 == 0;
            let mesh = jiggle(
                &holed_disk(seed, 0.01, move |u, outer| {
                    outer || (anchor_hole && (u[0] - 0.3).hypot(u[1] - 0.1) < 0.26)
                }),
                seed + 10,
                0.2,
            );
            let plan = setup(&mesh);
            let op = AiryOperator::new(&mesh, &plan, mode).unwrap();
            assert_eq!(op.cuts.len(), 1);
            let mut rng = Rng::new(seed);
            let y: Vec<f64> = (0..op.n_unknowns())
                .map(|_| rng.uniform(-1.0, 1.0))
                .collect();
            let q = op.s.mul(&y);
            let mut worst = 0.0f64;
            for v in 0..mesh.positions().len() {
                if mesh.on_boundary()[v] || !mesh.referenced()[v] {
                    continue;
                }
                let (mut f, mut size) = ([0.0; 2], 0.0);
                for &e in mesh.edges_at(v) {
                    let edge = &mesh.edges()[e as usize];
                    let other = if edge.v[0] as usize == v {
                        edge.v[1]
                    } else {
                        edge.v[0]
                    } as usize;
                    for (d, fd) in f.iter_mut().enumerate() {
                        let term = q[e as usize] * (plan.u[v][d] - plan.u[other][d]);
                        *fd += term;
                        size += term.abs();
                    }
                }
                worst = worst.max(f[0].abs().max(f[1].abs()) / size);
            }
            assert!(
                worst <= 1e-12,
                "{mode:?} seed {seed}: relative horizontal imbalance {worst:e}"
            );
            // The hole coefficients do change the stress (they are not silently ignored).
            let mut y0 = y.clone();
            y0[op.hole_start..op.hole_start + op.hole_width]
                .iter_mut()
                .for_each(|x| *x = 0.0);
            let q0 = op.s.mul(&y0);
            assert!(q.iter().zip(&q0).any(|(a, b)| (a - b).abs() > 1e-6));
        }
    }
}
