//! Masonry assessment through the C ABI: `VsrEnvelope` (the masonry between intrados and
//! extrados), `VsrAssessSettings` and `vsr_assess`, whose `VsrAssessment` is read in
//! `assessment.rs`.

use super::assessment::VsrAssessment;
use super::boundary::{
    boundary, checked_len, copy_out, free, from_error, give, handle, handle_mut, input, out_ptr,
    CResult, Failure,
};
use super::enum_args;
use super::mesh::VsrMesh;
use super::settings::{validated, Progress, VsrProgressFn};
use super::status::VsrStatus;
use crate::assess::{assess, AssessSettings, Envelope};
use crate::solid::Thickness;
use crate::stress::QBound;
use std::ffi::c_void;

/// Opaque handle: the masonry's envelope over a mesh's plan, per vertex an intrados (lower)
/// and an extrados (upper) height and per face the thickness whose weight loads the vault.
/// Create with `vsr_envelope_from_thickness` or `vsr_envelope_from_surfaces`, free with
/// `vsr_envelope_destroy`. `vsr_envelope_set_springing` changes its springing joints;
/// nothing else changes it, and a `const VsrEnvelope*` may be read from several threads at
/// once. It belongs to the mesh it was made for (`vsr_assess` checks the sizes).
pub struct VsrEnvelope {
    pub(crate) envelope: Envelope,
}

/// The core's error about an envelope's input, with `VSR_STATUS_NON_FINITE` where a value
/// is NaN or infinite (as the envelope functions document).
fn envelope_error(arg: &str, e: crate::Error) -> Failure {
    let non_finite = crate::validate::is_not_finite(&e);
    let mut failure = from_error(arg, e);
    if non_finite {
        failure.status = VsrStatus::NonFinite;
    }
    failure
}

/// The envelope of a masonry of thickness `thickness` about the mesh as middle surface:
/// `n_thickness` is 1 (a uniform thickness) or the mesh's face count (one per face, in the
/// order of its triangles). The masonry extends t/2 to either side along the unit vertex
/// normal n (area-weighted mean of the faces' normals), read vertically as t / (2 n_z) above
/// and below each vertex; a vertex takes the area-weighted mean of its faces' thicknesses.
/// Lengths in the units of the positions.
///
/// `out` receives a new envelope owned by the caller (free with `vsr_envelope_destroy`);
/// untouched on failure.
///
/// Errors: NULL arguments (`VSR_STATUS_NULL_POINTER`); a thickness that is NaN or infinite
/// (`VSR_STATUS_NON_FINITE`, naming the face); `n_thickness` neither 1 nor the face count,
/// a thickness <= 0 (naming the face), or a vertex where the mesh is vertical or overhangs
/// (normal z-component <= 1e-6: give intrados and extrados there instead)
/// (`VSR_STATUS_INVALID_ARGUMENT`).
///
/// # Safety
/// `mesh`: a valid handle; `thickness`: `n_thickness` readable doubles; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_envelope_from_thickness(
    mesh: *const VsrMesh,
    thickness: *const f64,
    n_thickness: usize,
    out: *mut *mut VsrEnvelope,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let mesh = unsafe { handle("mesh", mesh)? };
        let out = out_ptr("out", out)?;
        // SAFETY: caller's contract.
        let values = unsafe { input("thickness", thickness, n_thickness)? };
        let m = &mesh.problem.mesh;
        let t = match values.len() {
            1 => Thickness::Uniform(values[0]),
            n if n == m.n_faces() => Thickness::PerFace(values.to_vec()),
            n => {
                return Err(Failure::invalid(
                    "n_thickness",
                    format!("is {n}: give 1 (uniform) or one per face ({})", m.n_faces()),
                ))
            }
        };
        let envelope =
            Envelope::from_thickness(m, &t).map_err(|e| envelope_error("thickness", e))?;
        // SAFETY: `out` checked above, writable by the caller's contract.
        unsafe { give(out, VsrEnvelope { envelope }) }
    })
}

