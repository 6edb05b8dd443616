//! What a nearest-method run leaves for a warm re-solve after an edit ([`super::form_find_from`]),
//! and the checks that a previous result fits the problem it is to start.

use super::FormFindResult;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::problem::Problem;
use crate::stress::StressCache;
use std::hash::{Hash, Hasher};
use std::sync::Mutex;

/// The state of the nearest method's penalty continuation where a run ended, kept with its
/// result (shared between clones) so that a re-solve after a small edit picks it up.
pub(crate) struct Continuation {
    /// A fingerprint of the faces the run solved on.
    pub(super) faces: u64,
    /// Multipliers of the equilibrium rows (units of r̂) per vertex; 0 at anchored vertices.
    pub(super) lambda: Vec<f64>,
    /// The penalty weight w the run ended with, and the one it started from (stalling is
    /// judged against the start).
    pub(super) w: f64,
    pub(super) w_start: f64,
    /// Stress steps whose dual-length smoothing has faded: the next run's smoothing starts at
    /// `dual_length_smoothing` × decay^faded.
    pub(super) faded: usize,
    /// The stress steps' cache (ordering and symbolic factorisation, last active set, reduced
    /// operator); taken by the first re-solve from this result, later ones build their own.
    pub(super) cache: Mutex<Option<StressCache>>,
}

impl std::fmt::Debug for Continuation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Continuation")
            .field("w", &self.w)
            .field("w_start", &self.w_start)
            .field("faded", &self.faded)
            .finish_non_exhaustive()
    }
}

/// A fingerprint of `mesh`'s faces.
pub(super) fn faces_fingerprint(mesh: &Mesh) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    mesh.faces.hash(&mut h);
    h.finish()
}

fn invalid(reason: String) -> Error {
    Error::InvalidArgument {
        name: "previous",
        reason,
    }
}

/// Checks that `previous` is a result on `problem`'s mesh (same vertices, edges and faces;
/// heights may differ, and so may supports, loads and settings) with finite heights at its
/// referenced vertices; returns its continuation where it has one.
pub(super) fn check<'r>(
    problem: &Problem,
    previous: &'r FormFindResult,
) -> Result<Option<&'r Continuation>> {
    let mesh = &problem.mesh;
    let (n, m) = (mesh.positions.len(), previous.positions.len());
    if n != m {
        return Err(invalid(format!(
            "has {m} vertices, the mesh has {n}: a warm re-solve needs the mesh it was found on"
        )));
    }
    let (e, f) = (mesh.edges.len(), previous.stress.force_densities.len());
    if e != f {
        return Err(invalid(format!(
            "has force densities on {f} edges, the mesh has {e}: a warm re-solve needs the \
             mesh it was found on"
        )));
    }
    let cont = previous.warm.as_deref();
    if cont.is_some_and(|c| c.faces != faces_fingerprint(mesh)) {
        return Err(invalid(
            "was found on a mesh with other faces: a warm re-solve needs the same faces".into(),
        ));
    }
    let bad = (0..n).find(|&v| mesh.referenced[v] && !previous.positions[v][2].is_finite());
    if let Some(v) = bad {
        return Err(invalid(format!("has a non-finite height at vertex {v}")));
    }
    Ok(cont)
}
