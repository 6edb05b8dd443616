//! Mesh files through the C ABI: `vsr_mesh_read` and `vsr_result_write`.

use std::ffi::{c_char, CStr};
use std::path::PathBuf;

use super::boundary::{boundary, checked_len, copy, from_error, handle, input, out_ptr};
use super::boundary::{CResult, Failure};
use super::mesh::VsrMesh;
use super::result::VsrResult;
use super::status::VsrStatus;
use crate::io::{self, ReadOptions, Supports};
use crate::mesh::repair::PlanRepair;

/// A path argument: non-NULL, NUL-terminated UTF-8.
///
/// # Safety
/// When non-NULL, `ptr` must point to a NUL-terminated string.
pub(super) unsafe fn path_arg(name: &str, ptr: *const c_char) -> CResult<PathBuf> {
    if ptr.is_null() {
        return Err(Failure::null(name));
    }
    // SAFETY: non-NULL and NUL-terminated by the caller's contract.
    let text = unsafe { CStr::from_ptr(ptr) };
    text.to_str()
        .map(PathBuf::from)
        .map_err(|_| Failure::invalid(name, "is not UTF-8"))
}

/// Creates a mesh from a file: OBJ, OFF, STL (binary or ASCII) or PLY (ASCII or binary),
/// chosen by the extension of `path` (case-insensitive `.obj`, `.off`, `.stl`, `.ply`);
/// polygons are split into fans, and q_min does not bind the diagonals that splitting adds
/// (a quad mesh of rings split along one diagonal has no force network with q > 0 on them).
///
/// - `path`: the mesh file, a NUL-terminated UTF-8 path.
/// - `supports_path`: a JSON file of anchored vertex ids (`{"anchored": [ids]}` or `[ids]`),
///   or NULL to use `anchored` instead.
/// - `anchored`: `n_anchored` anchored vertex ids when `supports_path` is NULL (NULL when
///   `n_anchored` is 0). Giving both is `VSR_STATUS_INVALID_ARGUMENT`.
/// - `weld_tolerance`: vertices closer than `weld_tolerance` × (bounding box diagonal) are
///   merged into the first of them (0 merges exactly equal positions only; default in the Rust
///   API 1e-9); finite and >= 0. STL files, whose triangles never share vertices, need it.
/// - `repair_tolerance`: faces whose plan area is below `repair_tolerance` × (median plan
///   area), tiny or slightly inverted, are mended before validation by plan edge flips or the
///   smallest plan move of a non-anchored vertex (see `vsr_mesh_plan_flips` and
///   `vsr_mesh_plan_nudges`); 0 mends nothing and rejects the faces a tolerance of 1e-4 would
///   mend (`VSR_STATUS_INVALID_PLAN` naming them). Finite and >= 0; the Rust API's default is
///   1e-4.
/// - `n_merged`: receives how many of the file's vertices were merged into another; may be
///   NULL.
/// - `out`: receives a new handle on success, owned by the caller (free with
///   `vsr_mesh_destroy`); untouched on failure.
///
/// Support ids are the file's own 0-based vertex ids (an STL file has three per triangle:
/// vertex `3t + k` is corner `k` of triangle `t`). The mesh's vertices are the welded ones,
/// numbered in the order of their first vertex in the file; `vsr_mesh_welded_ids` maps file
/// ids onto them. Loads and defaults are those of `vsr_mesh_create`.
///
/// Errors: NULL `path` or `out` (`VSR_STATUS_NULL_POINTER`); an unknown extension, a file
/// that cannot be read, or a malformed file (`VSR_STATUS_INVALID_ARGUMENT`, the message names
/// the file and its line, or the element of a binary file); a support id `>=` the file's
/// vertex count (`VSR_STATUS_INDEX_OUT_OF_RANGE`); then the checks of `vsr_mesh_create`.
///
/// # Safety
/// `path` and `supports_path` (when non-NULL) must be NUL-terminated strings; `anchored` must
/// hold `n_anchored` readable ids; `n_merged` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_read(
    path: *const c_char,
    supports_path: *const c_char,
    anchored: *const u32,
    n_anchored: usize,
    weld_tolerance: f64,
    repair_tolerance: f64,
    n_merged: *mut usize,
    out: *mut *mut VsrMesh,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        let path = unsafe { path_arg("path", path)? };
        let out = out_ptr("out", out)?;
        if n_anchored > 0 && anchored.is_null() {
            return Err(Failure::null("anchored"));
        }
        let n = checked_len::<u32>("anchored", "n_anchored", n_anchored, 1)?;
        // SAFETY: length checked; readability is the caller's contract.
        let ids = unsafe { input("anchored", anchored, n)? };
        let supports = if supports_path.is_null() {
            Supports::Ids(ids.to_vec())
        } else {
            if n_anchored > 0 {
                return Err(Failure::invalid(
                    "anchored",
                    "give either `supports_path` or `anchored`, not both",
                ));
            }
            // SAFETY: non-NULL; NUL-terminated by the caller's contract.
            Supports::File(unsafe { path_arg("supports_path", supports_path)? })
        };
        let options = ReadOptions::new(supports)
            .with_weld_tolerance(Some(weld_tolerance))
            .with_repair_tolerance(repair_tolerance);
        let model = io::read_model(&path, &options).map_err(|e| match e {
            crate::Error::InvalidArgument { name, reason }
                if matches!(name, "weld_tolerance" | "repair_tolerance") =>
            {
                Failure::invalid(name, reason)
            }
            e if options.blames_supports_file(&e) => from_error("supports_path", e),
            e => from_error("path", e),
        })?;
        if !n_merged.is_null() {
            let merged = model.weld.as_ref().map_or(0, |w| w.merged);
            // SAFETY: non-NULL; writable by the caller's contract.
            unsafe { n_merged.write(merged) };
        }
        let handle = Box::new(VsrMesh::from_model(model));
        // SAFETY: `out` is non-NULL and writable by the caller's contract.
        unsafe { out.write(Box::into_raw(handle)) };
        Ok(())
    })
}