/// Positions and triangles of an intrados or extrados.
type Surface = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// A triangle surface from caller memory: positions #n by 3, triangles #nt by 3.
///
/// # Safety
/// As `vsr_envelope_from_surfaces` for the arrays named `name`.
unsafe fn surface(
    name: &str,
    positions: *const f64,
    n_vertices: usize,
    triangles: *const u32,
    n_triangles: usize,
) -> CResult<Surface> {
    let (p_name, t_name) = (format!("{name}_positions"), format!("{name}_triangles"));
    let np = checked_len::<f64>(&p_name, "n_vertices", n_vertices, 3)?;
    let nt = checked_len::<u32>(&t_name, "n_triangles", n_triangles, 3)?;
    // SAFETY: caller's contract; lengths checked above.
    let (p, t) = unsafe {
        (
            input(&p_name, positions, np)?,
            input(&t_name, triangles, nt)?,
        )
    };
    if let Some(k) = t.iter().position(|&v| v as usize >= n_vertices) {
        return Err(Failure::new(
            VsrStatus::IndexOutOfRange,
            format!(
                "argument `{t_name}`: triangle {} refers to vertex {}, beyond its {n_vertices} \
                 vertices",
                k / 3,
                t[k]
            ),
        ));
    }
    let rows = p.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let tris = t.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    Ok((rows, tris))
}

/// The envelope between an intrados and an extrados given as triangle surfaces (any
/// triangulation; positions #V by 3 doubles, triangles #F by 3 `uint32_t` ids, row-major),
/// sampled on the vertical through each vertex of the mesh by linear interpolation on the
/// triangle whose plan contains it (where several do, the highest intrados and the lowest
/// extrados count). The middle surface is halfway between; the load's thickness is the
/// vertical extent times the middle surface's normal z-component there.
///
/// `out` receives a new envelope owned by the caller (free with `vsr_envelope_destroy`);
/// untouched on failure.
///
/// Errors: NULL arguments (`VSR_STATUS_NULL_POINTER`); a count times 3 that overflows
/// (`VSR_STATUS_LENGTH_OVERFLOW`); a triangle id beyond its surface's vertices
/// (`VSR_STATUS_INDEX_OUT_OF_RANGE`); a coordinate that is NaN or infinite
/// (`VSR_STATUS_NON_FINITE`); a mesh vertex a surface does not cover, or where the intrados
/// lies above the extrados (`VSR_STATUS_INVALID_ARGUMENT`, naming the vertex).
///
/// # Safety
/// `mesh`: a valid handle; each array readable for its count of rows; `out` writable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn vsr_envelope_from_surfaces(
    mesh: *const VsrMesh,
    intrados_positions: *const f64,
    n_intrados_vertices: usize,
    intrados_triangles: *const u32,
    n_intrados_triangles: usize,
    extrados_positions: *const f64,
    n_extrados_vertices: usize,
    extrados_triangles: *const u32,
    n_extrados_triangles: usize,
    out: *mut *mut VsrEnvelope,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let mesh = unsafe { handle("mesh", mesh)? };
        let out = out_ptr("out", out)?;
        // SAFETY: caller's contract.
        let (lower, upper) = unsafe {
            (
                surface(
                    "intrados",
                    intrados_positions,
                    n_intrados_vertices,
                    intrados_triangles,
                    n_intrados_triangles,
                )?,
                surface(
                    "extrados",
                    extrados_positions,
                    n_extrados_vertices,
                    extrados_triangles,
                    n_extrados_triangles,
                )?,
            )
        };
        let envelope = Envelope::from_surfaces(
            &mesh.problem.mesh,
            (&lower.0, &lower.1),
            (&upper.0, &upper.1),
        )
        .map_err(|e| envelope_error("intrados", e))?;
        // SAFETY: `out` checked above, writable by the caller's contract.
        unsafe { give(out, VsrEnvelope { envelope }) }
    })
}

/// Frees an envelope. NULL is a no-op.
///
/// # Safety
/// `envelope` must be NULL or a handle from a `vsr_envelope_from_*` function not yet
/// destroyed, used by no other thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_envelope_destroy(envelope: *mut VsrEnvelope) {
    // SAFETY: forwarded caller's contract.
    boundary!(keep_error, (), { unsafe { free(envelope) } })
}

/// Borrows the envelope and copies `pick(envelope)` out.
unsafe fn copy_envelope(
    envelope: *const VsrEnvelope,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
    pick: impl FnOnce(&Envelope) -> &[f64],
) -> CResult {
    // SAFETY: caller's contract.
    let e = unsafe { handle("envelope", envelope)? };
    // SAFETY: caller's contract.
    unsafe { copy_out(pick(&e.envelope), out, len, needed) }
}

