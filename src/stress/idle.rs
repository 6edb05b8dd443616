//! Edges that no compressive state can load (docs/method.md §16.3). Compression balances a
//! vertex horizontally only with forces that point in no single open half-plane (Gordan's
//! alternative: Σ q_e d_e = 0 with q ≥ 0 and every d_e · c > 0 forces q = 0). So every edge
//! of a free corner (its edges all leave it into one open half-plane) carries nothing, and
//! at a vertex whose edges lie in a closed half-plane with two of them exactly opposite (a
//! straight free edge) only the edges on that line carry force. Removing those edges may
//! make further vertices corners or straight edges: peeling repeats until none changes.

use crate::mesh::Mesh;
use robust::{orient2d, Coord};
use std::f64::consts::{PI, TAU};

/// How far beyond a half turn the widest gap between a vertex's edge directions must be
/// (radians) for it to count as a corner: a straight free edge, whose two edges are opposite
/// up to rounding, can carry its load as an arch along the edge.
const MARGIN: f64 = 1e-9;

/// How near a half turn the widest gap must be (radians) for a vertex to be tested for two
/// exactly opposite edges (the test itself is exact).
const STRAIGHT: f64 = 1e-6;

/// Per edge: whether some compressive state may load it, as far as peeling tells. Starts
/// from `with_force` (the edges that may carry force at all) and peels at the vertices where
/// `balanced` holds (non-anchored, with no horizontal force but the edges'); an edge it
/// marks false carries nothing in any compressive state balanced there.
pub(crate) fn carrying(mesh: &Mesh, with_force: &[bool], balanced: &[bool]) -> Vec<bool> {
    let mut carries = with_force.to_vec();
    let mut queue: Vec<u32> = (0..balanced.len() as u32)
        .filter(|&v| balanced[v as usize])
        .collect();
    while let Some(v) = queue.pop() {
        for e in idle_edges(mesh, v, &carries) {
            carries[e as usize] = false;
            let j = mesh.other_end(e as usize, v);
            if balanced[j as usize] {
                queue.push(j);
            }
        }
    }
    carries
}

/// Whether the edges of `v` that may carry force all leave it into one open half-plane
/// (false for a vertex with none left).
pub(crate) fn is_corner(mesh: &Mesh, v: u32, carries: &[bool]) -> bool {
    let edges = carrying_edges(mesh, v, carries);
    !edges.is_empty() && widest_gap(&edges).0 > PI + MARGIN
}

/// The edges at `v` that compression cannot load while `v` stays in horizontal balance:
/// all of them at a corner; at a vertex whose edges lie in a closed half-plane, with two of
/// them exactly opposite (three points collinear by an exact predicate), every edge off
/// that line.
fn idle_edges(mesh: &Mesh, v: u32, carries: &[bool]) -> Vec<u32> {
    let edges = carrying_edges(mesh, v, carries);
    if edges.is_empty() {
        return Vec::new();
    }
    let (gap, [a, b]) = widest_gap(&edges);
    if gap > PI + MARGIN {
        return edges.into_iter().map(|(e, _)| e).collect();
    }
    if (gap - PI).abs() > STRAIGHT {
        return Vec::new();
    }
    let at = |e: u32| plan(mesh, mesh.other_end(e as usize, v));
    let (pa, pb) = (at(edges[a].0), at(edges[b].0));
    if orient2d(pa, plan(mesh, v), pb) != 0.0 {
        return Vec::new();
    }
    let side: Vec<(u32, f64)> = (edges.into_iter())
        .map(|(e, _)| (e, orient2d(pa, pb, at(e))))
        .filter(|&(_, o)| o != 0.0)
        .collect();
    // The angle sort put them on one side; a direction within rounding of the line could
    // sit on the other, and then the vertex is not proved to balance along the line only.
    if side.iter().any(|&(_, o)| o > 0.0) && side.iter().any(|&(_, o)| o < 0.0) {
        return Vec::new();
    }
    side.into_iter().map(|(e, _)| e).collect()
}

fn plan(mesh: &Mesh, v: u32) -> Coord<f64> {
    let p = mesh.positions[v as usize];
    Coord { x: p[0], y: p[1] }
}

/// The edges at `v` that may carry force, with their directions' angles, in angle order.
fn carrying_edges(mesh: &Mesh, v: u32, carries: &[bool]) -> Vec<(u32, f64)> {
    let p = mesh.positions[v as usize];
    let mut edges: Vec<(u32, f64)> = (mesh.edges_at(v as usize).iter().copied())
        .filter(|&e| carries[e as usize])
        .map(|e| {
            let q = mesh.positions[mesh.other_end(e as usize, v) as usize];
            (e, (q[1] - p[1]).atan2(q[0] - p[0]))
        })
        .collect();
    edges.sort_by(|a, b| a.1.total_cmp(&b.1));
    edges
}

/// The widest angle between consecutive directions of `edges` (sorted, not empty) and the
/// positions in `edges` of the directions before and after it.
fn widest_gap(edges: &[(u32, f64)]) -> (f64, [usize; 2]) {
    let last = edges.len() - 1;
    let mut widest = (edges[0].1 + TAU - edges[last].1, [last, 0]);
    for k in 0..last {
        let gap = edges[k + 1].1 - edges[k].1;
        if gap > widest.0 {
            widest = (gap, [k, k + 1]);
        }
    }
    widest
}

/// The vertices (increasing) where `keep` holds at the edges of `with_force` that peeling
/// idled (`carries` false) and a floor binds (`floored`): where a floor q_min > 0 cannot hold.
pub(crate) fn floored_idle(
    mesh: &Mesh,
    with_force: &[bool],
    carries: &[bool],
    floored: impl Fn(usize) -> bool,
    keep: impl Fn(u32) -> bool,
) -> Vec<u32> {
    let mut vertices: Vec<u32> = (0..carries.len())
        .filter(|&e| with_force[e] && !carries[e] && floored(e))
        .flat_map(|e| mesh.edges[e].v)
        .filter(|&v| keep(v))
        .collect();
    vertices.sort_unstable();
    vertices.dedup();
    vertices
}

/// Why a floor q_min > 0 cannot hold: at `vertices` (increasing) an edge it binds is one no
/// compressive state loads.
pub(crate) fn floor_reason(vertices: &[u32]) -> String {
    format!(
        "q_min (no compressive state loads every edge at vertices {}: at a free corner every \
         edge leaves the vertex on one side in plan, and a straight free edge carries force \
         only along itself; docs/method.md §16.3)",
        listed(vertices)
    )
}

/// Up to ten ids, then "…" and how many in all.
fn listed(ids: &[u32]) -> String {
    let named: Vec<String> = ids.iter().take(10).map(u32::to_string).collect();
    match ids.len() {
        n if n > 10 => format!("{}, … ({n} in all)", named.join(", ")),
        _ => named.join(", "),
    }
}
