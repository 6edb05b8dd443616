//! Generated vaults for tests, benchmarks and examples: plan domains with holes meshed by
//! spade's refined constrained Delaunay triangulation, heights from analytic functions.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};

/// A plan domain: an outer polygon and hole polygons (any orientation).
#[derive(Debug, Clone, Default)]
pub struct Domain {
    /// The outer boundary, a closed polygon (counter-clockwise).
    pub outer: Vec<[f64; 2]>,
    /// The holes, closed polygons inside it.
    pub holes: Vec<Vec<[f64; 2]>>,
}

/// Plan points and triangles.
pub type PlanMesh = (Vec<[f64; 2]>, Vec<[u32; 3]>);

/// `n` points on a circle.
pub fn circle(centre: [f64; 2], radius: f64, n: usize) -> Vec<[f64; 2]> {
    (0..n)
        .map(|k| {
            let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            [centre[0] + radius * a.cos(), centre[1] + radius * a.sin()]
        })
        .collect()
}

/// Axis-aligned rectangle [x0, x1] × [y0, y1] with `nx` × `ny` segments on its sides.
pub fn rectangle(x0: f64, y0: f64, x1: f64, y1: f64, nx: usize, ny: usize) -> Vec<[f64; 2]> {
    let mut p = Vec::new();
    for k in 0..nx {
        p.push([x0 + (x1 - x0) * k as f64 / nx as f64, y0]);
    }
    for k in 0..ny {
        p.push([x1, y0 + (y1 - y0) * k as f64 / ny as f64]);
    }
    for k in 0..nx {
        p.push([x1 - (x1 - x0) * k as f64 / nx as f64, y1]);
    }
    for k in 0..ny {
        p.push([x0, y1 - (y1 - y0) * k as f64 / ny as f64]);
    }
    p
}

/// Why spade refused a point, in words (its `Display` is the variant's name).
fn insertion_failure(point: &str, e: spade::InsertionError) -> String {
    match e {
        spade::InsertionError::TooSmall => format!(
            "{point} has a coordinate closer to 0 than {:e} (and not 0)",
            spade::MIN_ALLOWED_VALUE
        ),
        spade::InsertionError::TooLarge => format!(
            "{point} has a coordinate larger than {:e} in magnitude",
            spade::MAX_ALLOWED_VALUE
        ),
        spade::InsertionError::NAN => format!("{point} has a NaN coordinate"),
    }
}

/// Plan points and triangles of `domain`, refined until no triangle is larger than `max_area`
/// (angles at least 25° away from constraints).
pub fn triangulate(domain: &Domain, max_area: f64) -> Result<PlanMesh> {
    let bad = |reason: String| Error::InvalidArgument {
        name: "domain",
        reason,
    };
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    for (k, poly) in std::iter::once(&domain.outer)
        .chain(&domain.holes)
        .enumerate()
    {
        let mut handles = Vec::with_capacity(poly.len());
        for (i, p) in poly.iter().enumerate() {
            let point = match k {
                0 => format!("point {i} of the outer boundary"),
                h => format!("point {i} of hole {}", h - 1),
            };
            handles.push(
                cdt.insert(Point2::new(p[0], p[1]))
                    .map_err(|e| bad(insertion_failure(&point, e)))?,
            );
        }
        for k in 0..handles.len() {
            cdt.add_constraint(handles[k], handles[(k + 1) % handles.len()]);
        }
    }
    let params = RefinementParameters::<f64>::new()
        .exclude_outer_faces(true)
        .with_max_allowed_area(max_area)
        .with_angle_limit(AngleLimit::from_deg(25.0))
        .with_max_additional_vertices(2_000_000);
    let refined = cdt.refine(params);
    let excluded: std::collections::HashSet<_> =
        refined.excluded_faces.iter().map(|f| f.index()).collect();
    let points = cdt
        .vertices()
        .map(|v| [v.position().x, v.position().y])
        .collect();
    let triangles = cdt
        .inner_faces()
        .filter(|f| !excluded.contains(&f.fix().index()))
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();
    Ok((points, triangles))
}

/// Height of a spherical cap over a disk of `radius` whose tangent at the rim rises at `angle`
/// radians (π/2: a hemisphere), at plan distance `r` from the centre.
pub fn spherical_cap(radius: f64, angle: f64, r: f64) -> f64 {
    let sphere = radius / angle.sin();
    (sphere * sphere - r * r).max(0.0).sqrt() - sphere * angle.cos()
}

