//! `VsrMesh`: a validated mesh and its loading (a [`Problem`]).

use super::boundary::{
    boundary, checked_len, copy, free, from_error, handle, handle_mut, input, out_ptr, CResult,
    Failure,
};
use super::status::VsrStatus;
use crate::mesh::Mesh;
use crate::problem::Problem;

/// Opaque handle: a validated triangle mesh (plan x, y; height z), its supports and its loads.
/// Create with `vsr_mesh_create`, free with `vsr_mesh_destroy`.
pub struct VsrMesh {
    pub(crate) problem: Problem,
    /// For a mesh read from a file, the mesh vertex of each of the file's vertices.
    pub(crate) welded_ids: Option<Vec<u32>>,
    /// For a mesh read from a file, the plan repairs made before validation.
    pub(crate) repairs: Vec<crate::mesh::repair::PlanRepair>,
}

impl VsrMesh {
    /// The handle of a mesh file read by [`crate::io::read_model`].
    pub(crate) fn from_model(model: crate::io::Model) -> VsrMesh {
        VsrMesh {
            problem: model.problem,
            welded_ids: Some(model.welded_ids),
            repairs: model.repairs,
        }
    }
}

/// Largest vertex count (ids are `uint32_t`).
const MAX_VERTICES: usize = u32::MAX as usize;
/// Largest triangle count (edge and half-edge ids must fit in `uint32_t`).
const MAX_TRIANGLES: usize = (u32::MAX / 6) as usize;

fn too_many(name: &str, count: &str, n: usize, max: usize) -> CResult {
    if n > max {
        return Err(Failure::new(
            VsrStatus::LengthOverflow,
            format!("argument `{name}`: {count} = {n} exceeds the supported maximum {max}"),
        ));
    }
    Ok(())
}

/// Creates a mesh from flat arrays and validates it.
///
/// - `positions`: #V by 3 doubles, row-major (x, y, z per vertex; x, y is the plan and z the
///   height, in any consistent length unit). `n_vertices` = #V rows.
/// - `triangles`: #F by 3 `uint32_t` vertex ids (0-based), row-major; `n_triangles` = #F. The
///   plan may be counter-clockwise or clockwise (then all faces are reversed internally; edge
///   and face ids are unchanged).
/// - `anchored`: `n_anchored` vertex ids of the supports (each at most once).
/// - `out`: receives a new handle on success, owned by the caller (free with
///   `vsr_mesh_destroy`); untouched on failure.
///
/// Arrays are copied; the caller keeps ownership of them. An array may be NULL only when its
/// length is 0. Loads default to density 1 per unit of 3-D area on every face, no extra vertex
/// loads, no horizontal forces and τ = 0 (see the `vsr_mesh_set_*` functions).
///
/// Checked in this order: NULL pointers; lengths (`n * 3` overflow, at most 2^32 - 1 vertices
/// and (2^32 - 1) / 6 triangles: `VSR_STATUS_LENGTH_OVERFLOW`); empty mesh; ids `>= n_vertices`
/// (`VSR_STATUS_INDEX_OUT_OF_RANGE`); repeated supports; NaN or infinite coordinates of vertices
/// used by a triangle (`VSR_STATUS_NON_FINITE`); coordinates beyond ±1e150, or a plan less than
/// 1e-150 across, whose areas double precision cannot represent
/// (`VSR_STATUS_INVALID_ARGUMENT`); topology (`VSR_STATUS_INVALID_TOPOLOGY`); plan validity:
/// zero-area, flipped or overlapping faces, including faces that overlap away from any shared
/// vertex (a strip winding over itself, components stacked in plan) (`VSR_STATUS_INVALID_PLAN`);
/// supports (`VSR_STATUS_NO_SUPPORT`). The message names the offending vertex, face or edge
/// ids. Vertices used by no triangle are ignored.
///
/// # Safety
/// Each non-NULL array must hold the stated number of readable elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_create(
    positions: *const f64,
    n_vertices: usize,
    triangles: *const u32,
    n_triangles: usize,
    anchored: *const u32,
    n_anchored: usize,
    out: *mut *mut VsrMesh,
) -> VsrStatus {
    boundary!({
        if n_vertices > 0 && positions.is_null() {
            return Err(Failure::null("positions"));
        }
        if n_triangles > 0 && triangles.is_null() {
            return Err(Failure::null("triangles"));
        }
        if n_anchored > 0 && anchored.is_null() {
            return Err(Failure::null("anchored"));
        }
        let out = out_ptr("out", out)?;
        let n_pos = checked_len::<f64>("positions", "n_vertices", n_vertices, 3)?;
        let n_tri = checked_len::<u32>("triangles", "n_triangles", n_triangles, 3)?;
        checked_len::<u32>("anchored", "n_anchored", n_anchored, 1)?;
        too_many("positions", "n_vertices", n_vertices, MAX_VERTICES)?;
        too_many("triangles", "n_triangles", n_triangles, MAX_TRIANGLES)?;
        too_many("anchored", "n_anchored", n_anchored, MAX_VERTICES)?;
        // SAFETY: lengths checked above; readability is the caller's contract.
        let (pos, tri, anc) = unsafe {
            (
                input("positions", positions, n_pos)?,
                input("triangles", triangles, n_tri)?,
                input("anchored", anchored, n_anchored)?,
            )
        };
        let pos: Vec<[f64; 3]> = pos.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let tri: Vec<[u32; 3]> = tri.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let arg = if pos.is_empty() {
            "positions"
        } else {
            "triangles"
        };
        let mesh = Mesh::new(pos, tri, anc).map_err(|e| from_error(arg, e))?;
        let handle = Box::new(VsrMesh {
            problem: Problem::new(mesh),
            welded_ids: None,
            repairs: Vec::new(),
        });
        // SAFETY: `out` is non-NULL and writable by the caller's contract.
        unsafe { out.write(Box::into_raw(handle)) };
        Ok(())
    })
}

