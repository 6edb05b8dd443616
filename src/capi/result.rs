//! `VsrResult` and its copy-out getters.
//!
//! Every array getter has the shape `(result, out, len, needed)`: `out` is a buffer of `len`
//! elements (or NULL with `len` 0 to query the size), `needed` (may be NULL) receives the
//! number of elements the data has, on success and on `VSR_STATUS_BUFFER_TOO_SMALL`; `out`
//! is written only on success.

use super::boundary::{boundary, c_string, copy, free, handle, out_ptr, scalars, CResult, Failure};
use super::status::{VsrQpSolver, VsrResultKind, VsrStatus, VsrStressStatus, VsrTermination};
use crate::mesh::Mesh;
use crate::stress::StressResult;
use crate::{FormFindResult, Termination};
use std::ffi::c_char;

pub(crate) enum Outcome {
    Analysis {
        positions: Vec<[f64; 3]>,
        stress: StressResult,
    },
    FormFinding(FormFindResult),
}

/// Opaque handle: the outcome of `vsr_analyse` or `vsr_form_find`. It owns copies of
/// everything it reports; free with `vsr_result_destroy`. Immutable: a `const VsrResult*`
/// may be read from several threads at once.
pub struct VsrResult {
    outcome: Outcome,
    /// Edge vertex pairs, flattened (#E by 2).
    edges: Vec<u32>,
    n_faces: usize,
}

impl VsrResult {
    pub(crate) fn new(mesh: &Mesh, outcome: Outcome) -> VsrResult {
        VsrResult {
            outcome,
            edges: mesh.edges.iter().flat_map(|e| e.v).collect(),
            n_faces: mesh.n_faces(),
        }
    }

    fn stress(&self) -> &StressResult {
        match &self.outcome {
            Outcome::Analysis { stress, .. } => stress,
            Outcome::FormFinding(f) => &f.stress,
        }
    }

    pub(crate) fn positions(&self) -> &[[f64; 3]] {
        match &self.outcome {
            Outcome::Analysis { positions, .. } => positions,
            Outcome::FormFinding(f) => &f.positions,
        }
    }

    /// The form finding this result holds, for the argument `name` of a warm re-solve.
    pub(crate) fn form_found(&self, name: &str) -> CResult<&FormFindResult> {
        match &self.outcome {
            Outcome::FormFinding(f) => Ok(f),
            Outcome::Analysis { .. } => Err(Failure::new(
                VsrStatus::InvalidArgument,
                format!(
                    "argument `{name}`: a warm re-solve starts from a result of vsr_form_find, \
                     and this one comes from vsr_analyse"
                ),
            )),
        }
    }

    fn form(&self, what: &str) -> CResult<&FormFindResult> {
        match &self.outcome {
            Outcome::FormFinding(f) => Ok(f),
            Outcome::Analysis { .. } => Err(Failure::new(
                VsrStatus::NotAvailable,
                format!(
                    "argument `result`: only a result of vsr_form_find has {what}, and this \
                     one comes from vsr_analyse"
                ),
            )),
        }
    }
}

fn flat2(v: &[[f64; 2]]) -> Vec<f64> {
    v.iter().flatten().copied().collect()
}

/// Frees a result. NULL is a no-op.
///
/// # Safety
/// `result` must be NULL or a handle from a solve not yet destroyed, used by no other thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_destroy(result: *mut VsrResult) {
    // SAFETY: forwarded caller's contract.
    boundary!(keep_error, (), { unsafe { free(result) } })
}

/// Which solve produced the result: `VSR_RESULT_KIND_ANALYSIS` or
/// `VSR_RESULT_KIND_FORM_FINDING`. Written only on success.
///
/// # Safety
/// `result`: a valid handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_kind(
    result: *const VsrResult,
    out: *mut VsrResultKind,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            scalars("result", result, [("out", out)], |r| {
                Ok([match r.outcome {
                    Outcome::Analysis { .. } => VsrResultKind::Analysis,
                    Outcome::FormFinding(_) => VsrResultKind::FormFinding,
                }])
            })
        }
    })
}

