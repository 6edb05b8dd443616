//! Free corners and the parts they strand (docs/method.md §16.3). Once peeling
//! (`stress::idle`) has removed the edges that no compressive state can load, a connected
//! part whose remaining edges reach no support holds its load with nothing, by the sum of
//! its vertical equations: no thrust surface exists in any envelope, however thick, and an
//! assessment answers so before any search.

use super::model::{Model, Run};
use super::{AssessSettings, Objective};
use crate::solve::Termination;
use crate::stress::idle;
use crate::stress::QBound;

/// How many stranded vertices (besides the corners) a message names before it only counts.
const NAMED: usize = 10;

/// What the plan alone proves infeasible: the free corners of the plan as drawn that are
/// stranded or border a stranded vertex, and every vertex of a loaded part left with no
/// compressive path to a support (corners included where they are stranded themselves),
/// both in increasing order.
pub(super) struct Stranded {
    pub corners: Vec<u32>,
    pub vertices: Vec<u32>,
}

/// The stranded parts of the plan, if any. A part counts when its dead load exceeds what the
/// certificate forgives (`tolerance` times the mean load per vertex) and, for `max-load`,
/// when the live pattern loads none of its vertices (the factor may take either sign and
/// cancel the dead load). A vertex with a prescribed horizontal force is never peeled.
pub(super) fn stranded(model: &Model, tolerance: f64) -> Option<Stranded> {
    let mesh = &model.problem.mesh;
    let with_force = with_force(model);
    let vertices = unsupported(model, &model.carries, tolerance);
    let listed = |v: u32| vertices.binary_search(&v).is_ok();
    // A corner elsewhere (exempt by its live load or its small load) explains nothing here.
    let corners: Vec<u32> = (model.residual.iter().copied())
        .filter(|&v| peelable(model, v) && idle::is_corner(mesh, v, &with_force))
        .filter(|&v| listed(v) || mesh.neighbours(v).any(listed))
        .collect();
    (!vertices.is_empty()).then_some(Stranded { corners, vertices })
}

/// Per edge: whether some compressive state in horizontal balance may load it, as far as
/// peeling corners and straight free edges tells (an edge marked false carries nothing in
/// every such state).
pub(super) fn carrying(model: &Model) -> Vec<bool> {
    let mut balanced = vec![false; model.problem.mesh.positions.len()];
    for &v in model.residual.iter().filter(|&&v| peelable(model, v)) {
        balanced[v as usize] = true;
    }
    idle::carrying(&model.problem.mesh, &with_force(model), &balanced)
}

fn with_force(model: &Model) -> Vec<bool> {
    model.stress.bounds.iter().map(Option::is_some).collect()
}

fn peelable(model: &Model, v: u32) -> bool {
    model.stress.external[v as usize] == [0.0, 0.0]
}

/// The vertices of the loaded parts that the carrying edges join to no support.
fn unsupported(model: &Model, carries: &[bool], tolerance: f64) -> Vec<u32> {
    let mesh = &model.problem.mesh;
    let n = mesh.positions().len();
    let mut parts = Parts::new(n);
    for (e, _) in carries.iter().enumerate().filter(|(_, &c)| c) {
        let [a, b] = mesh.edges()[e].v;
        parts.join(a as usize, b as usize);
    }
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

/// With a floor q_min > 0: the vertices (increasing) at an edge the floor binds (not a
/// polygon's diagonal) that no compressive state loads, where the floor cannot hold.
pub(super) fn floored_idle(model: &Model, settings: &AssessSettings) -> Vec<u32> {
    let (QBound::Absolute(q) | QBound::Relative(q)) = settings.q_min;
    if q <= 0.0 {
        return Vec::new();
    }
    let problem = model.problem;
    let floored = |e: usize| !problem.polygon_diagonal[e];
    let keep = |v: u32| problem.mesh.is_non_anchored(v as usize);
    idle::floored_idle(
        &problem.mesh,
        &with_force(model),
        &model.carries,
        floored,
        keep,
    )
}

/// The answer where a floor cannot hold at `idle`: the middle surface without force.
pub(super) fn unfloored(model: &Model, idle: &[u32]) -> Run {
    Run {
        state: model.start_state(),
        termination: Termination::Infeasible {
            constraint: idle::floor_reason(idle),
        },
        iterations: 0,
        seconds: 0.0,
        unbounded: false,
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