/// Frees a mesh. NULL is a no-op. Results computed from it stay valid (they own their data).
///
/// # Safety
/// `mesh` must be NULL or a handle from `vsr_mesh_create` not yet destroyed, used by no
/// other thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_destroy(mesh: *mut VsrMesh) {
    // SAFETY: forwarded caller's contract.
    boundary!(keep_error, (), { unsafe { free(mesh) } })
}

/// Reads `rows` by `width` doubles (one row per face or per vertex), checks finiteness, and applies `set` to a copy of the
/// problem, which replaces the handle's only on success.
#[allow(clippy::too_many_arguments)]
unsafe fn set_rows(
    mesh: *mut VsrMesh,
    name: &str,
    count: &str,
    data: *const f64,
    rows: usize,
    width: usize,
    per_face: bool,
    set: impl FnOnce(Problem, &[f64]) -> crate::Result<Problem>,
) -> CResult {
    // SAFETY: caller's contract (valid handle, exclusive access).
    let mesh = unsafe { handle_mut("mesh", mesh)? };
    if rows > 0 && data.is_null() {
        return Err(Failure::null(name));
    }
    let n = checked_len::<f64>(name, count, rows, width)?;
    let m = &mesh.problem.mesh;
    let expected = if per_face {
        m.n_faces()
    } else {
        m.n_vertices()
    };
    if rows != expected {
        return Err(Failure::invalid(
            count,
            format!(
                "is {rows}, expected {expected} (one row per {})",
                if per_face { "face" } else { "vertex" }
            ),
        ));
    }
    // SAFETY: length checked; readability is the caller's contract.
    let values = unsafe { input(name, data, n)? };
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(Failure::new(
            VsrStatus::NonFinite,
            format!(
                "argument `{name}`: entry {} (row {}) is {}",
                i,
                i / width,
                values[i]
            ),
        ));
    }
    let problem = set(mesh.problem.clone(), values).map_err(|e| match e {
        crate::Error::InvalidArgument { reason, .. } => Failure::invalid(name, reason),
        e => from_error(name, e),
    })?;
    mesh.problem = problem;
    Ok(())
}

