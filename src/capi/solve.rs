//! The entry points: stress analysis of a fixed shape, form finding, and a warm re-solve of
//! form finding after an edit.

use super::boundary::{boundary, from_error, handle, out_ptr};
use super::mesh::VsrMesh;
use super::result::{Outcome, VsrResult};
use super::settings::VsrSettings;
use super::status::VsrStatus;
use crate::{analyse, form_find, form_find_from};

/// Stress analysis of the mesh as given: the best compressive force densities for its fixed
/// shape, with the formulation, bounds, τ mode, hole mode and load rule of `settings` (the
/// form-finding options are ignored). The outcome of the QP is read with
/// `vsr_result_stress_status`; an infeasible or failed QP is still `VSR_STATUS_OK`.
///
/// `out` receives a new result owned by the caller (free with `vsr_result_destroy`); it
/// copies everything it reports and does not refer to `mesh` or `settings`. Untouched on
/// failure. `mesh` and `settings` are only read: they may be shared with other threads that
/// also only read them.
///
/// # Safety
/// `mesh`, `settings`: valid handles; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_analyse(
    mesh: *const VsrMesh,
    settings: *const VsrSettings,
    out: *mut *mut VsrResult,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let (mesh, settings) = unsafe { (handle("mesh", mesh)?, handle("settings", settings)?) };
        let out = out_ptr("out", out)?;
        let problem = &mesh.problem;
        let stress = analyse(problem, &settings.form.stress).map_err(|e| from_error("mesh", e))?;
        let result = VsrResult::new(
            &problem.mesh,
            Outcome::Analysis {
                positions: problem.mesh.positions.clone(),
                stress,
            },
        );
        // SAFETY: non-NULL, writable by the caller's contract.
        unsafe { out.write(Box::into_raw(Box::new(result))) };
        Ok(())
    })
}

/// Form finding: moves the heights (supports fixed; the plan fixed unless ODT sweeps are
/// set) until the shape stands
/// (ε∞ < tolerance) or the loop stops; each iteration is a stress step (as `vsr_analyse`)
/// followed by a height step. Calls the progress callback of `settings`, if any, once per
/// iteration on this thread.
///
/// A loop that does not converge is still `VSR_STATUS_OK`: read why it stopped with
/// `vsr_result_termination`; the result always holds the best final state and its stress.
/// `out` receives a new result owned by the caller (free with `vsr_result_destroy`);
/// untouched on failure. `mesh` and `settings` are only read (the mesh keeps its input
/// heights; read the new ones with `vsr_result_positions`).
///
/// # Safety
/// `mesh`, `settings`: valid handles; `out` writable; the callback and its `user` pointer
/// valid for the duration of the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_form_find(
    mesh: *const VsrMesh,
    settings: *const VsrSettings,
    out: *mut *mut VsrResult,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let (mesh, settings) = unsafe { (handle("mesh", mesh)?, handle("settings", settings)?) };
        let out = out_ptr("out", out)?;
        let problem = &mesh.problem;
        let found = (settings.progress)
            .run(|progress| form_find(problem, &settings.form, progress))
            .map_err(|e| from_error("mesh", e))?;
        let result = VsrResult::new(&problem.mesh, Outcome::FormFinding(found));
        // SAFETY: non-NULL, writable by the caller's contract.
        unsafe { out.write(Box::into_raw(Box::new(result))) };
        Ok(())
    })
}

/// Form finding after a small edit, started from `previous`, a result of `vsr_form_find` or
/// `vsr_form_find_from` on a mesh with the same vertices and triangles: the same answer as
/// `vsr_form_find` on `mesh` (the nearest self-supporting shape to its heights as they are
/// now, with the same tolerance, terminations and best state), in fewer stress steps where
/// the edit is small. Between the calls the heights of any vertices, the anchored vertices,
/// the loads and every setting but the method may change (build the edited mesh with
/// `vsr_mesh_create`). Reused: `previous`'s heights as the start (anchored vertices at their
/// heights in `mesh`), its force densities, and its nearest method's penalty state and stress
/// solver cache (taken by the first re-solve from `previous`; later ones build their own).
/// See docs/method.md §13.4.
///
/// Errors: `VSR_STATUS_INVALID_ARGUMENT` naming `previous` when it comes from `vsr_analyse`,
/// when its vertex or edge count or its triangles differ from `mesh`'s, or when a height of
/// it is not finite; naming `method` when `settings` ask for the paper's loop. Otherwise as
/// `vsr_form_find`: `out` receives a new result owned by the caller, untouched on failure;
/// `mesh`, `settings` and `previous` are only read (`previous` stays valid and unchanged
/// but for the cache it lends).
///
/// # Safety
/// `mesh`, `settings`, `previous`: valid handles; `out` writable; the callback and its `user`
/// pointer valid for the duration of the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_form_find_from(
    mesh: *const VsrMesh,
    settings: *const VsrSettings,
    previous: *const VsrResult,
    out: *mut *mut VsrResult,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let (mesh, settings, previous) = unsafe {
            (
                handle("mesh", mesh)?,
                handle("settings", settings)?,
                handle("previous", previous)?,
            )
        };
        let out = out_ptr("out", out)?;
        let previous = previous.form_found("previous")?;
        let problem = &mesh.problem;
        let found = (settings.progress)
            .run(|progress| form_find_from(problem, &settings.form, previous, progress))
            .map_err(|e| from_error("mesh", e))?;
        let result = VsrResult::new(&problem.mesh, Outcome::FormFinding(found));
        // SAFETY: non-NULL, writable by the caller's contract.
        unsafe { out.write(Box::into_raw(Box::new(result))) };
        Ok(())
    })
}
