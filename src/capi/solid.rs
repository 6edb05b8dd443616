//! Printable solids through the C ABI: `vsr_result_write_solid` and
//! `vsr_result_write_solid_from_density`.

use std::ffi::c_char;

use super::boundary::{boundary, from_error, CResult};
use super::files::write_args;
use super::mesh::VsrMesh;
use super::result::VsrResult;
use super::status::VsrStatus;
use crate::solid::{thicken, Thickness};

/// Thickens the result's shape and writes the solid to `path`.
///
/// # Safety
/// `result`, `mesh`: valid handles or NULL; `path`: NULL or a NUL-terminated string.
unsafe fn write_solid(
    result: *const VsrResult,
    mesh: *const VsrMesh,
    path: *const c_char,
    thickness: impl FnOnce(&VsrMesh) -> CResult<Thickness>,
) -> CResult {
    // SAFETY: forwarded caller's contract.
    let (result, mesh, path) = unsafe { write_args(result, mesh, path)? };
    let (m, positions) = (&mesh.problem.mesh, result.positions());
    let format = crate::io::MeshFormat::from_path(&path).map_err(|e| from_error("path", e))?;
    let solid = thicken(m, positions, &thickness(mesh)?).map_err(|e| from_error("thickness", e))?;
    crate::io::write_mesh_as(&path, format, &solid.positions, &solid.faces)
        .map_err(|e| from_error("path", e))
}

/// Writes a printable solid of the result's shape to `path`: the surface thickened by
/// `thickness` (a length in the units of the positions; half above, half below, along
/// area-weighted vertex normals, divided by the mean cosine to the faces' normals so that
/// creases keep their thickness) and closed by walls along every boundary loop, outer and
/// holes. The solid is one closed triangle mesh, every edge shared by two faces in opposite
/// directions, faces pointing outwards: upper vertices first (one per mesh vertex that a face
/// uses, in id order), then the lower ones, then the faces of the upper surface, of the lower
/// surface and of the walls. The format follows the extension as in `vsr_result_write`, plus
/// `.3mf` (a 3MF package: closed meshes only, in millimetres); `.stl` is binary, single
/// precision. All or nothing, as `vsr_result_write`.
///
/// Errors: NULL arguments (`VSR_STATUS_NULL_POINTER`); a `thickness` that is not a finite
/// number above 0, a thickness so large that an offset face would turn over (the solid would
/// intersect itself; the message names the face, its vertices and the largest thickness it
/// allows), a fold no offset direction clears (naming the vertex), parts of the shell so near
/// each other that the solid would cross itself (naming them), a result with another
/// vertex count than the mesh, an unknown extension, or a file that cannot be written
/// (`VSR_STATUS_INVALID_ARGUMENT`).
///
/// # Safety
/// `result`, `mesh`: valid handles; `path`: a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_write_solid(
    result: *const VsrResult,
    mesh: *const VsrMesh,
    thickness: f64,
    path: *const c_char,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe { write_solid(result, mesh, path, |_| Ok(Thickness::Uniform(thickness))) }
    })
}

/// As `vsr_result_write_solid`, with a thickness per face derived from the mesh's face
/// densities (`vsr_mesh_set_face_density`, default 1): density / `unit_weight`, density
/// being weight per unit area and `unit_weight` weight per unit volume. A vertex takes the
/// area-weighted mean of its faces' thicknesses.
///
/// Errors: those of `vsr_result_write_solid`; a `unit_weight` that is not finite and > 0, or
/// a face of density 0 (`VSR_STATUS_INVALID_ARGUMENT`, naming the face).
///
/// # Safety
/// `result`, `mesh`: valid handles; `path`: a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_write_solid_from_density(
    result: *const VsrResult,
    mesh: *const VsrMesh,
    unit_weight: f64,
    path: *const c_char,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            write_solid(result, mesh, path, |m| {
                Thickness::from_density(&m.problem.face_density, unit_weight)
                    .map_err(|e| from_error("unit_weight", e))
            })
        }
    })
}
