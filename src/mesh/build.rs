//! `Mesh::new`: validation in a fixed order, then derivation of the connectivity.
//!
//! Every check is a full pass over the mesh, and the checks run in the order documented on
//! [`Mesh::new`], so the error returned is always the first one in that order. Each pass is
//! linear or `O(n log n)` (sorting); nothing is quadratic.

use super::connectivity::{
    boundary_loops, build_edges, components, half_edges, HalfEdge, UnionFind,
};
use super::Mesh;
use crate::{Error, Result};

/// A face is degenerate when |plan area| <= `AREA_TOL` × (plan bounding-box diagonal)².
pub const AREA_TOL: f64 = 1e-12;
/// Largest coordinate magnitude accepted: squares and products of two coordinates (areas,
/// loads, Airy values) then stay far from the largest double (about 1.8e308).
pub const MAX_COORDINATE: f64 = 1e150;
/// Smallest plan extent (bounding-box diagonal) accepted, unless it is 0 (then every face is
/// degenerate): areas then stay far from the smallest normal double (about 2.2e-308).
pub const MIN_PLAN_EXTENT: f64 = 1e-150;
/// An interior vertex overlaps when its plan angle sum differs from 2π by more than this, a
/// boundary vertex when its sum exceeds 2π by more.
pub const ANGLE_TOL: f64 = 1e-6;

impl Mesh {
    /// Validates a triangle mesh and derives its connectivity.
    ///
    /// `positions` are (x, y) plan and z height; `faces` are 0-based vertex ids; `anchored`
    /// lists the supported vertices (0-based, each at most once). Vertices that no face
    /// refers to are ignored (even if their coordinates are NaN) and listed in `unreferenced`.
    ///
    /// The checks run in this order, and the first failing one is returned:
    /// 1. no vertex or no face: [`Error::EmptyMesh`];
    /// 2. a face index `>= n_vertices`: [`Error::IndexOutOfRange`] (first such face);
    /// 3. an anchored id out of range or listed twice: [`Error::InvalidAnchor`];
    /// 4. a NaN / infinite coordinate on a referenced vertex: [`Error::NonFiniteCoordinate`];
    ///    a coordinate beyond ±[`MAX_COORDINATE`], or a plan less than [`MIN_PLAN_EXTENT`]
    ///    across (but not 0): [`Error::InvalidArgument`] for `positions` (areas and loads
    ///    could not be represented in double precision);
    /// 5. a face repeating a vertex: [`Error::RepeatedVertexInFace`];
    /// 6. two faces on the same three vertices (any order): [`Error::DuplicateFace`];
    /// 7. faces of (near) zero plan area: [`Error::DegenerateFaces`] (all of them);
    /// 8. an edge with more than two faces: [`Error::NonManifoldEdge`];
    /// 9. two faces traversing an edge in the same direction: [`Error::InconsistentOrientation`];
    /// 10. a vertex whose faces form more than one fan: [`Error::NonManifoldVertex`];
    /// 11. plan orientation: if most faces are clockwise in plan, all faces are reversed
    ///     (`reversed = true`); faces still clockwise: [`Error::FlippedFaces`]; interior
    ///     vertices whose plan angles do not sum to 2π, or boundary vertices whose angles sum
    ///     to more: [`Error::OverlappingPlan`]; two faces overlapping in plan elsewhere (a strip
    ///     winding over itself, components stacked in plan): [`Error::OverlappingFaces`];
    /// 12. supports: [`Error::NoSupports`], then [`Error::UnsupportedComponent`] for the
    ///     first connected component without an anchored vertex.
    pub fn new(positions: Vec<[f64; 3]>, faces: Vec<[u32; 3]>, anchored: &[u32]) -> Result<Mesh> {
        let n = positions.len();
        // 1. sizes
        if n == 0 || faces.is_empty() {
            return Err(Error::EmptyMesh);
        }
        check_sizes(n, faces.len())?;
        // 2.-5. indices, anchors, finiteness, face-local checks
        check_indices(&faces, n)?;
        let anchored_flags = check_anchors(anchored, n)?;
        let referenced = referenced_flags(&faces, n);
        check_finite(&positions, &referenced)?;
        check_magnitudes(&positions, &referenced)?;
        check_repeated_vertices(&faces)?;
        // 6.-7. duplicates and degenerate faces
        check_duplicate_faces(&faces)?;
        let areas: Vec<f64> = faces.iter().map(|f| plan_area(&positions, f)).collect();
        check_degenerate(&positions, &referenced, &areas)?;
        // 8.-10. manifoldness and consistent orientation
        let halves = half_edges(&faces);
        check_edges(&halves)?;
        check_vertex_fans(&faces, &halves, n)?;
        // 11. plan orientation and plan validity
        let negative = areas.iter().filter(|a| **a < 0.0).count();
        let positive = areas.len() - negative;
        let reversed = negative > positive;
        let mut faces = faces;
        if reversed {
            for f in &mut faces {
                f.swap(1, 2);
            }
        }
        let flipped: Vec<usize> = areas
            .iter()
            .enumerate()
            .filter(|(_, a)| if reversed { **a > 0.0 } else { **a < 0.0 })
            .map(|(t, _)| t)
            .collect();
        if !flipped.is_empty() {
            return Err(Error::FlippedFaces { faces: flipped });
        }
        // The undirected edges are unchanged by the reversal; sides and corners are not.
        let halves = if reversed { half_edges(&faces) } else { halves };
        let (edges, face_edges) = build_edges(&faces, &halves);
        let mut on_boundary = vec![false; n];
        for e in edges.iter().filter(|e| e.is_boundary()) {
            on_boundary[e.v[0] as usize] = true;
            on_boundary[e.v[1] as usize] = true;
        }
        check_angle_sums(&positions, &faces, &referenced, &on_boundary)?;
        if let Some(faces) = super::overlap::first_overlap(&positions, &faces, &edges) {
            return Err(Error::OverlappingFaces { faces });
        }
        // 12. components and supports
        let (vertex_component, n_components) = components(&faces, &referenced);
        check_supports(
            &vertex_component,
            n_components,
            &anchored_flags,
            &referenced,
        )?;

        let face_component: Vec<u32> = faces
            .iter()
            .map(|f| vertex_component[f[0] as usize])
            .collect();
        let (vertex_edge_start, vertex_edges) = vertex_edge_csr(&edges, n);
        let loops = boundary_loops(
            &positions,
            &edges,
            &on_boundary,
            &vertex_component,
            n_components,
        );
        let unreferenced: Vec<u32> = (0..n)
            .filter(|&v| !referenced[v])
            .map(|v| v as u32)
            .collect();

        Ok(Mesh {
            positions,
            faces,
            reversed,
            edges,
            face_edges,
            vertex_edge_start,
            vertex_edges,
            anchored: anchored_flags,
            on_boundary,
            referenced,
            vertex_component,
            face_component,
            n_components,
            loops,
            unreferenced,
        })
    }
}

