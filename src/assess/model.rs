//! The assessment problem in frame units (docs/method.md §1: z′ = z/L₀, p′ = p/p̄,
//! q′ = q L₀/p̄): fixed loads from the envelope, the bounds, the stress constraints, and the
//! functions of a state (residuals, objective, reactions); and the certificate of a run.

use super::envelope::Envelope;
use super::{AssessResult, AssessSettings, Objective, SpringingJoint};
use crate::error::{Error, Result};
use crate::geometry::loads;
use crate::problem::Problem;
use crate::solve::Termination;
use crate::stress::linear::LinearStress;
use crate::stress::{equilibrium, StressSettings, TauMode};

/// A point of the search, in frame units.
#[derive(Debug, Clone, Default)]
pub(super) struct State {
    /// Stress unknowns: q = S y.
    pub y: Vec<f64>,
    /// Force density per mesh edge (0 on edges without force).
    pub q: Vec<f64>,
    /// Height per vertex.
    pub z: Vec<f64>,
    /// The objective's scalar: the thickness scale s or the load factor λ (else unused).
    pub t: f64,
}

pub(super) struct Model<'a> {
    pub problem: &'a Problem,
    pub objective: Objective,
    pub stress: LinearStress,
    pub p_bar: f64,
    pub l0: f64,
    /// Physical self-weight plus extra loads, and the live pattern, per vertex.
    pub dead_physical: Vec<f64>,
    pub live_physical: Vec<f64>,
    /// Frame loads per vertex: the dead loads over p̄, the live pattern over its own mean on
    /// the non-anchored vertices (so that the search's scalar is the same whatever the
    /// pattern's scale).
    pub dead: Vec<f64>,
    pub live: Vec<f64>,
    /// λ per unit of the search's scalar: p̄ over the live pattern's mean (1 without one).
    pub live_unit: f64,
    /// Frame middle heights and half extents per vertex.
    pub middle: Vec<f64>,
    pub half: Vec<f64>,
    /// Frame heights of the start (the middle surface; the mesh's at fixed supports).
    pub z_start: Vec<f64>,
    /// Per vertex: its height is an unknown.
    pub variable: Vec<bool>,
    /// Vertices with a vertical equation (referenced, not anchored).
    pub residual: Vec<u32>,
    /// Referenced anchored vertices.
    pub supports: Vec<u32>,
    /// Per edge with force and exactly one anchored end: (edge, anchored end, other end).
    pub support_edges: Vec<(usize, u32, u32)>,
    /// Plan area share per vertex whose height is an unknown (summing to 1).
    pub area: Vec<f64>,
    /// Σ of the frame dead loads: the unit of thrust.
    pub total_load: f64,
    /// Edge ids around each vertex.
    pub incident: Vec<Vec<u32>>,
    /// Per edge: whether a compressive state in horizontal balance may load it (false for
    /// edges without force and those that free corners and straight free edges idle,
    /// docs/method.md §16.3).
    pub carries: Vec<bool>,
    /// The springing joints of the free supports with a finite reach.
    pub joints: Vec<Joint>,
}

/// A free support's springing joint (frame units): the reaction's line of action, followed
/// from the support down to the springing plane, meets it within the reach. At the scale σ
/// of the half extents the plane lies at m − σ (m − s) and the reach is σ b (the uniformly
/// thinner copy of the envelope about its middle).
pub(super) struct Joint {
    pub support: u32,
    /// (edge, other end) of the edges with force from the support.
    pub edges: Vec<(usize, u32)>,
    /// Springing plane s and reach b at scale 1.
    pub springing: f64,
    pub reach: f64,
}

impl Joint {
    /// The length that turns the joint's moment w |H| − σ b V into a load: b, or the frame's
    /// unit where the reach is 0.
    pub fn unit(&self) -> f64 {
        if self.reach > 0.0 {
            self.reach
        } else {
            1.0
        }
    }
}

/// A joint at a state: w = z_a − s(σ), the horizontal reaction H_a, the vertical one
/// V_a = Σ q_e (z_j − z_a) + p_a (the support's own load included) and the scale σ.
pub(super) struct JointState {
    pub w: f64,
    pub h: [f64; 2],
    pub v: f64,
    pub scale: f64,
}

