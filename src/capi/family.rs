//! The least thickness over a family of envelopes through the C ABI: the caller's function
//! gives the bounds at each thickness (docs/method.md §16.5).

use super::assess::VsrAssessSettings;
use super::assessment::VsrAssessment;
use super::boundary::{boundary, from_error, handle, out_ptr, CResult, Failure};
use super::mesh::VsrMesh;
use super::status::VsrStatus;
use crate::assess::{min_thickness_of_family, Envelope};
use crate::solid::Thickness;
use crate::Error;
use std::ffi::{c_int, c_void};

/// The envelope of thickness `thickness`: the function writes `n_vertices` intrados heights
/// to `lower` and as many extrados heights to `upper` (one per mesh vertex, in the mesh's
/// order) and returns 0; any other value stops the search. It runs on the calling thread and
/// must not unwind (throw a C++ exception or longjmp) out of the call.
pub type VsrEnvelopeAtFn = Option<
    unsafe extern "C" fn(
        user: *mut c_void,
        thickness: f64,
        lower: *mut f64,
        upper: *mut f64,
        n_vertices: usize,
    ) -> c_int,
>;

/// The least thickness t of a family of envelopes whose bounds are functions of t (Heyman's
/// dome between the spheres R ± t/2 read vertically, compas_tno's `zlb`/`zub`): `envelope_at`
/// gives the bounds at t; the self-weight is the middle surface's area × t × the settings'
/// unit weight. Rounds of the least-thickness analysis move t towards the thickness whose
/// least scale is 1, starting at `thickness` (docs/method.md §16.5); the settings' objective
/// is ignored.
///
/// `out` receives the least-thickness analysis at the least certified thickness (its surface
/// lies inside that envelope; free with `vsr_assessment_destroy`), `thickness_out` that
/// thickness and `converged_out` 1 when the last round's scale lay in
/// [1 − `scale_tolerance`, 1] (a local least thickness of a nested family), else 0. All three
/// are untouched on failure.
///
/// Errors: NULL arguments or function (`VSR_STATUS_NULL_POINTER`); `thickness` or
/// `scale_tolerance` not a finite number > 0, bounds that are not finite or with lower above
/// upper (naming the vertex), `envelope_at` returning non-zero, no round with a certified
/// surface (`VSR_STATUS_INVALID_ARGUMENT`); `VSR_STATUS_NUMERICAL` when a QP fails.
///
/// # Safety
/// `mesh`, `settings`: valid handles; `out`, `thickness_out`, `converged_out` writable;
/// `envelope_at` and `user` valid for the duration of the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_min_thickness_of_family(
    mesh: *const VsrMesh,
    envelope_at: VsrEnvelopeAtFn,
    user: *mut c_void,
    thickness: f64,
    scale_tolerance: f64,
    settings: *const VsrAssessSettings,
    out: *mut *mut VsrAssessment,
    thickness_out: *mut f64,
    converged_out: *mut c_int,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let (mesh, settings) = unsafe { (handle("mesh", mesh)?, handle("settings", settings)?) };
        let envelope_at = envelope_at.ok_or_else(|| Failure::null("envelope_at"))?;
        let out = out_ptr("out", out)?;
        let thickness_out = out_ptr("thickness_out", thickness_out)?;
        let converged_out = out_ptr("converged_out", converged_out)?;
        let problem = &mesh.problem;
        let n = problem.mesh.positions.len();
        let member = |t: f64| -> crate::Result<Envelope> {
            let (mut lower, mut upper) = (vec![0.0; n], vec![0.0; n]);
            // SAFETY: the function and `user` are valid for this call (caller's contract);
            // both buffers hold n values.
            let answer = unsafe { envelope_at(user, t, lower.as_mut_ptr(), upper.as_mut_ptr(), n) };
            if answer != 0 {
                return Err(Error::InvalidArgument {
                    name: "envelope_at",
                    reason: format!("returned {answer} at thickness {t}"),
                });
            }
            Envelope::from_bounds(&problem.mesh, lower, upper, &Thickness::Uniform(t))
        };
        let found = min_thickness_of_family(
            problem,
            member,
            thickness,
            scale_tolerance,
            &settings.settings,
        );
        let found = found.map_err(|e| from_error("envelope_at", e))?;
        write_family(&problem.mesh, found, out, thickness_out, converged_out)
    })
}

fn write_family(
    mesh: &crate::Mesh,
    found: crate::FamilyThickness,
    out: *mut *mut VsrAssessment,
    thickness_out: *mut f64,
    converged_out: *mut c_int,
) -> CResult {
    let handle = Box::new(VsrAssessment::new(mesh, found.result));
    // SAFETY: non-NULL and writable by the caller's contract.
    unsafe {
        out.write(Box::into_raw(handle));
        thickness_out.write(found.thickness);
        converged_out.write(c_int::from(found.converged));
    }
    Ok(())
}