/// Ids are stored as `u32`; edge ids go up to 3 × faces and the vertex → edge lists hold
/// 2 × edges entries.
fn check_sizes(n_vertices: usize, n_faces: usize) -> Result<()> {
    if n_vertices > u32::MAX as usize {
        return Err(Error::InvalidArgument {
            name: "positions",
            reason: format!("{n_vertices} vertices: at most {} are supported", u32::MAX),
        });
    }
    let max_faces = (u32::MAX / 6) as usize;
    if n_faces > max_faces {
        return Err(Error::InvalidArgument {
            name: "faces",
            reason: format!("{n_faces} faces: at most {max_faces} are supported"),
        });
    }
    Ok(())
}

fn check_indices(faces: &[[u32; 3]], n: usize) -> Result<()> {
    for (t, f) in faces.iter().enumerate() {
        if let Some(&index) = f.iter().find(|&&i| i as usize >= n) {
            return Err(Error::IndexOutOfRange {
                face: t,
                index: u64::from(index),
                n_vertices: n,
            });
        }
    }
    Ok(())
}

/// Anchored ids are checked in the order given: out of range first, then repeats.
fn check_anchors(anchored: &[u32], n: usize) -> Result<Vec<bool>> {
    let mut flags = vec![false; n];
    for &a in anchored {
        let Some(flag) = flags.get_mut(a as usize) else {
            return Err(Error::InvalidAnchor {
                index: u64::from(a),
                reason: "out of range",
            });
        };
        if *flag {
            return Err(Error::InvalidAnchor {
                index: u64::from(a),
                reason: "listed twice",
            });
        }
        *flag = true;
    }
    Ok(flags)
}

/// Requires valid indices (checked before).
fn referenced_flags(faces: &[[u32; 3]], n: usize) -> Vec<bool> {
    let mut referenced = vec![false; n];
    for &i in faces.iter().flatten() {
        referenced[i as usize] = true;
    }
    referenced
}

fn check_finite(positions: &[[f64; 3]], referenced: &[bool]) -> Result<()> {
    let bad = positions
        .iter()
        .zip(referenced)
        .position(|(p, &r)| r && !p.iter().all(|c| c.is_finite()));
    match bad {
        Some(vertex) => Err(Error::NonFiniteCoordinate { vertex }),
        None => Ok(()),
    }
}