/// Sets the weight per unit area of each face (density × thickness × g, force per area; the
/// load rule decides which area, see `vsr_settings_set_load_rule`).
///
/// `density`: #F doubles, finite and >= 0; `n_faces` must equal the mesh's #F. Default: 1 on
/// every face. The array is copied. On failure the mesh keeps its previous values. Zeros are
/// accepted here, but `vsr_analyse` and `vsr_form_find` return `VSR_STATUS_INVALID_ARGUMENT`
/// (naming `loads`) when the loads on the non-anchored vertices average 0 or less (nothing to
/// balance), or lie beyond what double precision carries through a solve (a mean outside
/// 1e-150 to 1e150).
///
/// # Safety
/// `mesh`: a valid handle with exclusive access; `density`: `n_faces` readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_set_face_density(
    mesh: *mut VsrMesh,
    density: *const f64,
    n_faces: usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            set_rows(
                mesh,
                "density",
                "n_faces",
                density,
                n_faces,
                1,
                true,
                |p, v| p.with_face_density(v.to_vec()),
            )
        }
    })
}

/// Sets an extra vertical point load per vertex (force, downward positive; negative values
/// lift), added to the face weights.
///
/// `loads`: #V doubles, finite; `n_vertices` must equal the mesh's #V. Default: 0. Copied.
/// On failure the mesh keeps its previous values.
///
/// # Safety
/// `mesh`: a valid handle with exclusive access; `loads`: `n_vertices` readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_set_extra_loads(
    mesh: *mut VsrMesh,
    loads: *const f64,
    n_vertices: usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            set_rows(
                mesh,
                "loads",
                "n_vertices",
                loads,
                n_vertices,
                1,
                false,
                |p, v| p.with_extra_loads(v.to_vec()),
            )
        }
    })
}

/// Sets a prescribed horizontal force (fx, fy; force) per vertex. Only free boundary vertices
/// (on the boundary, not anchored) may carry a non-zero force: interior vertices are balanced
/// by the Airy function, anchored ones by their support.
///
/// `forces`: #V by 2 doubles, row-major, finite; `n_vertices` = #V rows. Default: 0. Copied.
/// On failure the mesh keeps its previous values.
///
/// # Safety
/// `mesh`: a valid handle with exclusive access; `forces`: `2 * n_vertices` readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_set_horizontal_forces(
    mesh: *mut VsrMesh,
    forces: *const f64,
    n_vertices: usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            set_rows(
                mesh,
                "forces",
                "n_vertices",
                forces,
                n_vertices,
                2,
                false,
                |p, v| p.with_horizontal_forces(v.chunks_exact(2).map(|c| [c[0], c[1]]).collect()),
            )
        }
    })
}

/// Sets the prescribed inward normal push τ per vertex (force), used at free boundary
/// vertices when the τ mode is `VSR_TAU_MODE_PRESCRIBED` (ignored elsewhere).
///
/// `tau`: #V doubles, finite and >= 0; `n_vertices` must equal the mesh's #V. Default: 0.
/// Copied. On failure the mesh keeps its previous values.
///
/// # Safety
/// `mesh`: a valid handle with exclusive access; `tau`: `n_vertices` readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_set_prescribed_tau(
    mesh: *mut VsrMesh,
    tau: *const f64,
    n_vertices: usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe {
            set_rows(
                mesh,
                "tau",
                "n_vertices",
                tau,
                n_vertices,
                1,
                false,
                |p, v| p.with_prescribed_tau(v.to_vec()),
            )
        }
    })
}

/// Sizes of a mesh: vertices #V (as given, including ones used by no triangle), undirected
/// edges #E, faces #F and holes #H (boundary loops that are not the outer loop of their
/// component). All four pointers are required; written only on success.
///
/// # Safety
/// `mesh`: a valid handle; the out-pointers writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_counts(
    mesh: *const VsrMesh,
    n_vertices: *mut usize,
    n_edges: *mut usize,
    n_faces: *mut usize,
    n_holes: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        let mesh = unsafe { handle("mesh", mesh)? };
        let outs = [
            out_ptr("n_vertices", n_vertices)?,
            out_ptr("n_edges", n_edges)?,
            out_ptr("n_faces", n_faces)?,
            out_ptr("n_holes", n_holes)?,
        ];
        let m = &mesh.problem.mesh;
        let values = [m.n_vertices(), m.n_edges(), m.n_faces(), m.holes().count()];
        for (p, v) in outs.into_iter().zip(values) {
            // SAFETY: non-NULL and writable (caller's contract).
            unsafe { p.write(v) };
        }
        Ok(())
    })
}