/// Sizes of the arrays of a result: vertices #V, edges #E, faces #F, holes #H (as for
/// `vsr_mesh_counts`). All four pointers required; written only on success.
///
/// # Safety
/// `result`: a valid handle; the out-pointers writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_counts(
    result: *const VsrResult,
    n_vertices: *mut usize,
    n_edges: *mut usize,
    n_faces: *mut usize,
    n_holes: *mut usize,
) -> VsrStatus {
    boundary!({
        let outs = [
            ("n_vertices", n_vertices),
            ("n_edges", n_edges),
            ("n_faces", n_faces),
            ("n_holes", n_holes),
        ];
        // SAFETY: forwarded caller's contract.
        unsafe {
            scalars("result", result, outs, |r| {
                Ok([
                    r.positions().len(),
                    r.edges.len() / 2,
                    r.n_faces,
                    r.stress().hole_coefficients.len(),
                ])
            })
        }
    })
}

/// Vertex positions, #V by 3 doubles (x, y, z), row-major, in the input's length unit: the
/// form-found shape (heights moved; the plan too when ODT sweeps are on), or the input for an
/// analysis.
/// Copy-out as described in the header's introduction.
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_positions(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(r.positions().iter().flatten().copied().collect())
            })
        }
    })
}

/// Edges, #E by 2 `uint32_t` vertex ids (smaller first), row-major, sorted; row e is edge e
/// of every per-edge array.
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable elements; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_edges(
    result: *const VsrResult,
    out: *mut u32,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe { copy("result", result, out, len, needed, |r| Ok(r.edges.clone())) }
    })
}

/// Force density per edge, #E doubles (force per length; compression positive, 0 on edges
/// that carry none, e.g. boundary edges between two supports).
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_force_densities(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(r.stress().force_densities.clone())
            })
        }
    })
}

/// Airy stress function value φ per vertex, #V doubles (force × length; 0 at vertices used by
/// no triangle). φ is defined up to an affine function, which changes no force: the reduced
/// formulation pins it to 0 at three free vertices far apart in each connected part (at the
/// first face where there are no three such), the edge-based one integrates it from the
/// first face; compare forces, not φ, between runs.
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_airy(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(r.stress().airy.clone())
            })
        }
    })
}

/// Vertex weights w = x² + y² − 2 φ, #V doubles (the power diagram of the plan points with
/// these weights is the force diagram, except along the holes' cuts where φ jumps (it is
/// multivalued there; see `vsr_result_hole_coefficients`); units as in the paper, length² and force × length mixed, so
/// meaningful for unit loads). Like φ, defined up to an affine function (see
/// `vsr_result_airy`).
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_weights(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(r.stress().weights.clone())
            })
        }
    })
}

/// Inward normal push τ per vertex, #V doubles (force; non-zero only at free boundary
/// vertices; a non-zero τ means the free edge needs a tie or buttress there).
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_tau(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(r.stress().tau.clone())
            })
        }
    })
}

/// External horizontal force per vertex needed at free edges (prescribed force − τ × outward
/// normal), #V by 2 doubles (fx, fy; force), row-major; 0 away from free boundary vertices.
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_external_horizontal(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(flat2(&r.stress().external_horizontal))
            })
        }
    })
}

/// Vertical load per vertex, #V doubles (force, downward positive): face weights shared by
/// the load rule plus extra loads, at the result's shape (for form finding, the final one).
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_loads(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(r.stress().loads.clone())
            })
        }
    })
}

/// Vertical residual r_i = Σ_j q_ij (z_i − z_j) − p_i per vertex, #V doubles (force; 0 at
/// anchored and unused vertices), recomputed from the returned force densities: the
/// certificate of equilibrium.
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_residuals(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(r.stress().residuals.clone())
            })
        }
    })
}