/// New heights for a validated mesh ([`Mesh::with_heights`]): one per vertex, finite on the
/// referenced vertices and within ±[`MAX_COORDINATE`] (the plan checks do not involve them).
pub(super) fn check_heights(heights: &[f64], referenced: &[bool]) -> Result<()> {
    if heights.len() != referenced.len() {
        return Err(Error::InvalidArgument {
            name: "heights",
            reason: format!(
                "{} heights for {} vertices: give one per vertex",
                heights.len(),
                referenced.len()
            ),
        });
    }
    let mut used = heights.iter().zip(referenced).enumerate();
    if let Some((vertex, _)) = used.clone().find(|(_, (z, &r))| r && !z.is_finite()) {
        return Err(Error::NonFiniteCoordinate { vertex });
    }
    match used.find(|(_, (z, &r))| r && z.abs() > MAX_COORDINATE) {
        Some((v, (z, _))) => Err(Error::InvalidArgument {
            name: "heights",
            reason: format!(
                "vertex {v} has the height {z:e}: beyond ±{MAX_COORDINATE:e}, loads cannot be \
                 represented in double precision (express the model in larger units)"
            ),
        }),
        None => Ok(()),
    }
}

/// Coordinates whose squares (areas, loads) double precision can represent with room to spare.
fn check_magnitudes(positions: &[[f64; 3]], referenced: &[bool]) -> Result<()> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for (v, (p, _)) in positions
        .iter()
        .zip(referenced)
        .enumerate()
        .filter(|(_, (_, &r))| r)
    {
        if let Some(c) = p.iter().find(|c| c.abs() > MAX_COORDINATE) {
            return Err(Error::InvalidArgument {
                name: "positions",
                reason: format!(
                    "vertex {v} has the coordinate {c:e}: beyond ±{MAX_COORDINATE:e}, areas and \
                     loads cannot be represented in double precision (express the model in \
                     larger units)"
                ),
            });
        }
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    // NaN (no referenced vertex) fails both comparisons.
    let extent = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    if extent > 0.0 && extent < MIN_PLAN_EXTENT {
        return Err(Error::InvalidArgument {
            name: "positions",
            reason: format!(
                "the plan is {extent:e} across: below {MIN_PLAN_EXTENT:e}, areas and loads \
                 cannot be represented in double precision (express the model in smaller units)"
            ),
        });
    }
    Ok(())
}

fn check_repeated_vertices(faces: &[[u32; 3]]) -> Result<()> {
    match faces
        .iter()
        .position(|f| f[0] == f[1] || f[1] == f[2] || f[2] == f[0])
    {
        Some(face) => Err(Error::RepeatedVertexInFace { face }),
        None => Ok(()),
    }
}

/// Reports the duplicate with the smallest face id, paired with the first face of its set.
fn check_duplicate_faces(faces: &[[u32; 3]]) -> Result<()> {
    let mut keyed: Vec<([u32; 3], usize)> = faces
        .iter()
        .enumerate()
        .map(|(t, f)| {
            let mut k = *f;
            k.sort_unstable();
            (k, t)
        })
        .collect();
    keyed.sort_unstable();
    let mut found: Option<(usize, usize)> = None;
    for group in keyed.chunk_by(|a, b| a.0 == b.0) {
        if let [(_, first), (_, second), ..] = group {
            if found.is_none_or(|(face, _)| *second < face) {
                found = Some((*second, *first));
            }
        }
    }
    match found {
        Some((face, first)) => Err(Error::DuplicateFace { face, first }),
        None => Ok(()),
    }
}

/// Signed plan area (x, y) of a face: positive when counter-clockwise.
pub(super) fn plan_area(positions: &[[f64; 3]], f: &[u32; 3]) -> f64 {
    let [a, b, c] = f.map(|i| positions[i as usize]);
    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
}

fn check_degenerate(positions: &[[f64; 3]], referenced: &[bool], areas: &[f64]) -> Result<()> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for (p, _) in positions.iter().zip(referenced).filter(|(_, &r)| r) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diag2 = (hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2);
    let tol = AREA_TOL * diag2;
    let faces: Vec<usize> = areas
        .iter()
        .enumerate()
        .filter(|(_, a)| a.abs() <= tol || a.is_nan())
        .map(|(t, _)| t)
        .collect();
    if faces.is_empty() {
        Ok(())
    } else {
        Err(Error::DegenerateFaces { faces })
    }
}

/// Checks 8 (at most two faces per edge) then 9 (opposite directions), each over all edges.
fn check_edges(halves: &[HalfEdge]) -> Result<()> {
    for group in halves.chunk_by(HalfEdge::same_edge) {
        if group.len() > 2 {
            let mut faces: Vec<usize> = group.iter().map(|h| h.face as usize).collect();
            faces.sort_unstable();
            return Err(Error::NonManifoldEdge {
                edge: [group[0].lo as usize, group[0].hi as usize],
                faces,
            });
        }
    }
    for group in halves.chunk_by(HalfEdge::same_edge) {
        if let [a, b] = group {
            if a.forward == b.forward {
                let (lo, hi) = (a.lo as usize, a.hi as usize);
                return Err(Error::InconsistentOrientation {
                    edge: if a.forward { [lo, hi] } else { [hi, lo] },
                    faces: [a.face as usize, b.face as usize],
                });
            }
        }
    }
    Ok(())
}