impl<'a> Model<'a> {
    pub fn new(
        problem: &'a Problem,
        envelope: &Envelope,
        settings: &AssessSettings,
    ) -> Result<Model<'a>> {
        let mesh = &problem.mesh;
        let n = mesh.positions.len();
        check_lengths(problem, envelope)?;
        let middle_positions = envelope.middle_positions(mesh);
        let density: Vec<f64> = (envelope.face_thickness.iter())
            .map(|t| t * settings.unit_weight)
            .collect();
        let dead_physical = loads::vertex_loads(
            mesh,
            &middle_positions,
            settings.load_rule,
            &density,
            &problem.extra_loads,
        );
        let live_physical = live_pattern(problem, settings)?;
        let residual = crate::stress::non_anchored(mesh);
        let p_bar = mean_load(&dead_physical, &residual, envelope, settings)?;
        let live_mean = (residual.iter())
            .map(|&v| live_physical[v as usize])
            .sum::<f64>()
            / residual.len().max(1) as f64;
        let live_scale = if live_mean > 0.0 { live_mean } else { p_bar };
        let stress_settings = StressSettings {
            q_min: settings.q_min,
            tau: TauMode::Zero,
            ..StressSettings::default()
        };
        let stress = LinearStress::new(problem, &middle_positions, &stress_settings, p_bar)?;
        let l0 = stress.frame.scale;
        let supports: Vec<u32> = (0..n as u32)
            .filter(|&v| mesh.referenced[v as usize] && mesh.anchored[v as usize])
            .collect();
        let variable: Vec<bool> = (0..n)
            .map(|v| mesh.referenced[v] && !(settings.fixed_supports && mesh.anchored[v]))
            .collect();
        let z_start: Vec<f64> = (0..n)
            .map(|v| {
                let z = if variable[v] {
                    envelope.middle[v]
                } else {
                    mesh.positions[v][2]
                };
                z / l0
            })
            .collect();
        let incident = (0..n)
            .map(|v| {
                let (a, b) = (mesh.vertex_edge_start[v], mesh.vertex_edge_start[v + 1]);
                mesh.vertex_edges[a as usize..b as usize].to_vec()
            })
            .collect();
        let model = Model {
            problem,
            objective: settings.objective,
            p_bar,
            l0,
            dead: dead_physical.iter().map(|p| p / p_bar).collect(),
            live: live_physical.iter().map(|p| p / live_scale).collect(),
            live_unit: p_bar / live_scale,
            dead_physical,
            live_physical,
            middle: envelope.middle.iter().map(|m| m / l0).collect(),
            half: envelope.half_extent().iter().map(|h| h / l0).collect(),
            z_start,
            joints: joints(problem, &stress, envelope, settings, l0),
            support_edges: support_edges(problem, &stress),
            area: area_shares(problem, &stress, &variable),
            total_load: 0.0,
            variable,
            residual,
            supports,
            incident,
            carries: Vec::new(),
            stress,
        };
        model.check_fixed_supports(settings)?;
        let mut model = Model {
            total_load: model.residual.iter().map(|&v| model.dead[v as usize]).sum(),
            carries: super::corners::carrying(&model),
            ..model
        };
        model.release_idle_edges();
        Ok(model)
    }

    /// Lowers the bound of every idled edge (`carries` false) to zero force: a floor there
    /// could never hold (the retry's floor; a user's q_min > 0 is refused before any search,
    /// `corners::floored_idle`).
    fn release_idle_edges(&mut self) {
        for (bound, &carries) in self.stress.bounds.iter_mut().zip(&self.carries) {
            if let (Some((lo, _)), false) = (bound.as_mut(), carries) {
                *lo = lo.min(0.0);
            }
        }
    }

    /// Fixed supports must lie inside the envelope (at any scale, for the least thickness).
    fn check_fixed_supports(&self, settings: &AssessSettings) -> Result<()> {
        if !settings.fixed_supports {
            return Ok(());
        }
        for &a in &self.supports {
            let a = a as usize;
            let excess = (self.z_start[a] - self.middle[a]).abs() - self.half[a];
            let slack = if self.objective == Objective::MinThickness {
                f64::INFINITY
            } else {
                1e-12
            };
            if excess > slack || (self.half[a] == 0.0 && excess > 1e-12) {
                return Err(Error::InvalidArgument {
                    name: "fixed_supports",
                    reason: format!(
                        "support vertex {a} at height {} lies outside the envelope [{}, {}]",
                        self.z_start[a] * self.l0,
                        (self.middle[a] - self.half[a]) * self.l0,
                        (self.middle[a] + self.half[a]) * self.l0
                    ),
                });
            }
        }
        Ok(())
    }

    /// The searches' start: the start heights without force (scale 1 for the least
    /// thickness).
    pub fn start_state(&self) -> State {
        State {
            y: vec![0.0; self.stress.s().ncols],
            q: vec![0.0; self.stress.bounds.len()],
            z: self.z_start.clone(),
            t: match self.objective {
                Objective::MinThickness => 1.0,
                _ => 0.0,
            },
        }
    }

    /// The scale of the half extents at `state`.
    pub fn scale(&self, state: &State) -> f64 {
        if self.objective == Objective::MinThickness {
            state.t
        } else {
            1.0
        }
    }

    /// Frame load at vertex v.
    pub fn load(&self, state: &State, v: usize) -> f64 {
        if self.objective == Objective::MaxLoad {
            self.dead[v] + state.t * self.live[v]
        } else {
            self.dead[v]
        }
    }

    /// Vertical residual c_i = Σ q_e (z_i − z_j) − p_i per vertex of `residual`.
    pub fn residuals(&self, state: &State) -> Vec<f64> {
        let edges = &self.problem.mesh.edges;
        (self.residual.iter())
            .map(|&i| {
                let i = i as usize;
                let sum: f64 = (self.incident[i].iter())
                    .map(|&e| {
                        let j = other_end(edges[e as usize].v, i);
                        state.q[e as usize] * (state.z[i] - state.z[j])
                    })
                    .sum();
                sum - self.load(state, i)
            })
            .collect()
    }

    /// Horizontal reaction per vertex (frame; non-zero at supports).
    pub fn reactions(&self, q: &[f64]) -> Vec<[f64; 2]> {
        let u = &self.stress.plan.u;
        let mut r = vec![[0.0; 2]; u.len()];
        for &(e, a, j) in &self.support_edges {
            let (a, j) = (a as usize, j as usize);
            for d in 0..2 {
                r[a][d] += q[e] * (u[a][d] - u[j][d]);
            }
        }
        r
    }

    /// Σ |reaction| over the supports, over the total load.
    pub fn thrust(&self, q: &[f64]) -> f64 {
        let r = self.reactions(q);
        let sum: f64 = (self.supports.iter())
            .map(|&a| r[a as usize][0].hypot(r[a as usize][1]))
            .sum();
        sum / self.total_load
    }

    /// Joint k at `state`.
    pub fn joint_state(&self, state: &State, k: usize) -> JointState {
        let joint = &self.joints[k];
        let a = joint.support as usize;
        let u = &self.stress.plan.u;
        let scale = self.scale(state);
        let (mut h, mut v) = ([0.0; 2], self.load(state, a));
        for &(e, j) in &joint.edges {
            let j = j as usize;
            for d in 0..2 {
                h[d] += state.q[e] * (u[a][d] - u[j][d]);
            }
            v += state.q[e] * (state.z[j] - state.z[a]);
        }
        let w = state.z[a] - (self.middle[a] - scale * self.springing_rate(k));
        JointState { w, h, v, scale }
    }

    /// ∂w/∂s of joint k: the uniformly thinner envelope moves the springing plane towards the
    /// middle surface, w = z_a − (m − s (m − springing)).
    pub fn springing_rate(&self, k: usize) -> f64 {
        let joint = &self.joints[k];
        self.middle[joint.support as usize] - joint.springing
    }

    /// Per joint g = (w |H| − σ b V) / b, in load units: > 0 where the reaction's line
    /// meets the springing plane beyond the reach.
    pub fn joint_excess(&self, state: &State) -> Vec<f64> {
        (0..self.joints.len())
            .map(|k| {
                let j = self.joint_state(state, k);
                let joint = &self.joints[k];
                (j.w * j.h[0].hypot(j.h[1]) - j.scale * joint.reach * j.v) / joint.unit()
            })
            .collect()
    }

    /// The largest violation (|residual| or joint excess) and the ℓ1 sum of both.
    pub fn violation(&self, state: &State) -> (f64, f64) {
        let c = self.residuals(state);
        let g = self.joint_excess(state);
        let max = (c.iter().map(|x| x.abs()))
            .chain(g.iter().map(|x| x.max(0.0)))
            .fold(0.0, f64::max);
        let sum =
            c.iter().map(|x| x.abs()).sum::<f64>() + g.iter().map(|x| x.max(0.0)).sum::<f64>();
        (max, sum)
    }

    /// The objective f at `state` (lower is better).
    pub fn objective_value(&self, state: &State) -> f64 {
        match self.objective {
            Objective::Fit => (0..state.z.len())
                .filter(|&v| self.variable[v])
                .map(|v| self.area[v] * (state.z[v] - self.middle[v]).powi(2))
                .sum(),
            Objective::MinThickness => state.t,
            Objective::MinThrust => self.thrust(&state.q),
            Objective::MaxThrust => -self.thrust(&state.q),
            Objective::MaxLoad => -state.t,
        }
    }

    /// The certificate of the run's state, in physical units.
    pub fn certify(&self, run: Run, settings: &AssessSettings) -> AssessResult {
        let mesh = &self.problem.mesh;
        let state = &run.state;
        let n = mesh.positions.len();
        let positions: Vec<[f64; 3]> = (0..n)
            .map(|v| {
                let p = mesh.positions[v];
                if mesh.referenced[v] {
                    [p[0], p[1], state.z[v] * self.l0]
                } else {
                    p
                }
            })
            .collect();
        let unit = self.p_bar / self.l0;
        let force_densities: Vec<f64> = state.q.iter().map(|q| q * unit).collect();
        let lambda = if self.objective == Objective::MaxLoad {
            state.t * self.live_unit
        } else {
            0.0
        };
        let loads: Vec<f64> = (self.dead_physical.iter().zip(&self.live_physical))
            .map(|(d, l)| d + lambda * l)
            .collect();
        let external: Vec<[f64; 2]> = (self.stress.external.iter())
            .map(|f| [f[0] * self.p_bar, f[1] * self.p_bar])
            .collect();
        let (residuals, imbalance) =
            equilibrium(mesh, &positions, &force_densities, &loads, &external);
        // The mean of the returned loads (λ × pattern included) over the non-anchored vertices.
        let mean = (self.residual.iter())
            .map(|&v| loads[v as usize])
            .sum::<f64>()
            / self.residual.len() as f64;
        let (worst_residual_vertex, max_r) = (self.residual.iter())
            .map(|&v| (v, residuals[v as usize].abs()))
            .fold((None, 0.0), |(bv, bm), (v, m)| {
                if m > bm || bv.is_none() {
                    (Some(v), m)
                } else {
                    (bv, bm)
                }
            });
        let horizontal = (self.residual.iter())
            .map(|&v| imbalance[v as usize][0].hypot(imbalance[v as usize][1]))
            .fold(0.0, f64::max);
        let s = self.scale(state);
        let lower: Vec<f64> = (0..n)
            .map(|v| (self.middle[v] - s * self.half[v]) * self.l0)
            .collect();
        let upper: Vec<f64> = (0..n)
            .map(|v| (self.middle[v] + s * self.half[v]) * self.l0)
            .collect();
        let worst_bound = worst_bound(mesh, &positions, &lower, &upper);
        let q_ok = (self.stress.bounds.iter().zip(&force_densities))
            .all(|(b, q)| b.is_none_or(|(lo, hi)| *q >= lo * unit && *q <= hi * unit));
        let eps_inf = max_r / mean;
        let diag = 2.0 * self.l0;
        let reactions: Vec<[f64; 2]> = (self.reactions(&state.q).iter())
            .map(|r| [r[0] * self.p_bar, r[1] * self.p_bar])
            .collect();
        let thrust_horizontal = (self.supports.iter())
            .map(|&a| reactions[a as usize][0].hypot(reactions[a as usize][1]))
            .sum();
        let (joints, worst_joint) = self.joints_of(&positions, &force_densities, &loads, s, mean);
        let feasible = eps_inf < settings.tolerance
            && horizontal / mean < settings.tolerance
            && q_ok
            && worst_bound.0 <= 1e-9 * diag
            && worst_joint.0 < settings.tolerance
            && (joints.iter())
                .all(|j| positions[j.vertex as usize][2] >= j.springing - 1e-9 * diag);
        AssessResult {
            objective: self.objective,
            feasible,
            unbounded: feasible && run.unbounded,
            termination: run.termination,
            iterations: run.iterations,
            positions,
            force_densities,
            loads,
            residuals,
            eps_inf,
            horizontal_imbalance: horizontal / mean,
            lower,
            upper,
            thickness_scale: s,
            safety_factor: 1.0 / s,
            reactions,
            thrust_horizontal,
            load_factor: lambda,
            worst_bound,
            joints,
            worst_joint,
            worst_residual_vertex,
            needed_scale: None,
            stranded: Vec::new(),
            seconds: run.seconds,
        }
    }
}

