//! Plan repair: triangles whose plan area is tiny or slightly inverted (a surface that is
//! nearly vertical there, three vertices almost collinear in plan) are mended before
//! validation instead of rejected. An edge flip in plan is used where it gives two valid
//! triangles; otherwise the smallest plan move of a non-anchored vertex that makes the
//! triangle valid without spoiling its neighbours. Larger inverted triangles (a real fold or
//! overhang) are left for [`crate::Mesh::new`] to reject.

use std::collections::{BTreeSet, HashMap};

use crate::{Error, Result};

/// Default tolerance of [`repair_plan`], relative to the median plan area of the faces.
pub const DEFAULT_REPAIR_TOLERANCE: f64 = 1e-4;

/// One change made by [`repair_plan`]. Serialised (in reports) as `{"flip": {...}}` or
/// `{"nudge": {...}}`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum PlanRepair {
    /// Faces `faces[0]` and `faces[1]` shared the edge `removed`; they now share `added`.
    Flip {
        /// The two faces (they keep their ids).
        faces: [usize; 2],
        /// The edge they shared.
        removed: [u32; 2],
        /// The edge they share now.
        added: [u32; 2],
    },
    /// Vertex `vertex` moved in plan from `from` to `to` (its height unchanged), to mend `face`.
    Nudge {
        /// The moved vertex.
        vertex: u32,
        /// The face it mended.
        face: usize,
        /// Its plan position before.
        from: [f64; 2],
        /// Its plan position after.
        to: [f64; 2],
    },
}

impl std::fmt::Display for PlanRepair {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlanRepair::Flip {
                faces,
                removed,
                added,
            } => write!(
                f,
                "faces {} and {}: edge ({}, {}) flipped to ({}, {})",
                faces[0], faces[1], removed[0], removed[1], added[0], added[1]
            ),
            PlanRepair::Nudge {
                vertex,
                face,
                from,
                to,
            } => write!(
                f,
                "face {face}: vertex {vertex} moved in plan by {:.3e}",
                (to[0] - from[0]).hypot(to[1] - from[1])
            ),
        }
    }
}

/// Mends the faces whose plan area, in the orientation of the majority of faces, is below
/// `relative_tolerance` × (median plan area) in magnitude: first by flipping one of its
/// edges where both new triangles are at least that large, else by moving one of its
/// non-anchored vertices in plan (the smallest such move) until its area is twice the
/// tolerance while every other face at that vertex stays valid. Returns the repairs in the
/// order made; faces it cannot mend are left as they are, for [`crate::Mesh::new`] to report.
///
/// Errors: a negative or non-finite tolerance, a face index out of range
/// ([`Error::InvalidArgument`]).
pub fn repair_plan(
    positions: &mut [[f64; 3]],
    faces: &mut [[u32; 3]],
    anchored: &[u32],
    relative_tolerance: f64,
) -> Result<Vec<PlanRepair>> {
    if !(relative_tolerance.is_finite() && relative_tolerance >= 0.0) {
        return Err(Error::InvalidArgument {
            name: "repair tolerance",
            reason: format!("{relative_tolerance} is not a finite number >= 0"),
        });
    }
    let n = positions.len();
    if let Some(t) = faces
        .iter()
        .position(|f| f.iter().any(|&i| i as usize >= n))
    {
        return Err(Error::InvalidArgument {
            name: "faces",
            reason: format!("face {t} refers to a vertex >= {n}"),
        });
    }
    let used = |v: &u32| positions[*v as usize].iter().all(|c| c.is_finite());
    if !faces.iter().flatten().all(used) {
        // Non-finite coordinates are Mesh::new's to report.
        return Ok(Vec::new());
    }
    let mut plan = Plan::new(positions, faces, anchored, relative_tolerance);
    // Faces that may be bad, the lowest first: every face a repair changes is queued again,
    // so the lowest bad face is found without scanning them all (a long polygon's fan has
    // many slivers, and a scan per repair was quadratic).
    let mut queue: BTreeSet<usize> = (0..faces.len())
        .filter(|&t| plan.is_bad(positions, faces, t))
        .collect();
    let mut repairs = Vec::new();
    // Each repair mends a face for good or moves on; the bound only guards against cycles.
    let mut budget = 4 * faces.len().max(1);
    while budget > 0 {
        let Some(t) = queue.pop_first() else {
            break;
        };
        if plan.given_up[t] || !plan.is_bad(positions, faces, t) {
            continue;
        }
        budget -= 1;
        let changed = match plan.flip(positions, faces, t) {
            Some(r) => {
                let PlanRepair::Flip { faces: [t, u], .. } = r else {
                    unreachable!("a flip")
                };
                repairs.push(r);
                vec![t, u]
            }
            None => match plan.nudge(positions, faces, t) {
                Some(r) => {
                    let PlanRepair::Nudge { vertex, .. } = r else {
                        unreachable!("a nudge")
                    };
                    repairs.push(r);
                    plan.faces_at[vertex as usize].clone()
                }
                None => {
                    plan.given_up[t] = true;
                    Vec::new()
                }
            },
        };
        queue.extend(
            changed
                .into_iter()
                .filter(|&u| plan.is_bad(positions, faces, u)),
        );
    }
    Ok(repairs)
}

