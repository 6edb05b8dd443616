//! A stress step's data in frame units, and the loads and boundary terms it is built from
//! (docs/method.md §3, §6, §8).

use super::{EdgeScope, StressSettings, TauMode};
use crate::error::Result;
use crate::geometry::{loads, Frame, Plan};
use crate::mesh::Mesh;
use crate::problem::Problem;

/// Heights over `l0`, relative to the mean height of the anchored vertices (of all referenced
/// ones without any) where that lies far from them (`crate::geometry::far_base`): the QP sees
/// only their differences, which keep their digits where a model lifted by 10⁷ would lose
/// seven of them to z / L₀ rounded at that size. Elsewhere the heights are taken as they are,
/// so that ordinary models are solved with the same arithmetic wherever they stand.
fn relative_heights(mesh: &Mesh, positions: &[[f64; 3]], l0: f64) -> Vec<f64> {
    let heights = |keep: &dyn Fn(usize) -> bool| {
        (0..positions.len())
            .filter(|&v| mesh.referenced[v] && keep(v))
            .map(|v| positions[v][2])
            .collect::<Vec<f64>>()
    };
    let supports = heights(&|v| mesh.anchored[v]);
    let all = heights(&|_| true);
    let base = crate::geometry::far_base(if supports.is_empty() { &all } else { &supports }, &all);
    positions.iter().map(|p| (p[2] - base) / l0).collect()
}

/// A stress step's data in frame units (z' = z/L₀, p' = p/p̄, forces / p̄, q' = q L₀/p̄), the
/// same for all its attempts, with the physical loads and scales.
pub(super) struct FramedStep {
    pub(super) frame: Frame,
    pub(super) plan: Plan,
    /// Physical loads, the non-anchored vertices and their mean load p̄.
    pub(super) load: Vec<f64>,
    pub(super) free: Vec<u32>,
    pub(super) p_bar: f64,
    /// The natural force density scale p̄ / L₀.
    pub(super) unit: f64,
    /// Heights in frame units, relative to the supports' mean height (`relative_heights`).
    pub(super) z: Vec<f64>,
    pub(super) p: Vec<f64>,
    pub(super) normal: Vec<[f64; 2]>,
    pub(super) external: Vec<[f64; 2]>,
    pub(super) tau_normal: Vec<Option<[f64; 2]>>,
    pub(super) edges: Vec<[u32; 2]>,
    pub(super) bounds: Vec<Option<(f64, f64)>>,
    pub(super) smoothing_pairs: Vec<[usize; 2]>,
}

impl FramedStep {
    /// `load_offset`: physical loads added to the true ones in the QP's target (see
    /// `StressCache::set_load_offset`).
    pub(super) fn new(
        problem: &Problem,
        positions: &[[f64; 3]],
        settings: &StressSettings,
        load_offset: Option<&[f64]>,
    ) -> Result<FramedStep> {
        let mesh = &problem.mesh;
        let frame = Frame::of(mesh, positions);
        let plan = Plan::new(mesh, positions, &frame);
        let l0 = frame.scale;
        let (load, free, p_bar) = loads_at(problem, positions, settings);
        check_mean_load(&load, &free)?;
        let unit = p_bar / l0;
        let z = relative_heights(mesh, positions, l0);
        let p: Vec<f64> = match load_offset {
            Some(offset) => (load.iter().zip(offset))
                .map(|(x, o)| (x + o) / p_bar)
                .collect(),
            None => load.iter().map(|x| x / p_bar).collect(),
        };
        let normal = boundary_normals(mesh, &plan.u);
        let (external, tau_normal) = horizontal_terms(problem, settings, &normal, p_bar);
        let edges: Vec<[u32; 2]> = mesh.edges.iter().map(|e| e.v).collect();
        let bounds = edge_bounds(problem, &plan, settings, unit);
        let smoothing_pairs = if settings.dual_length_smoothing > 0.0 {
            face_edge_pairs(mesh)
        } else {
            Vec::new()
        };
        Ok(FramedStep {
            frame,
            plan,
            load,
            free,
            p_bar,
            unit,
            z,
            p,
            normal,
            external,
            tau_normal,
            edges,
            bounds,
            smoothing_pairs,
        })
    }
}