/// The mesh vertex id of each vertex of the file `vsr_mesh_read` read (several file vertices
/// share one id where they were welded); for a mesh from `vsr_mesh_create`, `0 .. #V - 1`.
/// Copy-out as described in the header's introduction: `uint32_t` entries, one per file
/// vertex.
///
/// # Safety
/// `mesh`: a valid handle; `out`: NULL or `len` writable ids; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_welded_ids(
    mesh: *const VsrMesh,
    out: *mut u32,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            copy("mesh", mesh, out, len, needed, |m| {
                Ok(match &m.welded_ids {
                    Some(ids) => ids.clone(),
                    None => (0..m.problem.mesh.n_vertices() as u32).collect(),
                })
            })
        }
    })
}

/// Writes the result's vertex positions with the mesh's triangles to `path`, in the format of
/// its extension (`.obj`, `.off`, `.ply` binary little-endian, `.stl` binary), all or nothing:
/// the file is written beside `path` under a temporary name and renamed over it.
///
/// OBJ, OFF and PLY keep every bit of the positions (the shortest decimal that reads back the
/// same double, or doubles). STL stores single precision by definition: about 7 significant
/// digits, enough to view or print a shape but not to keep its equilibrium. Triangles are
/// written in the orientation they were given (the mesh's internal reversal of a clockwise
/// plan is undone).
///
/// Errors: NULL arguments (`VSR_STATUS_NULL_POINTER`); a result with another vertex count than
/// the mesh, an unknown extension, `.3mf` (3MF holds closed solids: see
/// `vsr_result_write_solid`), or a file that cannot be written (`VSR_STATUS_INVALID_ARGUMENT`).
///
/// # Safety
/// `result`, `mesh`: valid handles; `path`: a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_result_write(
    result: *const VsrResult,
    mesh: *const VsrMesh,
    path: *const c_char,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        let (result, mesh, path) = unsafe { write_args(result, mesh, path)? };
        let positions = result.positions();
        let faces = mesh.problem.mesh.input_faces();
        let format = io::MeshFormat::from_path(&path).map_err(|e| from_error("path", e))?;
        if format == io::MeshFormat::ThreeMf {
            return Err(Failure::invalid(
                "path",
                "3MF holds closed solids: write the surface as .obj, .off, .ply or .stl, or a \
                 solid with vsr_result_write_solid",
            ));
        }
        io::write_mesh_as(&path, format, positions, &faces).map_err(|e| from_error("path", e))
    })
}