/// Horizontal imbalance Σ_j q_ij (u_i − u_j) + external force per vertex, #V by 2 doubles
/// (force), row-major. Exact by construction at interior vertices up to rounding (measured
/// ≤ 1e-10 of Σ|q| l + load); at free boundary vertices it is the QP solver's feasibility
/// accuracy (measured ≤ 1e-9 relative).
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_horizontal_imbalance(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(flat2(&r.stress().horizontal_imbalance))
            })
        }
    })
}

/// Airy jump around each hole M_h(x, y) = c + a_x x + a_y y (the change of the Airy function
/// continued once counter-clockwise around the hole), #H by 3 doubles (c in force × length;
/// a_x, a_y in force), row-major, holes in the order of the mesh's boundary loops. The solver
/// cuts the domain along a tree of shortest paths, each from a hole to the outer loop or to a
/// hole cut before it; across hole h's cut φ jumps by the sum of the coefficients of h and of
/// every hole cut through h.
/// With `VSR_HOLE_MODE_CONSTANT` a_x = a_y = 0. Empty (0 entries) for the edge-based
/// formulation, which has no hole unknowns.
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_hole_coefficients(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(r.stress()
                    .hole_coefficients
                    .iter()
                    .flatten()
                    .copied()
                    .collect())
            })
        }
    })
}

/// Force diagram points: one per face, the gradient of the Airy function on it, #F by 2
/// doubles (force), row-major, in face order. This is the power centre of the face's weighted
/// vertices except on the faces along a hole's cut where the Airy function jumps (it is
/// multivalued there; see `vsr_result_hole_coefficients`). Defined up to a
/// translation, as φ is up to an affine function (`vsr_result_airy`).
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_force_diagram_centres(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(flat2(&r.stress().force_diagram.centres))
            })
        }
    })
}

/// Force diagram segments: one per interior edge, in increasing edge id, #S by 4 doubles
/// (x0, y0, x1, y1; force), row-major: the points of the edge's left and right face (across
/// a hole's cut the right point is shifted by the gradient of the jump there). Its length over the edge's
/// plan length is the edge's force density. The edge ids are given, in the same order, by
/// `vsr_result_force_diagram_segment_edges`.
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_force_diagram_segments(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(r.stress()
                    .force_diagram
                    .segments
                    .iter()
                    .flatten()
                    .flat_map(|s| [s[0][0], s[0][1], s[1][0], s[1][1]])
                    .collect())
            })
        }
    })
}

/// Edge id of each force diagram segment, #S `uint32_t` (the interior edges, increasing).
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable elements; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_force_diagram_segment_edges(
    result: *const VsrResult,
    out: *mut u32,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(r.stress()
                    .force_diagram
                    .segments
                    .iter()
                    .enumerate()
                    .filter(|(_, s)| s.is_some())
                    .map(|(e, _)| e as u32)
                    .collect())
            })
        }
    })
}

/// ε∞ per form-finding iteration, one double per stress step (dimensionless), plus a last
/// one when the loop converged on the last shape step's certificate: the previous forces
/// recomputed at the new heights (the result's forces and residuals are then those). A step
/// that stopped short of its optimum and balanced the shape worse than the previous forces
/// at the same heights is not taken, and its entry is those forces' ε∞. For an analysis
/// result: `VSR_STATUS_NOT_AVAILABLE` (use `vsr_result_stress_summary`).
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_eps_history(
    result: *const VsrResult,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(r.form("an eps history")?.history.clone())
            })
        }
    })
}

/// The solver that answered each form-finding stress step, one `VsrQpSolver` per step (as
/// many as `vsr_result_termination`'s iterations, a step whose answer gave way to the forces
/// at hand included): `VSR_QP_SOLVER_CLARABEL` where clarabel was asked for, or where the
/// native one was but did not converge (much slower). For an analysis result:
/// `VSR_STATUS_NOT_AVAILABLE` (use `vsr_result_qp_solver`).
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable values; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_step_solvers(
    result: *const VsrResult,
    out: *mut VsrQpSolver,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                let steps = &r.form("the step solvers")?.solvers;
                Ok(steps.iter().map(|&s| VsrQpSolver::of(s)).collect())
            })
        }
    })
}