/// The external horizontal forces in frame units (prescribed τ included) and, per free
/// boundary vertex with an optimised τ, the normal it pushes along.
pub(super) fn horizontal_terms(
    problem: &Problem,
    settings: &StressSettings,
    normal: &[[f64; 2]],
    p_bar: f64,
) -> (Vec<[f64; 2]>, Vec<Option<[f64; 2]>>) {
    let mesh = &problem.mesh;
    let n = normal.len();
    let mut external: Vec<[f64; 2]> = problem
        .horizontal_forces
        .iter()
        .map(|f| [f[0] / p_bar, f[1] / p_bar])
        .collect();
    let mut tau_normal = vec![None; n];
    for v in 0..n {
        if !mesh.is_free_boundary(v) {
            continue;
        }
        match settings.tau {
            TauMode::Optimized => tau_normal[v] = Some(normal[v]),
            TauMode::Zero => {}
            TauMode::Prescribed => {
                let t = problem.prescribed_tau[v] / p_bar;
                external[v][0] -= t * normal[v][0];
                external[v][1] -= t * normal[v][1];
            }
        }
    }
    (external, tau_normal)
}

/// Whether edge `e` may carry force: not a boundary edge between two anchored vertices.
pub(crate) fn carries_force(mesh: &Mesh, e: usize) -> bool {
    let edge = &mesh.edges[e];
    !edge.is_boundary() || edge.v.iter().any(|&v| !mesh.anchored[v as usize])
}

/// Whether q_min binds edge `e` (its scope, and never a polygon's diagonal).
pub(crate) fn floored(problem: &Problem, settings: &StressSettings, e: usize) -> bool {
    let interior = !problem.mesh.edges[e].is_boundary();
    (settings.q_min_scope == EdgeScope::All || interior) && !problem.polygon_diagonal[e]
}

/// Per edge, its bounds on q in frame units (see [`force_density_bounds`]).
pub(super) fn edge_bounds(
    problem: &Problem,
    plan: &Plan,
    settings: &StressSettings,
    unit: f64,
) -> Vec<Option<(f64, f64)>> {
    (0..problem.mesh.edges.len())
        .map(|e| force_density_bounds(problem, settings, e, unit, plan.length[e]))
        .collect()
}

/// None for edge `e` without force (boundary, both ends anchored), else its bounds (lower,
/// upper) on q in frame units (multiples of `unit`, p̄/L₀): q_min on the edges of its scope
/// but polygon diagonals, q_max, and the dual length bounds of interior edges. `length` is
/// the edge's plan length over L₀.
pub(crate) fn force_density_bounds(
    problem: &Problem,
    settings: &StressSettings,
    e: usize,
    unit: f64,
    length: f64,
) -> Option<(f64, f64)> {
    let mesh = &problem.mesh;
    carries_force(mesh, e).then(|| {
        let q_min = settings.q_min.physical(unit) / unit;
        let q_max = settings
            .q_max
            .map_or(f64::INFINITY, |b| b.physical(unit) / unit);
        let (mut lo, mut hi) = (
            if floored(problem, settings, e) {
                q_min
            } else {
                0.0
            },
            q_max,
        );
        // Dual length d* = q l is p̄ q' l' in frame units: bounds on it are per-edge q bounds.
        if let (Some((d_lo, d_hi)), false) =
            (settings.dual_length_bounds, mesh.edges[e].is_boundary())
        {
            lo = lo.max(d_lo / length);
            hi = hi.min(d_hi / length);
        }
        (lo, hi)
    })
}

/// Vertices whose equations count: referenced and not anchored.
pub(crate) fn non_anchored(mesh: &Mesh) -> Vec<u32> {
    (0..mesh.positions.len() as u32)
        .filter(|&v| mesh.is_non_anchored(v as usize))
        .collect()
}