/// The state of a repair: orientation, threshold, supports and adjacency (kept up to date
/// through flips).
struct Plan {
    /// +1 when most faces are counter-clockwise in plan, else -1.
    sign: f64,
    threshold: f64,
    anchored: Vec<bool>,
    given_up: Vec<bool>,
    /// The faces at each edge (sorted vertex pair).
    edges: HashMap<(u32, u32), Vec<usize>>,
    /// The faces at each vertex.
    faces_at: Vec<Vec<usize>>,
}

fn signed_area(positions: &[[f64; 3]], f: &[u32; 3]) -> f64 {
    let [a, b, c] = f.map(|i| positions[i as usize]);
    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
}

/// The two faces a flip makes, and the edges it removes and adds.
type FlipFaces = ([[u32; 3]; 2], [[u32; 2]; 2]);

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

impl Plan {
    fn new(positions: &[[f64; 3]], faces: &[[u32; 3]], anchored: &[u32], tol: f64) -> Plan {
        let areas: Vec<f64> = faces.iter().map(|f| signed_area(positions, f)).collect();
        let negative = areas.iter().filter(|a| **a < 0.0).count();
        let sign = if 2 * negative > areas.len() {
            -1.0
        } else {
            1.0
        };
        let mut sizes: Vec<f64> = areas.iter().map(|a| a.abs()).collect();
        sizes.sort_by(f64::total_cmp);
        let median = sizes.get(sizes.len() / 2).copied().unwrap_or(0.0);
        let mut flags = vec![false; positions.len()];
        let n = flags.len();
        for &v in anchored.iter().filter(|&&v| (v as usize) < n) {
            flags[v as usize] = true;
        }
        let mut plan = Plan {
            sign,
            threshold: tol * median,
            anchored: flags,
            given_up: vec![false; faces.len()],
            edges: HashMap::new(),
            faces_at: vec![Vec::new(); n],
        };
        for (t, f) in faces.iter().enumerate() {
            plan.attach(t, f);
        }
        plan
    }

    /// Records face `t` with vertices `f` in the adjacency.
    fn attach(&mut self, t: usize, f: &[u32; 3]) {
        for k in 0..3 {
            let list = self.edges.entry(key(f[k], f[(k + 1) % 3])).or_default();
            list.push(t);
            list.sort_unstable();
            self.faces_at[f[k] as usize].push(t);
        }
    }

    /// Removes face `t` with vertices `f` from the adjacency.
    fn detach(&mut self, t: usize, f: &[u32; 3]) {
        for k in 0..3 {
            let e = key(f[k], f[(k + 1) % 3]);
            if let Some(list) = self.edges.get_mut(&e) {
                list.retain(|&u| u != t);
                if list.is_empty() {
                    self.edges.remove(&e);
                }
            }
            self.faces_at[f[k] as usize].retain(|&u| u != t);
        }
    }

    /// Tiny in plan, whichever its orientation.
    fn is_bad(&self, positions: &[[f64; 3]], faces: &[[u32; 3]], t: usize) -> bool {
        signed_area(positions, &faces[t]).abs() < self.threshold
    }