/// Check 10: the corners of the faces around each vertex must form one edge-connected fan.
/// Corner `3t + k` (vertex `faces[t][k]`) is joined to the corner of the same vertex in the
/// face across each edge; a vertex whose corners end in two sets is a bow-tie.
fn check_vertex_fans(faces: &[[u32; 3]], halves: &[HalfEdge], n: usize) -> Result<()> {
    let mut corners = UnionFind::new(3 * faces.len());
    let corner_of = |t: u32, v: u32| -> Option<usize> {
        let f = faces.get(t as usize)?;
        let k = f.iter().position(|&w| w == v)?;
        Some(3 * t as usize + k)
    };
    for group in halves.chunk_by(HalfEdge::same_edge) {
        if let [a, b] = group {
            for v in [a.lo, a.hi] {
                if let (Some(ca), Some(cb)) = (corner_of(a.face, v), corner_of(b.face, v)) {
                    corners.union(ca, cb);
                }
            }
        }
    }
    let mut fan_of = vec![usize::MAX; n];
    let mut bad: Option<usize> = None;
    for (c, &v) in faces.iter().flatten().enumerate() {
        let v = v as usize;
        let root = corners.find(c);
        if fan_of[v] == usize::MAX {
            fan_of[v] = root;
        } else if fan_of[v] != root && bad.is_none_or(|b| v < b) {
            bad = Some(v);
        }
    }
    match bad {
        Some(vertex) => Err(Error::NonManifoldVertex { vertex }),
        None => Ok(()),
    }
}

/// Interior vertices must see their (counter-clockwise) faces sum to 2π in plan, boundary
/// vertices at most 2π (more and the fan of faces around them wraps over itself).
fn check_angle_sums(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    referenced: &[bool],
    on_boundary: &[bool],
) -> Result<()> {
    let mut sums = vec![0.0f64; positions.len()];
    for f in faces {
        for k in 0..3 {
            let [p, q, r] = [f[k], f[(k + 1) % 3], f[(k + 2) % 3]].map(|i| positions[i as usize]);
            let (ux, uy) = (q[0] - p[0], q[1] - p[1]);
            let (wx, wy) = (r[0] - p[0], r[1] - p[1]);
            sums[f[k] as usize] += (ux * wy - uy * wx).atan2(ux * wx + uy * wy);
        }
    }
    let full = std::f64::consts::TAU;
    let vertices: Vec<usize> = (0..positions.len())
        .filter(|&v| {
            let off = if on_boundary[v] {
                sums[v] - full
            } else {
                (sums[v] - full).abs()
            };
            referenced[v] && (off > ANGLE_TOL || sums[v].is_nan())
        })
        .collect();
    if vertices.is_empty() {
        Ok(())
    } else {
        Err(Error::OverlappingPlan { vertices })
    }
}

fn check_supports(
    vertex_component: &[u32],
    n_components: usize,
    anchored: &[bool],
    referenced: &[bool],
) -> Result<()> {
    let mut supported = vec![false; n_components];
    for ((&c, &a), &r) in vertex_component.iter().zip(anchored).zip(referenced) {
        if a && r {
            if let Some(s) = supported.get_mut(c as usize) {
                *s = true;
            }
        }
    }
    if !supported.iter().any(|&s| s) {
        return Err(Error::NoSupports);
    }
    if let Some(component) = supported.iter().position(|&s| !s) {
        let vertices: Vec<usize> = vertex_component
            .iter()
            .enumerate()
            .filter(|(_, &c)| c as usize == component)
            .map(|(v, _)| v)
            .collect();
        return Err(Error::UnsupportedComponent {
            component,
            vertices,
        });
    }
    Ok(())
}

/// CSR of the edges incident to each vertex, each list in increasing edge id.
fn vertex_edge_csr(edges: &[super::Edge], n: usize) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; n + 1];
    for e in edges {
        start[e.v[0] as usize + 1] += 1;
        start[e.v[1] as usize + 1] += 1;
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut fill: Vec<u32> = start[..n].to_vec();
    let mut list = vec![0u32; 2 * edges.len()];
    for (id, e) in edges.iter().enumerate() {
        for v in e.v {
            let slot = &mut fill[v as usize];
            list[*slot as usize] = id as u32;
            *slot += 1;
        }
    }
    (start, list)
}