impl Model<'_> {
    /// The joints recomputed from physical outputs at scale `s`, and the largest excess
    /// over the reach's unit × the mean load `mean`.
    fn joints_of(
        &self,
        positions: &[[f64; 3]],
        q: &[f64],
        loads: &[f64],
        s: f64,
        mean: f64,
    ) -> (Vec<SpringingJoint>, (f64, Option<u32>)) {
        let mut worst = (0.0, None);
        let joints = (self.joints.iter())
            .map(|joint| {
                let a = joint.support as usize;
                let p = positions[a];
                let (mut h, mut v) = ([0.0; 2], loads[a]);
                for &(e, j) in &joint.edges {
                    let o = positions[j as usize];
                    h = [h[0] + q[e] * (p[0] - o[0]), h[1] + q[e] * (p[1] - o[1])];
                    v += q[e] * (o[2] - p[2]);
                }
                let m = self.middle[a] * self.l0;
                let springing = m - s * (m - joint.springing * self.l0);
                let reach = s * joint.reach * self.l0;
                let w = p[2] - springing;
                let hn = h[0].hypot(h[1]);
                let excess = (w * hn - reach * v).max(0.0) / (joint.unit() * self.l0 * mean);
                if excess > worst.0 {
                    worst = (excess, Some(joint.support));
                }
                let (point, offset) = if hn == 0.0 {
                    ([p[0], p[1], springing], 0.0)
                } else if v > 0.0 {
                    let k = w / v;
                    ([p[0] + k * h[0], p[1] + k * h[1], springing], k * hn)
                } else {
                    let far = f64::INFINITY;
                    ([far * h[0].signum(), far * h[1].signum(), springing], far)
                };
                SpringingJoint {
                    vertex: joint.support,
                    springing,
                    reach,
                    horizontal: h,
                    vertical: v,
                    point,
                    offset,
                }
            })
            .collect();
        (joints, worst)
    }
}