/// Intrados height per vertex, #V doubles (0 at vertices used by no triangle). Copy-out as
/// described in the header's introduction.
///
/// # Safety
/// `envelope`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_envelope_lower(
    envelope: *const VsrEnvelope,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({ unsafe { copy_envelope(envelope, out, len, needed, |e| &e.lower) } })
}

/// Extrados height per vertex, #V doubles (0 at vertices used by no triangle).
///
/// # Safety
/// `envelope`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_envelope_upper(
    envelope: *const VsrEnvelope,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({ unsafe { copy_envelope(envelope, out, len, needed, |e| &e.upper) } })
}

/// Thickness per face measured along the middle surface's normal, #F doubles: area ×
/// thickness × unit weight is the face's weight.
///
/// # Safety
/// `envelope`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_envelope_face_thickness(
    envelope: *const VsrEnvelope,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({ unsafe { copy_envelope(envelope, out, len, needed, |e| &e.face_thickness) } })
}

/// Height of the springing plane per vertex, #V doubles, read at free supports (see
/// `vsr_envelope_set_springing` for its meaning and defaults).
///
/// # Safety
/// `envelope`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_envelope_springing(
    envelope: *const VsrEnvelope,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({ unsafe { copy_envelope(envelope, out, len, needed, |e| &e.springing) } })
}

/// Reach of the springing joint per vertex, #V doubles (`INFINITY` where there is no joint),
/// read at free supports (see `vsr_envelope_set_springing`).
///
/// # Safety
/// `envelope`: a valid handle; `out`: NULL or `len` writable doubles; `needed`: NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_envelope_reach(
    envelope: *const VsrEnvelope,
    out: *mut f64,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({ unsafe { copy_envelope(envelope, out, len, needed, |e| &e.reach) } })
}

/// Sets the springing joints (docs/method.md §16.1), read at the free supports (those whose
/// height the assessment chooses; not with fixed supports): per vertex the height of the
/// springing plane and the joint's reach, #V doubles each (copied; entries at other vertices
/// are checked but not read). A free support lies on or above its plane, and its reaction's
/// line of action, followed down to the plane, meets it within `reach` (in plan) of the
/// support's plan point. A reach of `INFINITY` drops the joint: the support's height is then
/// bounded by the envelope alone (the vertical reading). Defaults: from a thickness, the
/// plane through the middle surface's vertex and reach t / (2 |n_h|) (the slab's horizontal
/// section, n_h the normal's plan part); from surfaces, the plane at the intrados and half
/// the vertex's thickness.
///
/// Errors: NULL arguments (`VSR_STATUS_NULL_POINTER`); a length other than the mesh's vertex
/// count, a springing height that is not finite or lies above the extrados, a reach that is
/// NaN or < 0 (`VSR_STATUS_INVALID_ARGUMENT`, naming the argument and the vertex). The
/// envelope is unchanged on failure.
///
/// # Safety
/// `envelope`: a valid handle with exclusive access; `springing`: `n_springing` readable
/// doubles; `reach`: `n_reach` readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_envelope_set_springing(
    envelope: *mut VsrEnvelope,
    springing: *const f64,
    n_springing: usize,
    reach: *const f64,
    n_reach: usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let e = unsafe { handle_mut("envelope", envelope)? };
        // SAFETY: caller's contract.
        let (springing, reach) = unsafe {
            (
                input("springing", springing, n_springing)?,
                input("reach", reach, n_reach)?,
            )
        };
        let changed = (e.envelope.clone())
            .with_springing(springing.to_vec(), reach.to_vec())
            .map_err(|err| from_error("springing", err))?;
        e.envelope = changed;
        Ok(())
    })
}

/// Opaque handle: the options of `vsr_assess`. Create with `vsr_assess_settings_create`
/// (defaults documented there), change with the `vsr_assess_settings_set_*` functions, free
/// with `vsr_assess_settings_destroy`.
pub struct VsrAssessSettings {
    pub(crate) settings: AssessSettings,
    pub(crate) progress: Progress,
}

