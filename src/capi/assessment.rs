//! `VsrAssessment` (the outcome of `vsr_assess`) and its getters. Array getters copy out as
//! `VsrResult`'s do: `(assessment, out, len, needed)`.

use super::boundary::{boundary, c_string, copy, free, handle, out_ptr, scalars};
use super::status::{VsrObjective, VsrStatus, VsrTermination};
use crate::assess::AssessResult;
use crate::mesh::Mesh;
use std::ffi::c_char;

/// The vertex id that stands for "no vertex" in `vsr_assessment_certificate`.
pub const VSR_NO_VERTEX: u32 = u32::MAX;

/// Opaque handle: the outcome of `vsr_assess`. It owns copies of everything it reports; free
/// with `vsr_assessment_destroy`. Immutable: a `const VsrAssessment*` may be read from several
/// threads at once.
pub struct VsrAssessment {
    result: AssessResult,
    /// Edge vertex pairs, flattened (#E by 2).
    edges: Vec<u32>,
}

impl VsrAssessment {
    pub(crate) fn new(mesh: &Mesh, result: AssessResult) -> VsrAssessment {
        VsrAssessment {
            result,
            edges: mesh.edges.iter().flat_map(|e| e.v).collect(),
        }
    }
}

/// Frees an assessment. NULL is a no-op.
///
/// # Safety
/// `assessment` must be NULL or a handle from `vsr_assess` not yet destroyed, used by no other
/// thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_destroy(assessment: *mut VsrAssessment) {
    // SAFETY: forwarded caller's contract.
    boundary!(keep_error, (), { unsafe { free(assessment) } })
}

/// The analysis that was run (a `VsrObjective`). Written only on success.
///
/// # Safety
/// `assessment`: a valid handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_objective(
    assessment: *const VsrAssessment,
    out: *mut VsrObjective,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            scalars("assessment", assessment, [("out", out)], |a| {
                Ok([VsrObjective::of(a.result.objective)])
            })
        }
    })
}

/// How the search ended: `feasible` 1 when the positions with the force densities are a
/// certified thrust surface (ε∞ and the horizontal imbalance below the tolerance, every force
/// density within its bounds,
/// every height within `[lower − 1e-9 d, upper + 1e-9 d]`, d the plan diagonal), else 0 (the
/// least infeasible state reached is reported); `termination` `VSR_TERMINATION_CONVERGED`
/// when the objective's optimum was reached (else why the search stopped: max iterations,
/// stalled, cancelled, ...; `VSR_TERMINATION_INFEASIBLE`, without a search, where a loaded
/// part of the plan has no compressive path to a support, cut off by free corners or
/// straight free edges, so that no thrust surface exists in any envelope: the termination
/// message names them); the
/// steps taken; the wall-clock seconds. Every pointer required; written only on success.
///
/// # Safety
/// `assessment`: a valid handle; the out-pointers writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_outcome(
    assessment: *const VsrAssessment,
    feasible: *mut u32,
    termination: *mut VsrTermination,
    iterations: *mut usize,
    seconds: *mut f64,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let a = unsafe { handle("assessment", assessment)? };
        let r = &a.result;
        let (f, t, i, s) = (
            out_ptr("feasible", feasible)?,
            out_ptr("termination", termination)?,
            out_ptr("iterations", iterations)?,
            out_ptr("seconds", seconds)?,
        );
        // SAFETY: non-NULL and writable (caller's contract).
        unsafe {
            f.write(u32::from(r.feasible));
            t.write(VsrTermination::of(&r.termination));
            i.write(r.iterations);
            s.write(r.seconds);
        }
        Ok(())
    })
}

/// The analysis' figures: `thickness_scale` s, the scale of the envelope's half extents
/// (the least one for min-thickness, else 1); `safety_factor` 1 / s; `thrust_horizontal`,
/// Σ over supports of the horizontal reaction's magnitude (force); `load_factor` λ of
/// max-load (else 0). Every pointer required; written only on success.
///
/// # Safety
/// `assessment`: a valid handle; the out-pointers writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_figures(
    assessment: *const VsrAssessment,
    thickness_scale: *mut f64,
    safety_factor: *mut f64,
    thrust_horizontal: *mut f64,
    load_factor: *mut f64,
) -> VsrStatus {
    boundary!({
        let outs = [
            ("thickness_scale", thickness_scale),
            ("safety_factor", safety_factor),
            ("thrust_horizontal", thrust_horizontal),
            ("load_factor", load_factor),
        ];
        // SAFETY: forwarded caller's contract.
        unsafe {
            scalars("assessment", assessment, outs, |a| {
                let r = &a.result;
                Ok([
                    r.thickness_scale,
                    r.safety_factor,
                    r.thrust_horizontal,
                    r.load_factor,
                ])
            })
        }
    })
}