pub(super) fn other_end(v: [u32; 2], i: usize) -> usize {
    if v[0] as usize == i {
        v[1] as usize
    } else {
        v[0] as usize
    }
}

fn check_lengths(problem: &Problem, envelope: &Envelope) -> Result<()> {
    let mesh = &problem.mesh;
    let n = mesh.positions.len();
    for (name, len, want) in [
        ("envelope", envelope.lower.len(), n),
        ("envelope", envelope.upper.len(), n),
        ("envelope", envelope.middle.len(), n),
        ("envelope", envelope.face_thickness.len(), mesh.faces.len()),
        ("envelope", envelope.springing.len(), n),
        ("envelope", envelope.reach.len(), n),
    ] {
        if len != want {
            return Err(Error::InvalidArgument {
                name,
                reason: format!("was built for another mesh: {len} entries, expected {want}"),
            });
        }
    }
    Ok(())
}

fn live_pattern(problem: &Problem, settings: &AssessSettings) -> Result<Vec<f64>> {
    let n = problem.mesh.positions.len();
    match (&settings.load_pattern, settings.objective) {
        (Some(p), Objective::MaxLoad) => {
            crate::validate::one_per_vertex("load_pattern", p.len(), n)?;
            let free = crate::stress::non_anchored(&problem.mesh);
            if free.iter().all(|&v| p[v as usize] == 0.0) {
                return Err(Error::InvalidArgument {
                    name: "load_pattern",
                    reason: "is 0 on every non-anchored vertex: there is no load to multiply"
                        .into(),
                });
            }
            Ok(p.clone())
        }
        (None, Objective::MaxLoad) => Err(Error::InvalidArgument {
            name: "load_pattern",
            reason: "the max-load analysis needs a load pattern (one load per vertex)".into(),
        }),
        _ => Ok(vec![0.0; n]),
    }
}

