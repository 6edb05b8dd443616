//! Free corners and the parts they strand (docs/method.md §16.3). A non-anchored vertex whose
//! edges with force all leave it into one open half-plane of the plan cannot be balanced
//! horizontally by compression unless every one of those edges carries nothing (Gordan's
//! alternative: Σ q_e d_e = 0 with q ≥ 0 and every d_e · c > 0 forces q = 0). Removing such
//! edges may leave further vertices with edges on one side only, and so on. A connected part
//! whose remaining edges reach no support then holds its load with nothing, by the sum of its
//! vertical equations: no thrust surface exists in any envelope, however thick, and an
//! assessment answers so before any search.

use super::model::{Model, Run};
use super::Objective;
use crate::solve::Termination;
use robust::{orient2d, Coord};
use std::f64::consts::{PI, TAU};

/// How far beyond a half turn the widest gap between a vertex's edge directions must be
/// (radians) for it to count as a corner: a straight free edge, whose two edges are opposite
/// up to rounding, can carry its load as an arch along the edge.
const MARGIN: f64 = 1e-9;

/// How near a half turn the widest gap must be (radians) for a vertex to be tested for two
/// exactly opposite edges (the test itself is exact).
const STRAIGHT: f64 = 1e-6;

/// How many stranded vertices (besides the corners) a message names before it only counts.
const NAMED: usize = 10;

/// What the plan alone proves infeasible: the free corners of the plan as drawn, and every
/// vertex of a loaded part left with no compressive path to a support (corners included
/// where they are stranded themselves), both in increasing order.
pub(super) struct Stranded {
    pub corners: Vec<u32>,
    pub vertices: Vec<u32>,
}

/// The stranded parts of the plan, if any. A part counts when its dead load exceeds what the
/// certificate forgives (`tolerance` times the mean load per vertex) and, for `max-load`,
/// when the live pattern loads none of its vertices (the factor may take either sign and
/// cancel the dead load). A vertex with a prescribed horizontal force is never peeled.
pub(super) fn stranded(model: &Model, tolerance: f64) -> Option<Stranded> {
    let with_force: Vec<bool> = model.stress.bounds.iter().map(Option::is_some).collect();
    let corners: Vec<u32> = (model.residual.iter().copied())
        .filter(|&v| peelable(model, v) && is_corner(model, v, &with_force))
        .collect();
    let vertices = unsupported(model, &model.carries, tolerance);
    (!vertices.is_empty()).then_some(Stranded { corners, vertices })
}

/// Per edge: whether some compressive state in horizontal balance may load it, as far as
/// peeling corners and straight free edges tells (an edge marked false carries nothing in
/// every such state).
pub(super) fn carrying(model: &Model) -> Vec<bool> {
    let mut carries: Vec<bool> = model.stress.bounds.iter().map(Option::is_some).collect();
    peel(model, &mut carries);
    carries
}

fn peelable(model: &Model, v: u32) -> bool {
    model.stress.external[v as usize] == [0.0, 0.0]
}

/// Removes the edges that cannot carry force, vertex by vertex, until no vertex has more.
fn peel(model: &Model, carries: &mut [bool]) {
    let mesh = &model.problem.mesh;
    let mut queue: Vec<u32> = (model.residual.iter().copied())
        .filter(|&v| peelable(model, v))
        .collect();
    while let Some(v) = queue.pop() {
        for e in idle_edges(model, v, carries) {
            carries[e as usize] = false;
            let j = mesh.other_end(e as usize, v);
            if !mesh.anchored()[j as usize] && peelable(model, j) {
                queue.push(j);
            }
        }
    }
}

/// Whether the edges of `v` that may carry force all leave it into one open half-plane
/// (false for a vertex with none left).
fn is_corner(model: &Model, v: u32, carries: &[bool]) -> bool {
    let edges = carrying_edges(model, v, carries);
    !edges.is_empty() && widest_gap(&edges).0 > PI + MARGIN
}

/// The edges at `v` that compression cannot load while `v` stays in horizontal balance:
/// all of them at a corner; at a vertex whose edges lie in a closed half-plane, with two of
/// them exactly opposite (three points collinear by an exact predicate, as along a straight
/// free edge), every edge off that line.
fn idle_edges(model: &Model, v: u32, carries: &[bool]) -> Vec<u32> {
    let edges = carrying_edges(model, v, carries);
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
    let mesh = &model.problem.mesh;
    let plan = |v: u32| {
        let p = mesh.positions()[v as usize];
        Coord { x: p[0], y: p[1] }
    };
    let at = |e: u32| plan(mesh.other_end(e as usize, v));
    let (pa, pb) = (at(edges[a].0), at(edges[b].0));
    if orient2d(pa, plan(v), pb) != 0.0 {
        return Vec::new();
    }
    (edges.into_iter().map(|(e, _)| e))
        .filter(|&e| orient2d(pa, pb, at(e)) != 0.0)
        .collect()
}