/// Creates assessment settings with the documented defaults (those of the Rust
/// `AssessSettings`):
///
/// | option | default |
/// |---|---|
/// | objective | `VSR_OBJECTIVE_FIT` |
/// | fixed supports | 0 (the thrust meets each support anywhere within the envelope) |
/// | unit weight (weight per volume) | 1 |
/// | load rule | `VSR_LOAD_RULE_BARYCENTRIC` |
/// | load pattern (max-load) | none |
/// | q_min | 0, `VSR_BOUND_KIND_ABSOLUTE` (compression only) |
/// | tolerance (on ε∞ of a certified surface) | 1e-6 |
/// | max iterations (sequential QP steps) | 200 |
/// | progress callback | none |
///
/// `out` receives a handle owned by the caller (free with `vsr_assess_settings_destroy`);
/// untouched on failure.
///
/// # Safety
/// `out` must be writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assess_settings_create(out: *mut *mut VsrAssessSettings) -> VsrStatus {
    boundary!({
        let handle = VsrAssessSettings {
            settings: AssessSettings::default(),
            progress: Progress::default(),
        };
        // SAFETY: forwarded caller's contract.
        unsafe { give(out, handle) }
    })
}

/// Frees assessment settings. NULL is a no-op.
///
/// # Safety
/// `settings` must be NULL or a handle from `vsr_assess_settings_create` not yet destroyed,
/// used by no other thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assess_settings_destroy(settings: *mut VsrAssessSettings) {
    // SAFETY: forwarded caller's contract.
    boundary!(keep_error, (), { unsafe { free(settings) } })
}

/// Applies `f` to a copy of the settings, validates the copy with the library's
/// [`AssessSettings::validate`] (the one set of range checks), and stores it on success.
/// `args` maps the settings' field names to the setter's argument names, which a failure
/// names.
unsafe fn update(
    settings: *mut VsrAssessSettings,
    args: &[(&str, &str)],
    f: impl FnOnce(&mut AssessSettings),
) -> CResult {
    // SAFETY: forwarded caller's contract.
    unsafe {
        validated(
            settings,
            |h| &mut h.settings,
            AssessSettings::validate,
            args,
            f,
        )
    }
}

fn flag(name: &str, v: u32) -> CResult<bool> {
    match v {
        0 => Ok(false),
        1 => Ok(true),
        v => Err(Failure::invalid(name, format!("{v} is not 0 or 1"))),
    }
}

/// Sets the analysis: a `VsrObjective`. Default `VSR_OBJECTIVE_FIT`.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assess_settings_set_objective(
    settings: *mut VsrAssessSettings,
    objective: u32,
) -> VsrStatus {
    boundary!({
        let o = enum_args::objective("objective", objective)?;
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |s| s.objective = o) }
    })
}

/// 1 keeps the supports at the mesh's heights (they must lie inside the envelope); 0 (default)
/// lets the thrust meet each support anywhere between its intrados and extrados.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assess_settings_set_fixed_supports(
    settings: *mut VsrAssessSettings,
    fixed: u32,
) -> VsrStatus {
    boundary!({
        let on = flag("fixed", fixed)?;
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |s| s.fixed_supports = on) }
    })
}

/// Sets the weight per unit volume of the masonry: a face weighs its area on the middle
/// surface × its thickness × `unit_weight`. Finite and >= 0 (0: the mesh's extra loads
/// alone). Default 1.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assess_settings_set_unit_weight(
    settings: *mut VsrAssessSettings,
    unit_weight: f64,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |s| s.unit_weight = unit_weight) }
    })
}

/// Sets how a face's weight is shared among its corners: a `VsrLoadRule`. Default
/// `VSR_LOAD_RULE_BARYCENTRIC`.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assess_settings_set_load_rule(
    settings: *mut VsrAssessSettings,
    rule: u32,
) -> VsrStatus {
    boundary!({
        let rule = enum_args::load_rule("rule", rule)?;
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |s| s.load_rule = rule) }
    })
}

/// Sets the live load of `VSR_OBJECTIVE_MAX_LOAD`: a downward load per mesh vertex, #V
/// doubles (copied; each finite, >= 0 and at most 1e150, one at least > 0), multiplied by λ
/// and added to the self-weight. `n` 0 removes it (the
/// default: none). Other objectives ignore it; `vsr_assess` checks its length against the
/// mesh and, for max-load, that it loads a non-anchored vertex.
///
/// # Safety
/// `settings`: a valid handle with exclusive access; `loads`: `n` readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assess_settings_set_load_pattern(
    settings: *mut VsrAssessSettings,
    loads: *const f64,
    n: usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let values = unsafe { input("loads", loads, n)? };
        let pattern = (n > 0).then(|| values.to_vec());
        let args = [("load_pattern", "loads")];
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &args, |s| s.load_pattern = pattern) }
    })
}