/// Builds a validated mesh from plan points and triangles, lifting each point by `height` and
/// anchoring the vertices where `anchor(point, on_outer_boundary)` holds. Triangles keep
/// spade's vertex ids; points referenced by no triangle are dropped.
pub fn lift(
    points: &[[f64; 2]],
    triangles: &[[u32; 3]],
    height: impl Fn([f64; 2]) -> f64,
    anchor: impl Fn([f64; 2], bool) -> bool,
) -> Result<Mesh> {
    let mut used = vec![u32::MAX; points.len()];
    let mut positions = Vec::new();
    let faces: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                if used[v as usize] == u32::MAX {
                    used[v as usize] = positions.len() as u32;
                    let p = points[v as usize];
                    positions.push([p[0], p[1], height(p)]);
                }
                used[v as usize]
            })
        })
        .collect();
    // Anchoring needs boundary information: build once without supports being checked by
    // anchoring everything, then rebuild with the real supports.
    let all: Vec<u32> = (0..positions.len() as u32).collect();
    let probe = Mesh::new(positions.clone(), faces.clone(), &all)?;
    let mut outer = vec![false; positions.len()];
    for lp in probe.loops.iter().filter(|l| l.is_outer) {
        lp.vertices.iter().for_each(|&v| outer[v as usize] = true);
    }
    let anchored: Vec<u32> = (0..positions.len())
        .filter(|&v| anchor([positions[v][0], positions[v][1]], outer[v]))
        .map(|v| v as u32)
        .collect();
    Mesh::new(positions, faces, &anchored)
}

/// A spherical cap over the unit disk (rim anchored) with about `n` vertices.
pub fn cap_dome(angle: f64, n: usize) -> Result<Mesh> {
    let segments = ((n as f64).sqrt() * 3.5) as usize;
    let area = std::f64::consts::PI / (2.0 * n as f64);
    let (p, t) = triangulate(
        &Domain {
            outer: circle([0.0, 0.0], 1.0, segments.max(12)),
            holes: vec![],
        },
        area,
    )?;
    lift(
        &p,
        &t,
        |u| spherical_cap(1.0, angle, u[0].hypot(u[1])),
        |_, outer| outer,
    )
}

/// The benchmark's dome with a hole, about `n` vertices: a spherical cap of rim angle 0.9 rad
/// over the unit disk (rim anchored) with a free off-centre hole of radius 0.2 at (0.35, 0.1).
pub fn dome_with_hole(n: usize) -> Result<Mesh> {
    let k = (n as f64).sqrt();
    let domain = Domain {
        outer: circle([0.0, 0.0], 1.0, (k * 3.5) as usize),
        holes: vec![circle([0.35, 0.1], 0.2, (k * 0.8) as usize)],
    };
    let area = std::f64::consts::PI * (1.0 - 0.04);
    let (p, t) = triangulate(&domain, 1.6 * area / (2.0 * n as f64))?;
    lift(
        &p,
        &t,
        |u| spherical_cap(1.0, 0.9, u[0].hypot(u[1])),
        |_, outer| outer,
    )
}

/// A structured disk of radius 1: a centre vertex and `rings` concentric rings, ring k with
/// 6k vertices, consecutive rings zipped together by angle. Edges follow the radial and hoop
/// directions, the principal stress directions of a dome of revolution.
pub fn polar_disk(rings: usize) -> PlanMesh {
    let mut points = vec![[0.0, 0.0]];
    let mut ring_start = vec![0usize];
    let mut ring_len = vec![1usize];
    for k in 1..=rings {
        ring_start.push(points.len());
        ring_len.push(6 * k);
        let r = k as f64 / rings as f64;
        for m in 0..6 * k {
            // Odd rings are rotated by half a step so that the zipper alternates.
            let a = 2.0 * std::f64::consts::PI * (m as f64 + 0.5 * (k % 2) as f64) / (6 * k) as f64;
            points.push([r * a.cos(), r * a.sin()]);
        }
    }
    let angle = |p: [f64; 2]| p[1].atan2(p[0]).rem_euclid(2.0 * std::f64::consts::PI);
    let mut tris = Vec::new();
    for k in 1..=rings {
        let (is, il) = (ring_start[k - 1], ring_len[k - 1]);
        let (os, ol) = (ring_start[k], ring_len[k]);
        if il == 1 {
            for m in 0..ol {
                tris.push([0, (os + m) as u32, (os + (m + 1) % ol) as u32]);
            }
            continue;
        }
        // Zip the two rings counter-clockwise starting from angle 0.
        let key = |start: usize, len: usize, m: usize| {
            let a = angle(points[start + m % len]);
            a + 2.0 * std::f64::consts::PI * (m / len) as f64
        };
        let (mut i, mut o) = (0, 0);
        let first_i = (0..il)
            .min_by(|&a, &b| angle(points[is + a]).total_cmp(&angle(points[is + b])))
            .unwrap();
        let first_o = (0..ol)
            .min_by(|&a, &b| angle(points[os + a]).total_cmp(&angle(points[os + b])))
            .unwrap();
        while i < il || o < ol {
            let vi = (is + (first_i + i) % il) as u32;
            let vo = (os + (first_o + o) % ol) as u32;
            let next_i = key(is, il, first_i + i + 1);
            let next_o = key(os, ol, first_o + o + 1);
            let adv_inner = o >= ol || (i < il && next_i <= next_o);
            if adv_inner {
                tris.push([vi, vo, (is + (first_i + i + 1) % il) as u32]);
                i += 1;
            } else {
                tris.push([vi, vo, (os + (first_o + o + 1) % ol) as u32]);
                o += 1;
            }
        }
    }
    (points, tris)
}