/// The certificate's figures: `eps_inf`, max |vertical residual| / mean load over the
/// non-anchored vertices; `horizontal_imbalance`, the largest horizontal imbalance at a
/// non-anchored vertex over the mean load; `worst_bound`, the largest excess of a height over
/// its bounds (0 when all are inside) and `worst_bound_vertex` its vertex; and
/// `worst_residual_vertex`, the vertex of the largest residual (`VSR_NO_VERTEX` where there
/// is none). Every pointer required; written only on success.
///
/// # Safety
/// `assessment`: a valid handle; the out-pointers writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_certificate(
    assessment: *const VsrAssessment,
    eps_inf: *mut f64,
    horizontal_imbalance: *mut f64,
    worst_bound: *mut f64,
    worst_bound_vertex: *mut u32,
    worst_residual_vertex: *mut u32,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let a = unsafe { handle("assessment", assessment)? };
        let r = &a.result;
        let (e, h, w) = (
            out_ptr("eps_inf", eps_inf)?,
            out_ptr("horizontal_imbalance", horizontal_imbalance)?,
            out_ptr("worst_bound", worst_bound)?,
        );
        let (wb, wr) = (
            out_ptr("worst_bound_vertex", worst_bound_vertex)?,
            out_ptr("worst_residual_vertex", worst_residual_vertex)?,
        );
        // SAFETY: non-NULL and writable (caller's contract).
        unsafe {
            e.write(r.eps_inf);
            h.write(r.horizontal_imbalance);
            w.write(r.worst_bound.0);
            wb.write(r.worst_bound.1.unwrap_or(VSR_NO_VERTEX));
            wr.write(r.worst_residual_vertex.unwrap_or(VSR_NO_VERTEX));
        }
        Ok(())
    })
}

/// A one-line description of the termination, as a NUL-terminated UTF-8 string copied into
/// `out` (`len` bytes; `needed` counts the terminating NUL); for `VSR_TERMINATION_STALLED` it
/// lists the vertices with the largest residuals, for `VSR_TERMINATION_INFEASIBLE` the free
/// corners and the stranded vertices.
///
/// # Safety
/// `assessment`: a valid handle; `out`: NULL or `len` writable bytes; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_termination_message(
    assessment: *const VsrAssessment,
    out: *mut c_char,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("assessment", assessment, out, len, needed, |a| {
                Ok(c_string(&a.result.termination_message()))
            })
        }
    })
}

/// The thrust surface, #V by 3 doubles: the mesh's plan with the heights found.
///
/// # Safety
/// `assessment`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_positions(
    assessment: *const VsrAssessment,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            copy("assessment", assessment, out, len, needed, |a| {
                Ok(a.result.positions.iter().flatten().copied().collect())
            })
        }
    })
}

/// Force density per edge (rows of `vsr_assessment_edges`), #E doubles (force per length,
/// compression positive).
///
/// # Safety
/// `assessment`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_force_densities(
    assessment: *const VsrAssessment,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            copy("assessment", assessment, out, len, needed, |a| {
                Ok(a.result.force_densities.clone())
            })
        }
    })
}

/// Vertical load per vertex, #V doubles (downward positive): the self-weight, the mesh's
/// extra loads and λ × the load pattern.
///
/// # Safety
/// `assessment`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_loads(
    assessment: *const VsrAssessment,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            copy("assessment", assessment, out, len, needed, |a| {
                Ok(a.result.loads.clone())
            })
        }
    })
}

/// Vertical residual per vertex, #V doubles (0 at supports).
///
/// # Safety
/// `assessment`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_residuals(
    assessment: *const VsrAssessment,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            copy("assessment", assessment, out, len, needed, |a| {
                Ok(a.result.residuals.clone())
            })
        }
    })
}

/// Lower bound per vertex at the reported thickness (the envelope's intrados, scaled by the
/// thickness scale about the middle surface), #V doubles.
///
/// # Safety
/// `assessment`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_lower(
    assessment: *const VsrAssessment,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            copy("assessment", assessment, out, len, needed, |a| {
                Ok(a.result.lower.clone())
            })
        }
    })
}

/// Upper bound per vertex at the reported thickness, #V doubles.
///
/// # Safety
/// `assessment`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_upper(
    assessment: *const VsrAssessment,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            copy("assessment", assessment, out, len, needed, |a| {
                Ok(a.result.upper.clone())
            })
        }
    })
}