/// Sets the lower bound on the force densities: `kind` a `VsrBoundKind` (absolute, force
/// per length; or relative, × mean load / half the plan diagonal). Finite and >= 0. Default 0
/// absolute: compression only.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assess_settings_set_q_min(
    settings: *mut VsrAssessSettings,
    value: f64,
    kind: u32,
) -> VsrStatus {
    boundary!({
        let relative = enum_args::bound_kind("kind", kind)?;
        let bound = if relative {
            QBound::Relative(value)
        } else {
            QBound::Absolute(value)
        };
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[("q_min", "value")], |s| s.q_min = bound) }
    })
}

/// Sets the largest ε∞ (max vertical residual / mean load, dimensionless) of a certified
/// thrust surface. In (0, 1). Default 1e-6.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assess_settings_set_tolerance(
    settings: *mut VsrAssessSettings,
    tolerance: f64,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |s| s.tolerance = tolerance) }
    })
}

/// Sets the most sequential QP steps of each search (>= 1): the start's, the analysis' own
/// and each retry's count their own (the assessment's iteration count sums them all). Default
/// 200.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assess_settings_set_max_iterations(
    settings: *mut VsrAssessSettings,
    max_iterations: usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({ unsafe { update(settings, &[], |s| s.max_iterations = max_iterations) } })
}

/// Sets the progress callback of `vsr_assess` (a `VsrProgressFn`, called once per step, the
/// steps of its start and of its `needed_scale` search included, with the 1-based step and,
/// in place of ε∞, the infeasibility of the state reached: its largest vertical residual over
/// the mean load) and the `user` pointer passed back to it unchanged.
/// A non-zero return cancels (`VSR_TERMINATION_CANCELLED`). `callback` NULL removes it
/// (default: none). As `vsr_settings_set_progress` otherwise.
///
/// # Safety
/// `settings`: a valid handle with exclusive access; `callback`: NULL or a function with the
/// `VsrProgressFn` signature.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assess_settings_set_progress(
    settings: *mut VsrAssessSettings,
    callback: VsrProgressFn,
    user: *mut c_void,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({ unsafe { Progress::set(settings, |s| &mut s.progress, callback, user) } })
}

/// Masonry assessment (Heyman's safe theorem): a compression-only thrust surface over the
/// mesh's plan in equilibrium with the masonry's self-weight (the envelope's thickness × unit
/// weight on its middle surface, plus the mesh's extra loads and, for max-load, λ × the load
/// pattern) that lies between intrados and extrados, optimal for the settings' objective.
/// The mesh's face densities are not used. Calls the progress callback of `settings`, if
/// any, once per step on this thread.
///
/// A search that finds no certified surface is still `VSR_STATUS_OK`: read
/// `vsr_assessment_outcome` (feasible 0 with the least infeasible state, and where it fails).
/// `out` receives a new assessment owned by the caller (free with `vsr_assessment_destroy`);
/// untouched on failure. `mesh`, `envelope` and `settings` are only read.
///
/// Errors: NULL arguments (`VSR_STATUS_NULL_POINTER`); an envelope made for another mesh, a
/// load pattern of the wrong length (or, for max-load, missing or 0 on every non-anchored
/// vertex), fixed supports outside the envelope, a mesh whose every vertex is anchored
/// (`VSR_STATUS_INVALID_ARGUMENT`, naming the argument); `VSR_STATUS_NUMERICAL` when a QP
/// fails.
///
/// # Safety
/// `mesh`, `envelope`, `settings`: valid handles; `out` writable; the callback and its `user`
/// pointer valid for the duration of the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_assess(
    mesh: *const VsrMesh,
    envelope: *const VsrEnvelope,
    settings: *const VsrAssessSettings,
    out: *mut *mut VsrAssessment,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let (mesh, envelope, settings) = unsafe {
            (
                handle("mesh", mesh)?,
                handle("envelope", envelope)?,
                handle("settings", settings)?,
            )
        };
        let out = out_ptr("out", out)?;
        let (problem, s) = (&mesh.problem, &settings.settings);
        let result = (settings.progress)
            .run(|progress| assess(problem, &envelope.envelope, s, progress))
            .map_err(|e| from_error("mesh", e))?;
        let handle = Box::new(VsrAssessment::new(&problem.mesh, result));
        // SAFETY: non-NULL, writable by the caller's contract.
        unsafe { out.write(Box::into_raw(handle)) };
        Ok(())
    })
}