/// p̄, the mean of the self-weight and extra loads over the non-anchored vertices; where it
/// is not positive, the error names what weighs nothing (`unit_weight` 0, an envelope without
/// thickness), else the loads.
fn mean_load(
    load: &[f64],
    free: &[u32],
    envelope: &Envelope,
    settings: &AssessSettings,
) -> Result<f64> {
    if free.is_empty() {
        return Err(Error::InvalidArgument {
            name: "supports",
            reason: "every vertex is anchored: there is no vault to assess".into(),
        });
    }
    let mean = free.iter().map(|&v| load[v as usize]).sum::<f64>() / free.len() as f64;
    if mean.is_finite() && mean > 0.0 {
        return Ok(mean);
    }
    let positive = "a masonry vault stands under a positive downward load";
    let (name, reason) = if settings.unit_weight == 0.0 {
        let reason = format!(
            "is 0, so the masonry weighs nothing, and the extra loads on the non-anchored \
             vertices (max-load's pattern aside) average {mean:e}: {positive}"
        );
        ("unit_weight", reason)
    } else if envelope.face_thickness.iter().all(|&t| t == 0.0) {
        let reason = format!(
            "has no thickness at any face (intrados and extrados coincide), so the masonry \
             weighs nothing, and the extra loads on the non-anchored vertices average \
             {mean:e}: {positive}"
        );
        ("envelope", reason)
    } else {
        let reason = format!(
            "the self-weight and extra loads on the non-anchored vertices average {mean:e}: \
             {positive}"
        );
        ("loads", reason)
    };
    Err(Error::InvalidArgument { name, reason })
}

