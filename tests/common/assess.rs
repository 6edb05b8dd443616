//! Shared by the assessment's tests and benchmark: Heyman's hemisphere and barrel, their
//! shells, and the certificate recomputed from an analysis' outputs alone.
#![allow(dead_code)]

use voussoir::generate;
use voussoir::{AssessResult, Envelope, Mesh, Thickness};

/// A hemisphere of radius 1 whose rings are equal in the meridian's angle (plan radius
/// sin φ), so that the steep rows near the springing are as fine as the crown's; rim
/// anchored.
pub fn hemisphere_by_angle(rings: usize) -> Mesh {
    let (p, t) = generate::polar_disk(rings);
    let p: Vec<[f64; 2]> = (p.iter())
        .map(|&[x, y]| {
            let r = x.hypot(y);
            let s = if r > 0.0 {
                (0.5 * std::f64::consts::PI * r).sin() / r
            } else {
                0.0
            };
            [x * s, y * s]
        })
        .collect();
    let height = |u: [f64; 2]| (1.0 - u[0] * u[0] - u[1] * u[1]).max(0.0).sqrt();
    generate::lift(&p, &t, height, |_, outer| outer).unwrap()
}

/// A hemisphere of radius 1 on a radial form diagram (compas_tno's `create_circular_radial`,
/// triangulated): `rings` rings equal in the meridian's angle, each with `meridians` vertices on
/// the same meridians, a fan at the crown and every quad split by a diagonal whose direction
/// alternates from meridian to meridian; rim anchored. Unlike [`hemisphere_by_angle`], its
/// edges run along continuous meridians and hoops.
pub fn hemisphere_meridians(rings: usize, meridians: usize) -> Mesh {
    let mut points = vec![[0.0, 0.0]];
    for k in 1..=rings {
        let r = (0.5 * std::f64::consts::PI * k as f64 / rings as f64).sin();
        for m in 0..meridians {
            let a = 2.0 * std::f64::consts::PI * m as f64 / meridians as f64;
            points.push([r * a.cos(), r * a.sin()]);
        }
    }
    let id = |k: usize, m: usize| (1 + (k - 1) * meridians + m % meridians) as u32;
    let mut faces: Vec<[u32; 3]> = (0..meridians)
        .map(|m| [0, id(1, m), id(1, m + 1)])
        .collect();
    for k in 1..rings {
        for m in 0..meridians {
            let (a, b, c, d) = (id(k, m), id(k + 1, m), id(k + 1, m + 1), id(k, m + 1));
            if m % 2 == 0 {
                faces.extend([[a, b, c], [a, c, d]]);
            } else {
                faces.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    let height = |u: [f64; 2]| (1.0 - u[0] * u[0] - u[1] * u[1]).max(0.0).sqrt();
    generate::lift(&points, &faces, height, |_, outer| outer).unwrap()
}

/// A semicircular barrel of radius 1 and depth 0.1 (an arch strip with free long sides),
/// `nx` voussoirs equal in angle and `ny` rows, anchored at x = ±1.
pub fn barrel(nx: usize, ny: usize) -> Mesh {
    let points: Vec<[f64; 2]> = (0..=ny)
        .flat_map(|j| {
            (0..=nx).map(move |i| {
                [
                    -(std::f64::consts::PI * i as f64 / nx as f64).cos(),
                    0.1 * j as f64 / ny as f64,
                ]
            })
        })
        .collect();
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let faces: Vec<[u32; 3]> = (0..ny)
        .flat_map(|j| {
            (0..nx).flat_map(move |i| {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                [[a, b, c], [a, c, d]]
            })
        })
        .collect();
    let height = |u: [f64; 2]| (1.0 - u[0] * u[0]).max(0.0).sqrt();
    generate::lift(&points, &faces, height, |u, _| u[0].abs() > 1.0 - 1e-9).unwrap()
}

/// Heyman's shell between radii 1 ± t/2 read on the vertical at plan radius `radius(p)`;
/// below the intrados' footprint the springing plane z = 0 bounds it.
pub fn shell(mesh: &Mesh, radius: impl Fn([f64; 3]) -> f64, t: f64) -> voussoir::Result<Envelope> {
    let at = |rho: f64, r: f64| (rho * rho - r * r).max(0.0).sqrt();
    let (lower, upper) = (mesh.positions().iter())
        .map(|&p| (at(1.0 - 0.5 * t, radius(p)), at(1.0 + 0.5 * t, radius(p))))
        .unzip();
    Envelope::from_bounds(mesh, lower, upper, &Thickness::Uniform(t))
}

pub fn plan_diagonal(mesh: &Mesh) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in mesh.positions() {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (hi[0] - lo[0]).hypot(hi[1] - lo[1])
}

/// Per anchored vertex, from the outputs alone: the horizontal reaction H_a = Σ q (x_a − x_j)
/// and the vertical one V_a = Σ q (z_j − z_a) + p_a over its edges.
pub fn reactions(mesh: &Mesh, r: &AssessResult) -> Vec<Option<([f64; 2], f64)>> {
    let n = mesh.positions().len();
    let mut out: Vec<Option<([f64; 2], f64)>> = (0..n)
        .map(|v| mesh.anchored()[v].then_some(([0.0; 2], r.loads[v])))
        .collect();
    for (e, edge) in mesh.edges().iter().enumerate() {
        let [i, j] = edge.v.map(|v| v as usize);
        let q = r.force_densities[e];
        for (a, o) in [(i, j), (j, i)] {
            if let Some((h, v)) = out[a].as_mut() {
                let (pa, po) = (r.positions[a], r.positions[o]);
                h[0] += q * (pa[0] - po[0]);
                h[1] += q * (pa[1] - po[1]);
                *v += q * (po[2] - pa[2]);
            }
        }
    }
    out
}

/// The certificate recomputed from the outputs alone: ε∞ of the vertical residuals (equal to
/// the reported one), q ≥ 0, the plan unchanged, heights within the envelope scaled about its
/// middle by the reported scale (equal to the reported bounds), and every reported joint's
/// support on or above its springing plane, its reaction line meeting the plane within the
/// reach (to the tolerance's share: w |H| − σ b V ≤ tolerance · b · mean load).
pub fn check_certificate(mesh: &Mesh, envelope: &Envelope, r: &AssessResult, tolerance: f64) {
    assert!(r.feasible, "not certified: {:?}", r.termination);
    let n = mesh.positions().len();
    let mut residual = vec![0.0; n];
    for (e, edge) in mesh.edges().iter().enumerate() {
        let [i, j] = edge.v.map(|v| v as usize);
        let q = r.force_densities[e];
        assert!(q >= 0.0, "edge {e} in tension: q = {q}");
        let dz = r.positions[i][2] - r.positions[j][2];
        residual[i] += q * dz;
        residual[j] -= q * dz;
    }
    let free: Vec<usize> = (0..n).filter(|&v| !mesh.anchored()[v]).collect();
    let mean = free.iter().map(|&v| r.loads[v]).sum::<f64>() / free.len() as f64;
    let eps = (free.iter())
        .map(|&v| (residual[v] - r.loads[v]).abs() / mean)
        .fold(0.0, f64::max);
    assert!(eps < tolerance, "recomputed eps_inf {eps:e}");
    assert!(
        (eps - r.eps_inf).abs() <= 1e-9,
        "{eps:e} vs {:e}",
        r.eps_inf
    );
    let diag = plan_diagonal(mesh);
    let s = r.thickness_scale;
    for v in 0..n {
        let (m, h) = (
            envelope.middle[v],
            0.5 * (envelope.upper[v] - envelope.lower[v]),
        );
        let (lo, hi) = (m - s * h, m + s * h);
        assert!((lo - r.lower[v]).abs() <= 1e-12 * (1.0 + lo.abs()));
        assert!((hi - r.upper[v]).abs() <= 1e-12 * (1.0 + hi.abs()));
        let z = r.positions[v][2];
        assert!(
            z >= lo - 1e-9 * diag && z <= hi + 1e-9 * diag,
            "vertex {v} at {z} outside [{lo}, {hi}]"
        );
        assert_eq!(
            &r.positions[v][..2],
            &mesh.positions()[v][..2],
            "plan moved"
        );
    }
    check_joints(mesh, envelope, r, tolerance, mean);
}

/// Every reported joint, recomputed from the outputs; `mean` is the mean load of the free
/// vertices.
fn check_joints(mesh: &Mesh, envelope: &Envelope, r: &AssessResult, tolerance: f64, mean: f64) {
    let diag = plan_diagonal(mesh);
    let s = r.thickness_scale;
    let all = reactions(mesh, r);
    for joint in &r.joints {
        let a = joint.vertex as usize;
        let (h, v) = all[a].expect("a joint at a support");
        let m = envelope.middle[a];
        let springing = m - s * (m - envelope.springing[a]);
        let w = r.positions[a][2] - springing;
        assert!(
            w >= -1e-9 * diag,
            "support {a} {w} below its springing plane"
        );
        let b = envelope.reach[a];
        let excess = w * h[0].hypot(h[1]) - s * b * v;
        assert!(
            excess <= tolerance * b * mean,
            "support {a}: the reaction meets the springing plane beyond the reach ({excess:e})"
        );
        assert!((joint.springing - springing).abs() <= 1e-12 * (1.0 + springing.abs()));
        assert!((joint.vertical - v).abs() <= 1e-9 * v.abs().max(mean));
        assert!(joint.offset <= s * b * (1.0 + 1e-3));
    }
}

/// The plan-area-weighted RMS height of `positions` above the middle surface `middle` (a
/// third of each face's plan area to each corner): the root of what `fit` minimises, up to
/// its normalisation.
pub fn distance_from_middle(mesh: &Mesh, middle: &[f64], positions: &[[f64; 3]]) -> f64 {
    let p = mesh.positions();
    let (mut sum, mut area) = (0.0, 0.0);
    for f in mesh.faces() {
        let [a, b, c] = f.map(|v| p[v as usize]);
        let share =
            0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])).abs() / 3.0;
        for &v in f {
            sum += share * (positions[v as usize][2] - middle[v as usize]).powi(2);
            area += share;
        }
    }
    (sum / area).sqrt()
}

/// The plan points of an n × n grid over the unit square, row by row (as `grid_faces`).
pub fn unit_grid(n: usize) -> Vec<[f64; 2]> {
    (0..=n)
        .flat_map(|j| (0..=n).map(move |i| [i as f64 / n as f64, j as f64 / n as f64]))
        .collect()
}

/// Triangles of the grid of (nx + 1) × (ny + 1) points, row by row in x.
pub fn grid_faces(nx: usize, ny: usize) -> Vec<[u32; 3]> {
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut faces = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            faces.push([a, b, c]);
            faces.push([a, c, d]);
        }
    }
    faces
}