/// The checked arguments of a result writer: both handles, the path, and a mesh whose vertex
/// count is the result's.
///
/// # Safety
/// `result`, `mesh`: valid handles or NULL; `path`: NULL or a NUL-terminated string.
pub(super) unsafe fn write_args<'a>(
    result: *const VsrResult,
    mesh: *const VsrMesh,
    path: *const c_char,
) -> CResult<(&'a VsrResult, &'a VsrMesh, PathBuf)> {
    // SAFETY: forwarded caller's contract.
    let (result, mesh, path) = unsafe {
        (
            handle("result", result)?,
            handle("mesh", mesh)?,
            path_arg("path", path)?,
        )
    };
    let (n, m) = (mesh.problem.mesh.n_vertices(), result.positions().len());
    if n != m {
        return Err(Failure::invalid(
            "mesh",
            format!("has {n} vertices, the result {m}: they do not belong together"),
        ));
    }
    Ok((result, mesh, path))
}

/// The plan edge flips `vsr_mesh_read` made, in order: #flips by 6 `uint32_t`, row-major:
/// the two faces (which keep their ids), the two vertices of the removed edge and the two of
/// the added edge. None for a mesh from `vsr_mesh_create`. Copy-out as described in the
/// header's introduction.
///
/// # Safety
/// `mesh`: a valid handle; `out`: NULL or `len` writable ids; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_plan_flips(
    mesh: *const VsrMesh,
    out: *mut u32,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            repairs(mesh, out, len, needed, |r| match r {
                PlanRepair::Flip {
                    faces,
                    removed,
                    added,
                } => vec![
                    faces[0] as u32,
                    faces[1] as u32,
                    removed[0],
                    removed[1],
                    added[0],
                    added[1],
                ],
                _ => Vec::new(),
            })
        }
    })
}

/// The plan moves `vsr_mesh_read` made, in order: #nudges by 2 `uint32_t`, row-major: the
/// moved vertex and the face it mended. The vertex keeps its height; its new plan position is
/// the mesh's (as `vsr_result_positions` of an analysis gives it). None for a mesh from
/// `vsr_mesh_create`. Copy-out as described in the header's introduction.
///
/// # Safety
/// `mesh`: a valid handle; `out`: NULL or `len` writable ids; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_plan_nudges(
    mesh: *const VsrMesh,
    out: *mut u32,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({
        unsafe {
            repairs(mesh, out, len, needed, |r| match r {
                PlanRepair::Nudge { vertex, face, .. } => vec![*vertex, *face as u32],
                _ => Vec::new(),
            })
        }
    })
}

/// Copies out the rows `row` gives for the plan repairs `vsr_mesh_read` made, in order.
///
/// # Safety
/// As [`copy`].
unsafe fn repairs(
    mesh: *const VsrMesh,
    out: *mut u32,
    len: usize,
    needed: *mut usize,
    row: impl Fn(&PlanRepair) -> Vec<u32>,
) -> CResult {
    // SAFETY: forwarded caller's contract.
    unsafe {
        copy("mesh", mesh, out, len, needed, |m| {
            Ok(m.repairs.iter().flat_map(row).collect())
        })
    }
}