/// Copies the undirected edges: #E by 2 `uint32_t` vertex ids (smaller id first), row-major,
/// sorted. Edge e here is edge e of every per-edge result (force densities, segments).
///
/// `out`: buffer of `len` `uint32_t` (needs 2 #E), or NULL with `len` 0 to query the size.
/// `needed` (may be NULL) receives 2 #E on success and on `VSR_STATUS_BUFFER_TOO_SMALL`.
///
/// # Safety
/// `mesh`: a valid handle; `out`: NULL or `len` writable elements; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_edges(
    mesh: *const VsrMesh,
    out: *mut u32,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        unsafe {
            copy("mesh", mesh, out, len, needed, |m| {
                Ok(m.problem.mesh.edges.iter().flat_map(|e| e.v).collect())
            })
        }
    })
}

/// Marks the edges that split the polygons of the model into triangles, as `vsr_mesh_read`
/// marks those of a file's polygons: q_min does not bind them (only q >= 0), since a force
/// network on a polygon mesh needs no force along them. Without them a mesh of quads split
/// along one diagonal per ring (a latitude-longitude dome) may admit no stress with every
/// q >= q_min > 0. Replaces the diagonals marked before (`n_diagonals` = 0 clears them).
///
/// `diagonals`: #D by 2 `uint32_t` vertex ids, row-major, each pair an interior edge of the
/// mesh (either order); NULL only when `n_diagonals` is 0. Copied.
///
/// Errors: NULL `mesh`, or `diagonals` with a non-zero count (`VSR_STATUS_NULL_POINTER`);
/// `n_diagonals * 2` overflowing (`VSR_STATUS_LENGTH_OVERFLOW`); a vertex id `>= #V`
/// (`VSR_STATUS_INDEX_OUT_OF_RANGE`); a pair that is no interior edge
/// (`VSR_STATUS_INVALID_ARGUMENT`). The message names the pair; on failure the mesh keeps
/// the diagonals it had.
///
/// # Safety
/// `mesh`: a valid handle with exclusive access; `diagonals`: `2 n_diagonals` readable ids.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_set_polygon_diagonals(
    mesh: *mut VsrMesh,
    diagonals: *const u32,
    n_diagonals: usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract (valid handle, exclusive access).
        let mesh = unsafe { handle_mut("mesh", mesh)? };
        if n_diagonals > 0 && diagonals.is_null() {
            return Err(Failure::null("diagonals"));
        }
        let n = checked_len::<u32>("diagonals", "n_diagonals", n_diagonals, 2)?;
        // SAFETY: length checked; readability is the caller's contract.
        let ids = unsafe { input("diagonals", diagonals, n)? };
        let n_vertices = mesh.problem.mesh.n_vertices();
        if let Some(i) = ids.iter().position(|&v| v as usize >= n_vertices) {
            return Err(Failure::new(
                VsrStatus::IndexOutOfRange,
                format!(
                    "argument `diagonals`: pair {} has vertex {}, but there are only \
                     {n_vertices} vertices",
                    i / 2,
                    ids[i]
                ),
            ));
        }
        let pairs: Vec<[u32; 2]> = ids.chunks_exact(2).map(|p| [p[0], p[1]]).collect();
        let problem =
            (mesh.problem.clone().with_polygon_diagonals(&pairs)).map_err(|e| match e {
                crate::Error::InvalidArgument { reason, .. } => {
                    Failure::invalid("diagonals", reason)
                }
                e => from_error("diagonals", e),
            })?;
        mesh.problem = problem;
        Ok(())
    })
}

/// Copies the marked polygon diagonals (`vsr_mesh_set_polygon_diagonals`, or those of the
/// polygons of a file `vsr_mesh_read` read): #D by 2 `uint32_t` vertex ids, row-major,
/// smaller id first, in edge order. Copy-out as described in the header's introduction.
///
/// # Safety
/// `mesh`: a valid handle; `out`: NULL or `len` writable ids; `needed`: NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_mesh_polygon_diagonals(
    mesh: *const VsrMesh,
    out: *mut u32,
    len: usize,
    needed: *mut usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: caller's contract.
        unsafe {
            copy("mesh", mesh, out, len, needed, |m| {
                Ok(m.problem.polygon_diagonals().concat())
            })
        }
    })
}