/// Horizontal reaction per vertex, #V by 2 doubles (non-zero at supports): the force the
/// vault pushes the support with.
///
/// # Safety
/// `assessment`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_reactions(
    assessment: *const VsrAssessment,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            copy("assessment", assessment, out, len, needed, |a| {
                Ok(a.result.reactions.iter().flatten().copied().collect())
            })
        }
    })
}

/// Edges, #E by 2 `uint32_t` vertex ids (smaller first), row-major, sorted: the rows of
/// `vsr_assessment_force_densities` (the mesh's edges, as `vsr_mesh_edges`).
///
/// # Safety
/// `assessment`: a valid handle; `out`: NULL or `len` writable elements; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_edges(
    assessment: *const VsrAssessment,
    out: *mut u32,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            copy("assessment", assessment, out, len, needed, |a| {
                Ok(a.edges.clone())
            })
        }
    })
}

/// The support vertex of each springing joint, #J `uint32_t`: the free supports with a finite
/// reach (none with fixed supports), in the rows of `vsr_assessment_joints`.
///
/// # Safety
/// `assessment`: a valid handle; `out`: NULL or `len` writable elements; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_joint_vertices(
    assessment: *const VsrAssessment,
    out: *mut u32,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            copy("assessment", assessment, out, len, needed, |a| {
                Ok(a.result.joints.iter().map(|j| j.vertex).collect())
            })
        }
    })
}

/// The vertices of the loaded parts that no compressive state joins to a support (cut off
/// by free corners or straight free edges, docs/method.md §16.3; a part a `max-load` live
/// load reaches is left to the search), `uint32_t` in increasing order: where there are
/// any, no thrust surface exists in any envelope and the analysis answered
/// `VSR_TERMINATION_INFEASIBLE` without a search; none otherwise.
///
/// # Safety
/// `assessment`: a valid handle; `out`: NULL or `len` writable elements; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_stranded(
    assessment: *const VsrAssessment,
    out: *mut u32,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            copy("assessment", assessment, out, len, needed, |a| {
                Ok(a.result.stranded.clone())
            })
        }
    })
}

/// The springing joints recomputed from the returned surface, #J by 9 doubles, row-major
/// (docs/method.md §16.1): the springing plane's height and the joint's reach at the
/// reported thickness scale; the horizontal reaction H (x, y) and the vertical reaction V
/// (the vault pushes the support with (H, −V)); the point (x, y, z) where the reaction's line
/// meets the springing plane; and that point's plan distance from the support, at most the
/// reach on a certified surface.
///
/// # Safety
/// `assessment`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_joints(
    assessment: *const VsrAssessment,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            copy("assessment", assessment, out, len, needed, |a| {
                Ok(a.result.joints.iter().flat_map(|j| j.row()).collect())
            })
        }
    })
}

/// The largest joint excess max(0, (z − s) |H| − b V) over b × the mean load, below the
/// tolerance on a certified surface, and its support (`VSR_NO_VERTEX` where there is none).
/// Both pointers required; written only on success.
///
/// # Safety
/// `assessment`: a valid handle; the out-pointers writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_worst_joint(
    assessment: *const VsrAssessment,
    excess: *mut f64,
    vertex: *mut u32,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let a = unsafe { handle("assessment", assessment)? };
        let (e, v) = (out_ptr("excess", excess)?, out_ptr("vertex", vertex)?);
        let (worst, at) = a.result.worst_joint;
        // SAFETY: non-NULL and writable (caller's contract).
        unsafe {
            e.write(worst);
            v.write(at.unwrap_or(VSR_NO_VERTEX));
        }
        Ok(())
    })
}

/// `unbounded` 1 when the analysis is max-thrust or max-load and its objective has no
/// bound: the returned surface is certified, and its force densities (and load factor)
/// scaled by every s from some s₀ ≥ 1 on, with heights approaching a limit surface over the
/// same supports, give certified surfaces too (docs/method.md §16.4), so
/// `thrust_horizontal` or `load_factor` is a value reached, not the greatest; else 0. The
/// pointer required; written only on success.
///
/// # Safety
/// `assessment`: a valid handle; the out-pointer writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assessment_unbounded(
    assessment: *const VsrAssessment,
    unbounded: *mut u32,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let a = unsafe { handle("assessment", assessment)? };
        let out = out_ptr("unbounded", unbounded)?;
        // SAFETY: non-NULL and writable (caller's contract).
        unsafe { out.write(u32::from(a.result.unbounded)) };
        Ok(())
    })
}