/// Plans of the known-answer cases ([`self_supporting`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum KnownPlan {
    /// The unit disk, rim anchored.
    Disk,
    /// The square [−1, 1]², all sides anchored.
    Square,
    /// The square [−1, 1]² anchored along x = ±1, free along y = ±1 (τ at the free edges).
    SquareFreeSides,
    /// The annulus 0.3 ≤ r ≤ 1, both rims anchored.
    AnchoredAnnulus,
    /// The unit disk with a free oculus of radius 0.3.
    Oculus,
}

impl KnownPlan {
    /// Every plan, for tests over all of them.
    pub const ALL: [KnownPlan; 5] = [
        KnownPlan::Disk,
        KnownPlan::Square,
        KnownPlan::SquareFreeSides,
        KnownPlan::AnchoredAnnulus,
        KnownPlan::Oculus,
    ];
}

/// A mesh of `plan` with about `n` vertices, lifted to a smooth vault of rise about 0.5 that
/// is close to, but not, self-supporting.
pub fn vault(plan: KnownPlan, n: usize) -> Result<Mesh> {
    use std::f64::consts::FRAC_PI_2;
    let k = (n as f64).sqrt();
    let ring = |r: f64| circle([0.0, 0.0], r, ((k * 3.5 * r) as usize).max(12));
    let (domain, area) = match plan {
        KnownPlan::Disk => (ring(1.0), std::f64::consts::PI),
        KnownPlan::Oculus | KnownPlan::AnchoredAnnulus => (ring(1.0), 0.91 * std::f64::consts::PI),
        KnownPlan::Square | KnownPlan::SquareFreeSides => {
            let s = (k * 0.9) as usize;
            (rectangle(-1.0, -1.0, 1.0, 1.0, s, s), 4.0)
        }
    };
    let holes = match plan {
        KnownPlan::Oculus | KnownPlan::AnchoredAnnulus => vec![ring(0.3)],
        _ => vec![],
    };
    let domain = Domain {
        outer: domain,
        holes,
    };
    let (p, t) = triangulate(&domain, 1.6 * area / (2.0 * n as f64))?;
    let height = move |u: [f64; 2]| {
        let r = u[0].hypot(u[1]);
        match plan {
            KnownPlan::Disk | KnownPlan::Oculus => spherical_cap(1.0, 0.8, r),
            KnownPlan::AnchoredAnnulus => 0.4 * (std::f64::consts::PI * (r - 0.3) / 0.7).sin(),
            KnownPlan::Square => 0.6 * (FRAC_PI_2 * u[0]).cos() * (FRAC_PI_2 * u[1]).cos(),
            KnownPlan::SquareFreeSides => 0.5 * (FRAC_PI_2 * u[0]).cos(),
        }
    };
    let anchor = move |u: [f64; 2], outer: bool| match plan {
        KnownPlan::AnchoredAnnulus => u[0].hypot(u[1]) > 0.99 || u[0].hypot(u[1]) < 0.31,
        KnownPlan::SquareFreeSides => u[0].abs() > 1.0 - 1e-9,
        _ => outer,
    };
    lift(&p, &t, height, anchor)
}