fn support_edges(problem: &Problem, stress: &LinearStress) -> Vec<(usize, u32, u32)> {
    let mesh = &problem.mesh;
    (mesh.edges.iter().enumerate())
        .filter(|(e, _)| stress.bounds[*e].is_some())
        .filter_map(|(e, edge)| {
            let [a, b] = edge.v;
            match (mesh.anchored[a as usize], mesh.anchored[b as usize]) {
                (true, false) => Some((e, a, b)),
                (false, true) => Some((e, b, a)),
                _ => None,
            }
        })
        .collect()
}

/// The free supports' springing joints with a finite reach (none with fixed supports).
fn joints(
    problem: &Problem,
    stress: &LinearStress,
    envelope: &Envelope,
    settings: &AssessSettings,
    l0: f64,
) -> Vec<Joint> {
    if settings.fixed_supports {
        return Vec::new();
    }
    let mesh = &problem.mesh;
    let edges = support_edges(problem, stress);
    (0..mesh.positions.len())
        .filter(|&a| mesh.referenced[a] && mesh.anchored[a] && envelope.reach[a].is_finite())
        .map(|a| Joint {
            support: a as u32,
            edges: (edges.iter())
                .filter(|&&(_, s, _)| s as usize == a)
                .map(|&(e, _, j)| (e, j))
                .collect(),
            springing: envelope.springing[a] / l0,
            reach: envelope.reach[a] / l0,
        })
        .collect()
}

/// A third of each face's plan area per corner, over the vertices whose height is an
/// unknown, normalised to sum 1.
fn area_shares(problem: &Problem, stress: &LinearStress, variable: &[bool]) -> Vec<f64> {
    let mesh = &problem.mesh;
    let mut a = vec![0.0; variable.len()];
    for (t, f) in mesh.faces.iter().enumerate() {
        for &v in f {
            if variable[v as usize] {
                a[v as usize] += stress.plan.area[t] / 3.0;
            }
        }
    }
    let total: f64 = a.iter().sum();
    if total > 0.0 {
        a.iter_mut().for_each(|x| *x /= total);
    }
    a
}

/// The largest excess of a height over its bound (0 when all are inside) and its vertex.
fn worst_bound(
    mesh: &crate::mesh::Mesh,
    positions: &[[f64; 3]],
    lower: &[f64],
    upper: &[f64],
) -> (f64, Option<u32>) {
    (0..positions.len())
        .filter(|&v| mesh.referenced[v])
        .map(|v| {
            let z = positions[v][2];
            ((lower[v] - z).max(z - upper[v]), v as u32)
        })
        .fold(
            (0.0, None),
            |(bm, bv), (m, v)| {
                if m > bm {
                    (m, Some(v))
                } else {
                    (bm, bv)
                }
            },
        )
}

/// What the search (`sqp::solve`) returns: the best state reached and how it ended.
pub(super) struct Run {
    pub state: State,
    pub termination: Termination,
    pub iterations: usize,
    pub seconds: f64,
    /// The state starts a certified ray along which the objective has no bound (ray.rs).
    pub unbounded: bool,
}