/// Summary of the result's forces: `status` (a `VsrStressStatus`) and `qp_iterations` of the
/// interior-point solver of the stress step that produced them (0 when a form-finding step
/// was solved from the previous step's active set alone), `eps_inf` = max |r_i| / mean p_i
/// over non-anchored vertices (dimensionless) and `objective` = Σ r_i² (force²), both at the
/// result's shape (for form finding, the final one: the forces may come from an earlier step
/// than the shape). All four pointers required; written only on
/// success.
///
/// # Safety
/// `result`: a valid handle; the out-pointers writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_stress_summary(
    result: *const VsrResult,
    status: *mut VsrStressStatus,
    eps_inf: *mut f64,
    objective: *mut f64,
    qp_iterations: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let r = unsafe { handle("result", result)? };
        let outs = (
            out_ptr("status", status)?,
            out_ptr("eps_inf", eps_inf)?,
            out_ptr("objective", objective)?,
            out_ptr("qp_iterations", qp_iterations)?,
        );
        let s = r.stress();
        // SAFETY: all non-NULL and writable (caller's contract).
        unsafe {
            outs.0.write(VsrStressStatus::of(s.status));
            outs.1.write(s.eps_inf);
            outs.2.write(s.objective);
            outs.3.write(s.iterations as usize);
        }
        Ok(())
    })
}

/// The regulariser ε actually used by the stress step that produced the result's forces
/// (larger than the setting after
/// a numerical failure was retried). Written only on success.
///
/// # Safety
/// `result`: a valid handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_regularisation(
    result: *const VsrResult,
    out: *mut f64,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            scalars("result", result, [("out", out)], |r| {
                Ok([r.stress().regularisation])
            })
        }
    })
}

/// The solver that produced the result's forces: `VSR_QP_SOLVER_CLARABEL` when
/// the native one was asked for but did not converge. Written only on success.
///
/// # Safety
/// `result`: a valid handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_qp_solver(
    result: *const VsrResult,
    out: *mut VsrQpSolver,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            scalars("result", result, [("out", out)], |r| {
                Ok([VsrQpSolver::of(r.stress().solver)])
            })
        }
    })
}

/// Why form finding stopped (a `VsrTermination`) and how many iterations (stress steps) it
/// ran. Both pointers required; written only on success. For an analysis result:
/// `VSR_STATUS_NOT_AVAILABLE`.
///
/// # Safety
/// `result`: a valid handle; the out-pointers writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_termination(
    result: *const VsrResult,
    termination: *mut VsrTermination,
    iterations: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let r = unsafe { handle("result", result)? };
        let (t, i) = (
            out_ptr("termination", termination)?,
            out_ptr("iterations", iterations)?,
        );
        let f = r.form("the termination")?;
        // SAFETY: non-NULL and writable (caller's contract).
        unsafe {
            t.write(VsrTermination::of(&f.termination));
            i.write(f.iterations);
        }
        Ok(())
    })
}

/// A one-line explanation of the termination, as a NUL-terminated UTF-8 string copied into
/// `out` (`len` bytes; `needed` counts the terminating NUL). For `VSR_TERMINATION_INFEASIBLE`
/// it names the constraints to relax, for `VSR_TERMINATION_NUMERICAL_ERROR` where it failed,
/// for `VSR_TERMINATION_STALLED` the blocking vertices. For an analysis result:
/// `VSR_STATUS_NOT_AVAILABLE`.
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable bytes; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_termination_message(
    result: *const VsrResult,
    out: *mut c_char,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                let text = r.form("the termination message")?.termination.to_string();
                Ok(c_string(&text))
            })
        }
    })
}