/// Unit outward normals (sum of the two boundary edges' normals) at boundary vertices.
pub(super) fn boundary_normals(mesh: &Mesh, u: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut nrm = vec![[0.0; 2]; u.len()];
    for lp in &mesh.loops {
        let n = lp.vertices.len();
        for k in 0..n {
            let (a, b) = (lp.vertices[k] as usize, lp.vertices[(k + 1) % n] as usize);
            let d = [u[b][0] - u[a][0], u[b][1] - u[a][1]];
            let len = d[0].hypot(d[1]);
            let out = [d[1] / len, -d[0] / len];
            for v in [a, b] {
                nrm[v][0] += out[0];
                nrm[v][1] += out[1];
            }
        }
    }
    for m in &mut nrm {
        let len = m[0].hypot(m[1]);
        if len > 0.0 {
            *m = [m[0] / len, m[1] / len];
        }
    }
    nrm
}

/// Pairs of interior edges (all of which carry force) that share a face: their dual segments
/// meet at the face's power centre.
pub(super) fn face_edge_pairs(mesh: &Mesh) -> Vec<[usize; 2]> {
    let interior = |e: u32| !mesh.edges[e as usize].is_boundary();
    let mut pairs = Vec::new();
    for fe in &mesh.face_edges {
        for k in 0..3 {
            let (a, b) = (fe[k], fe[(k + 1) % 3]);
            if interior(a) && interior(b) {
                pairs.push([a as usize, b as usize]);
            }
        }
    }
    pairs
}

/// Largest mean load on the non-anchored vertices that a stress step accepts. With the plan's
/// extent L₀ within what [`Mesh::new`] accepts, force densities (of order p̄/L₀), Airy values
/// (p̄ L₀) and the objective (squared residuals, of order p̄²) stay representable.
pub const MAX_MEAN_LOAD: f64 = 1e150;
/// Smallest positive mean load a stress step accepts (see [`MAX_MEAN_LOAD`]).
pub const MIN_MEAN_LOAD: f64 = 1e-150;

/// A stress step needs weight to balance, of a size double precision can represent: the mean
/// load p̄ on the non-anchored vertices is the unit of ε∞, of relative q bounds and of the
/// problem's scaling, so it must be positive and within [`MIN_MEAN_LOAD`], [`MAX_MEAN_LOAD`].
pub(super) fn check_mean_load(load: &[f64], free: &[u32]) -> Result<()> {
    let mean = mean_over(load, free);
    let reason = if free.is_empty() {
        // Every vertex is anchored: nothing to balance, and nothing wrong.
        return Ok(());
    } else if mean == 0.0 {
        "the loads on the non-anchored vertices are all 0 (density 0 on every face and no extra \
         load): there is no weight to balance; give the faces a positive density"
            .to_string()
    } else if mean < 0.0 {
        format!(
            "the loads on the non-anchored vertices average {mean:e}, upwards: a compression-only \
             vault stands under a downward load"
        )
    } else if mean.is_nan() || mean > MAX_MEAN_LOAD {
        format!(
            "the loads on the non-anchored vertices average {mean:e}: beyond {MAX_MEAN_LOAD:e}, \
             force densities and squared residuals cannot be represented in double precision \
             (express the model in larger units or lower the density)"
        )
    } else if mean < MIN_MEAN_LOAD {
        format!(
            "the loads on the non-anchored vertices average {mean:e}: below {MIN_MEAN_LOAD:e}, \
             force densities and squared residuals cannot be represented in double precision \
             (express the model in smaller units or raise the density)"
        )
    } else {
        return Ok(());
    };
    Err(crate::Error::InvalidArgument {
        name: "loads",
        reason,
    })
}

/// Loads at `positions`, the non-anchored vertices, and their mean load p̄ (1 when not
/// positive: a stress step rejects such loads, see [`check_mean_load`], and a certificate at
/// new heights keeps a scale).
pub(super) fn loads_at(
    problem: &Problem,
    positions: &[[f64; 3]],
    settings: &StressSettings,
) -> (Vec<f64>, Vec<u32>, f64) {
    let mesh = &problem.mesh;
    let load = loads::vertex_loads(
        mesh,
        positions,
        settings.load_rule,
        &problem.face_density,
        &problem.extra_loads,
    );
    let p_bar = problem.mean_load(&load);
    (load, non_anchored(mesh), p_bar)
}

pub(super) fn mean_over(x: &[f64], ids: &[u32]) -> f64 {
    if ids.is_empty() {
        return 0.0;
    }
    ids.iter().map(|&v| x[v as usize]).sum::<f64>() / ids.len() as f64
}