/// A self-supporting vault over `plan` with about `n` vertices: [`vault`] form-found by the
/// paper's loop to ε∞ < 1e-9 with `settings`' stress constraints, so that it is a feasible
/// answer, a known one, for any perturbation of it (see [`perturb`]).
pub fn self_supporting(
    plan: KnownPlan,
    n: usize,
    settings: &crate::FormFindSettings,
) -> Result<Mesh> {
    let mesh = vault(plan, n)?;
    let problem = crate::Problem::new(mesh.clone());
    let paper = crate::FormFindSettings {
        method: crate::FormMethod::Paper,
        tolerance: 1e-9,
        max_iterations: 200,
        stall_window: 30,
        ..settings.clone()
    };
    let r = crate::form_find(&problem, &paper, None)?;
    if r.termination != crate::Termination::Converged {
        return Err(Error::Numerical {
            what: format!("the known-answer vault over {plan:?} did not converge"),
        });
    }
    let mut truth = mesh;
    truth.positions = r.positions;
    Ok(truth)
}

/// Changes of a self-supporting shape that make the known-answer inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Perturbation {
    /// A smooth concave dent of a third of the rise, off-centre.
    Dent,
    /// The crown cut flat at 80% of the rise.
    Flatten,
    /// A smooth ridge of 15% of the rise along a line across the plan.
    Ridge,
    /// A sum of eight smooth random bumps of up to 5% of the rise.
    Noise,
    /// All heights scaled by 1.3.
    Scale,
}

impl Perturbation {
    /// Every perturbation, for tests over all of them.
    pub const ALL: [Perturbation; 5] = [
        Perturbation::Dent,
        Perturbation::Flatten,
        Perturbation::Ridge,
        Perturbation::Noise,
        Perturbation::Scale,
    ];
}

/// `truth` with heights changed by `kind` (anchored vertices keep theirs); `seed` places the
/// feature.
pub fn perturb(truth: &Mesh, kind: Perturbation, seed: u64) -> Mesh {
    let mut rng = SplitMix(seed);
    let z = |v: usize| truth.positions[v][2];
    let rise = (0..truth.positions.len())
        .filter(|&v| truth.referenced[v])
        .map(z)
        .fold(0.0f64, |a, b| a.max(b.abs()));
    let bump = |u: [f64; 3], c: [f64; 2], sigma: f64| {
        (-((u[0] - c[0]).powi(2) + (u[1] - c[1]).powi(2)) / (2.0 * sigma * sigma)).exp()
    };
    let centre = [rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4)];
    let angle = rng.uniform(0.0, std::f64::consts::PI);
    let bumps: Vec<([f64; 2], f64)> = (0..8)
        .map(|_| {
            let c = [rng.uniform(-0.8, 0.8), rng.uniform(-0.8, 0.8)];
            (c, rng.uniform(-0.05, 0.05) * rise)
        })
        .collect();
    let mut out = truth.clone();
    for (v, p) in out.positions.iter_mut().enumerate() {
        if !truth.is_non_anchored(v) {
            continue;
        }
        let u = *p;
        p[2] = match kind {
            Perturbation::Dent => u[2] - rise / 3.0 * bump(u, centre, 0.2),
            Perturbation::Flatten => u[2].min(0.8 * rise),
            Perturbation::Ridge => {
                let d = (u[0] - centre[0]) * angle.sin() - (u[1] - centre[1]) * angle.cos();
                u[2] + 0.15 * rise * (-d * d / (2.0 * 0.1 * 0.1)).exp()
            }
            Perturbation::Noise => {
                u[2] + bumps
                    .iter()
                    .map(|&(c, a)| a * bump(u, c, 0.25))
                    .sum::<f64>()
            }
            Perturbation::Scale => 1.3 * u[2],
        };
    }
    out
}

/// SplitMix64: a small seeded generator for reproducible cases.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refused_points_are_named_in_words() {
        let mut hole = circle([0.0, 0.0], 0.3, 8);
        hole[5] = [f64::NAN, 0.0];
        let domain = Domain {
            outer: rectangle(-1.0, -1.0, 1.0, 1.0, 4, 4),
            holes: vec![hole],
        };
        let message = triangulate(&domain, 0.1).unwrap_err().to_string();
        assert_eq!(
            message,
            "invalid argument `domain`: point 5 of hole 0 has a NaN coordinate"
        );
        let domain = Domain {
            outer: vec![[0.0, 0.0], [1e300, 0.0], [0.0, 1.0]],
            holes: Vec::new(),
        };
        let message = triangulate(&domain, 0.1).unwrap_err().to_string();
        assert!(
            message.contains("point 1 of the outer boundary has a coordinate larger than"),
            "{message}"
        );
    }
}