/// The edges at `v` that may carry force, with their directions' angles, in angle order.
fn carrying_edges(model: &Model, v: u32, carries: &[bool]) -> Vec<(u32, f64)> {
    let vi = v as usize;
    let mesh = &model.problem.mesh;
    let u = &model.stress.plan.u;
    let mut edges: Vec<(u32, f64)> = (model.incident[vi].iter().copied())
        .filter(|&e| carries[e as usize])
        .map(|e| {
            let j = mesh.other_end(e as usize, v) as usize;
            (e, (u[j][1] - u[vi][1]).atan2(u[j][0] - u[vi][0]))
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

/// The vertices of the loaded parts that the carrying edges join to no support.
fn unsupported(model: &Model, carries: &[bool], tolerance: f64) -> Vec<u32> {
    let mesh = &model.problem.mesh;
    let mut parts = Parts::new(mesh.positions().len());
    for (e, _) in carries.iter().enumerate().filter(|(_, &c)| c) {
        let [a, b] = mesh.edges()[e].v;
        parts.join(a as usize, b as usize);
    }
    let n = mesh.positions().len();
    let (mut supported, mut live) = (vec![false; n], vec![false; n]);
    let (mut load, mut count) = (vec![0.0; n], vec![0usize; n]);
    for &v in &model.supports {
        supported[parts.root(v as usize)] = true;
    }
    for &v in &model.residual {
        let (v, r) = (v as usize, parts.root(v as usize));
        load[r] += model.dead[v];
        count[r] += 1;
        live[r] |= model.objective == Objective::MaxLoad && model.live[v] != 0.0;
    }
    let stranded =
        |r: usize| !supported[r] && !live[r] && load[r].abs() >= tolerance * count[r] as f64;
    (model.residual.iter().copied())
        .filter(|&v| stranded(parts.root(v as usize)))
        .collect()
}

/// Union–find over vertices, joined along the edges that may carry force.
struct Parts(Vec<usize>);

impl Parts {
    fn new(n: usize) -> Self {
        Parts((0..n).collect())
    }

    fn root(&mut self, mut v: usize) -> usize {
        while self.0[v] != v {
            self.0[v] = self.0[self.0[v]];
            v = self.0[v];
        }
        v
    }

    fn join(&mut self, a: usize, b: usize) {
        let (a, b) = (self.root(a), self.root(b));
        self.0[a.max(b)] = a.min(b);
    }
}

/// The answer where a part is stranded: the middle surface without force (its residuals are
/// the loads), with the termination naming the corners and the stranded vertices.
pub(super) fn unbalanced(model: &Model, stranded: &Stranded) -> Run {
    Run {
        state: model.start_state(),
        termination: Termination::Infeasible {
            constraint: message(stranded),
        },
        iterations: 0,
        seconds: 0.0,
        unbounded: false,
    }
}

fn message(stranded: &Stranded) -> String {
    let list = |ids: &[u32]| {
        let mut named: Vec<String> = ids.iter().take(NAMED).map(u32::to_string).collect();
        if ids.len() > NAMED {
            named.push("…".to_owned());
        }
        named.join(", ")
    };
    let others: Vec<u32> = (stranded.vertices.iter().copied())
        .filter(|v| stranded.corners.binary_search(v).is_err())
        .collect();
    let mut parts = Vec::new();
    let side = "(every edge leaves the vertex on one side in plan)";
    match stranded.corners.as_slice() {
        [] => {}
        [v] => parts.push(format!("vertex {v} is a free corner {side}")),
        ids => parts.push(format!(
            "vertices {} ({} in all) are free corners {side}",
            list(ids),
            ids.len()
        )),
    }
    match others.as_slice() {
        [] => {}
        [v] => parts.push(format!("vertex {v} has no compressive path to a support")),
        ids => parts.push(format!(
            "{} vertices ({}) have no compressive path to a support",
            ids.len(),
            list(ids)
        )),
    }
    let mend = match stranded.corners.is_empty() {
        true => "add supports, or edges that reach them",
        false => "anchor the corners",
    };
    format!(
        "the supports: {}, which compression alone cannot balance in any envelope; {mend}",
        parts.join(", and then ")
    )
}