/// Vertices listed by a `VSR_TERMINATION_STALLED` or `VSR_TERMINATION_BLOCKED` form
/// finding, `uint32_t` ids (0 entries for any other termination). For an analysis result: `VSR_STATUS_NOT_AVAILABLE`.
///
/// # Safety
/// `result`: a valid handle; `out`: NULL or `len` writable elements; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_stalled_vertices(
    result: *const VsrResult,
    out: *mut u32,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("result", result, out, len, needed, |r| {
                Ok(match &r.form("the stalled vertices")?.termination {
                    Termination::Stalled { vertices } | Termination::Blocked { vertices, .. } => {
                        vertices.clone()
                    }
                    _ => Vec::new(),
                })
            })
        }
    })
}

/// The height change of a form finding, over the plan bounding-box diagonal
/// (dimensionless): `rms` = the RMS change of the non-anchored vertices weighted by their plan
/// area shares (the nearest method's objective), `max` = the largest change at any vertex.
/// Both pointers required; written only on success. For an analysis result:
/// `VSR_STATUS_NOT_AVAILABLE`.
///
/// # Safety
/// `result`: a valid handle; the out-pointers writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_height_change(
    result: *const VsrResult,
    rms: *mut f64,
    max: *mut f64,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            scalars("result", result, [("rms", rms), ("max", max)], |r| {
                let f = r.form("the height change")?;
                Ok([f.rms_change, f.max_change])
            })
        }
    })
}

/// Whether form finding read the input as drawn upside down (docs/method.md §13.1): 1 when
/// the input hung below the unloaded surface over its supports and the search started from,
/// and stayed near, its mirror image; 0 otherwise. The height change and the distances are
/// measured from the input as given either way. Written only on success. For an analysis
/// result: `VSR_STATUS_NOT_AVAILABLE`.
///
/// # Safety
/// `result`: a valid handle; `mirrored` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_mirrored(
    result: *const VsrResult,
    mirrored: *mut i32,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            scalars("result", result, [("mirrored", mirrored)], |r| {
                Ok([i32::from(
                    r.form("whether the input was mirrored")?.mirrored,
                )])
            })
        }
    })
}

/// Distances between the form-found and the input surfaces, over the plan bounding-box
/// diagonal (dimensionless), sampled at vertices: `hausdorff` = the symmetric Hausdorff
/// distance (the largest distance from a vertex of either surface to the other surface),
/// `l2` = the RMS distance from the form-found vertices to the input surface, weighted by
/// vertex area (for the height change itself see `vsr_result_height_change`). Both pointers required; written only
/// on success. For an analysis result: `VSR_STATUS_NOT_AVAILABLE`.
///
/// # Safety
/// `result`: a valid handle; the out-pointers writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_distances(
    result: *const VsrResult,
    hausdorff: *mut f64,
    l2: *mut f64,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            scalars(
                "result",
                result,
                [("hausdorff", hausdorff), ("l2", l2)],
                |r| {
                    let f = r.form("the distances")?;
                    Ok([f.hausdorff, f.l2])
                },
            )
        }
    })
}

/// Wall-clock seconds spent in stress steps, in height steps, and in total. For an analysis
/// result the shape time is 0 and the total is the stress time. All three pointers required;
/// written only on success.
///
/// # Safety
/// `result`: a valid handle; the out-pointers writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_timings(
    result: *const VsrResult,
    stress_seconds: *mut f64,
    shape_seconds: *mut f64,
    total_seconds: *mut f64,
) -> VsrStatus {
    boundary!({
        let outs = [
            ("stress_seconds", stress_seconds),
            ("shape_seconds", shape_seconds),
            ("total_seconds", total_seconds),
        ];
        // SAFETY: forwarded caller's contract.
        unsafe {
            scalars("result", result, outs, |r| {
                Ok(match &r.outcome {
                    Outcome::Analysis { stress, .. } => [stress.seconds, 0.0, stress.seconds],
                    Outcome::FormFinding(f) => [f.stress_seconds, f.shape_seconds, f.total_seconds],
                })
            })
        }
    })
}