    fn valid(&self, positions: &[[f64; 3]], f: &[u32; 3]) -> bool {
        self.sign * signed_area(positions, f) >= self.threshold
    }

    /// The best flip of an edge of face `t` giving two valid triangles, made.
    fn flip(
        &mut self,
        positions: &[[f64; 3]],
        faces: &mut [[u32; 3]],
        t: usize,
    ) -> Option<PlanRepair> {
        let edges = &self.edges;
        let mut best: Option<(f64, usize, FlipFaces)> = None;
        for k in 0..3 {
            let f = faces[t];
            let (a, b, c) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
            let Some(&[x, y]) = edges.get(&key(a, b)).map(Vec::as_slice) else {
                continue;
            };
            let u = if x == t { y } else { x };
            let g = faces[u];
            // u must run b -> a (consistent orientation); d is its third vertex.
            let Some(j) = (0..3).find(|&j| g[j] == b && g[(j + 1) % 3] == a) else {
                continue;
            };
            let d = g[(j + 2) % 3];
            if d == c || edges.contains_key(&key(c, d)) {
                continue;
            }
            let (new_t, new_u) = ([a, d, c], [d, b, c]);
            if !(self.valid(positions, &new_t) && self.valid(positions, &new_u)) {
                continue;
            }
            let worst = signed_area(positions, &new_t)
                .abs()
                .min(signed_area(positions, &new_u).abs());
            if best.as_ref().is_none_or(|b| worst > b.0) {
                best = Some((worst, u, ([new_t, new_u], [[a, b], [c, d]])));
            }
        }
        let (_, u, ([new_t, new_u], [removed, added])) = best?;
        let (old_t, old_u) = (faces[t], faces[u]);
        self.detach(t, &old_t);
        self.detach(u, &old_u);
        faces[t] = new_t;
        faces[u] = new_u;
        self.attach(t, &new_t);
        self.attach(u, &new_u);
        Some(PlanRepair::Flip {
            faces: [t, u],
            removed,
            added,
        })
    }

    /// The smallest plan move of a non-anchored vertex of face `t` that makes it valid with
    /// a margin while keeping every valid face at that vertex valid, made.
    fn nudge(
        &mut self,
        positions: &mut [[f64; 3]],
        faces: &[[u32; 3]],
        t: usize,
    ) -> Option<PlanRepair> {
        let target = 2.0 * self.threshold;
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        for k in 0..3 {
            let f = faces[t];
            let (v, p, q) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
            if self.anchored[v as usize] {
                continue;
            }
            let (pp, qq) = (positions[p as usize], positions[q as usize]);
            let e = [qq[0] - pp[0], qq[1] - pp[1]];
            let length = e[0].hypot(e[1]);
            if length == 0.0 {
                continue;
            }
            // Area of (v, p, q) grows by length / 2 per unit move along the left normal of p -> q.
            let normal = [-e[1] / length, e[0] / length];
            let area = self.sign * signed_area(positions, &[v, p, q]);
            let step = self.sign * 2.0 * (target - area) / length;
            let old = positions[v as usize];
            let moved = [old[0] + step * normal[0], old[1] + step * normal[1], old[2]];
            if best.as_ref().is_some_and(|b| b.0 <= step.abs()) {
                continue;
            }
            // A valid face at v must stay valid; a bad one must not get worse.
            let incident: Vec<usize> = (self.faces_at[v as usize].iter().copied())
                .filter(|&u| u != t)
                .collect();
            let before: Vec<f64> = incident
                .iter()
                .map(|&u| self.sign * signed_area(positions, &faces[u]))
                .collect();
            positions[v as usize] = moved;
            let keeps = incident.iter().zip(&before).all(|(&u, &b)| {
                self.sign * signed_area(positions, &faces[u]) >= self.threshold.min(b)
            });
            let mended = self.valid(positions, &faces[t]);
            positions[v as usize] = old;
            if keeps && mended {
                best = Some((step.abs(), v, moved));
            }
        }
        let (_, v, moved) = best?;
        let old = positions[v as usize];
        positions[v as usize] = moved;
        Some(PlanRepair::Nudge {
            vertex: v,
            face: t,
            from: [old[0], old[1]],
            to: [moved[0], moved[1]],
        })
    }
}
