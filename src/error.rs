//! One error type for the whole crate. Every variant names what was wrong
//! (argument, vertex, face or edge ids) so a CAD user can find it in the model.

use std::fmt;

/// Lists at most this many offending ids in a message; the rest are counted.
const MAX_IDS_SHOWN: usize = 8;

/// Everything that can go wrong before or during a solve.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// An argument is invalid (empty, wrong length, NaN, out of range, ...).
    InvalidArgument {
        /// The argument (or setting) at fault.
        name: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// The mesh has no vertices or no faces.
    EmptyMesh,
    /// A face refers to a vertex index `>= n_vertices`.
    IndexOutOfRange {
        /// The face.
        face: usize,
        /// The vertex index it refers to.
        index: u64,
        /// The number of vertices.
        n_vertices: usize,
    },
    /// An anchored (support) id is `>= n_vertices` or repeated.
    InvalidAnchor {
        /// The id.
        index: u64,
        /// `out of range` or `listed twice`.
        reason: &'static str,
    },
    /// A vertex has a NaN or infinite coordinate.
    NonFiniteCoordinate {
        /// The vertex.
        vertex: usize,
    },
    /// A face lists the same vertex twice.
    RepeatedVertexInFace {
        /// The face.
        face: usize,
    },
    /// Two faces have the same three vertices.
    DuplicateFace {
        /// The later face.
        face: usize,
        /// The earlier face with the same vertices.
        first: usize,
    },
    /// Faces whose plan (x, y) projection has (near) zero area.
    DegenerateFaces {
        /// The faces.
        faces: Vec<usize>,
    },
    /// An edge shared by more than two faces.
    NonManifoldEdge {
        /// The edge's vertices.
        edge: [usize; 2],
        /// The faces that share it.
        faces: Vec<usize>,
    },
    /// A vertex whose faces do not form a single fan (bow-tie).
    NonManifoldVertex {
        /// The vertex.
        vertex: usize,
    },
    /// Two faces traverse their shared edge in the same direction.
    InconsistentOrientation {
        /// The edge's vertices.
        edge: [usize; 2],
        /// The two faces.
        faces: [usize; 2],
    },
    /// Faces whose plan orientation is opposite to the majority: the plan folds over itself.
    FlippedFaces {
        /// The flipped faces.
        faces: Vec<usize>,
    },
    /// Vertices whose plan angles do not sum to 2π (interior vertices) or exceed 2π (boundary
    /// vertices): the plan wraps around them.
    OverlappingPlan {
        /// The vertices.
        vertices: Vec<usize>,
    },
    /// Two faces that overlap in plan away from any shared vertex (a strip winding over
    /// itself, two components stacked in plan).
    OverlappingFaces {
        /// The two faces.
        faces: [usize; 2],
    },
    /// A connected component of the mesh has no anchored vertex.
    UnsupportedComponent {
        /// The component.
        component: usize,
        /// Its vertices.
        vertices: Vec<usize>,
    },
    /// No vertex is anchored at all.
    NoSupports,
    /// A hole could not be joined to its component's outer boundary or to another hole through
    /// interior vertices.
    HoleNotCuttable {
        /// The hole (its index among the mesh's holes).
        hole: usize,
        /// A vertex of its boundary.
        vertex: usize,
    },
    /// A numerical failure inside a solver (not a property of the input).
    Numerical {
        /// What failed, in words.
        what: String,
    },
    /// A file could not be read or written.
    Io {
        /// The file.
        path: String,
        /// The system's reason.
        reason: String,
    },
    /// A file could be read but its content is malformed.
    Parse {
        /// The file.
        path: String,
        /// The line at fault (1-based).
        line: usize,
        /// What is wrong there.
        reason: String,
    },
    /// A binary file (or a part of a file without lines) is malformed: `element` names the
    /// part at fault, such as `triangle 12` or `vertex 3`.
    Malformed {
        /// The file.
        path: String,
        /// The part at fault.
        element: String,
        /// What is wrong there.
        reason: String,
    },
}

/// At most [`MAX_IDS_SHOWN`] ids, comma-separated, then how many there are in all.
pub(crate) fn ids(list: &[usize]) -> String {
    let mut s: Vec<String> = list
        .iter()
        .take(MAX_IDS_SHOWN)
        .map(|i| i.to_string())
        .collect();
    if list.len() > MAX_IDS_SHOWN {
        s.push(format!("... ({} in all)", list.len()));
    }
    s.join(", ")
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use Error::*;
        match self {
            InvalidArgument { name, reason } => write!(f, "invalid argument `{name}`: {reason}"),
            EmptyMesh => write!(f, "empty mesh: it needs at least one vertex and one face"),
            IndexOutOfRange { face, index, n_vertices } => write!(
                f,
                "face {face} refers to vertex {index}, but there are only {n_vertices} vertices"
            ),
            InvalidAnchor { index, reason } => write!(f, "anchored vertex {index}: {reason}"),
            NonFiniteCoordinate { vertex } => {
                write!(f, "vertex {vertex} has a NaN or infinite coordinate")
            }
            RepeatedVertexInFace { face } => write!(f, "face {face} repeats a vertex"),
            DuplicateFace { face, first } => {
                write!(f, "face {face} has the same vertices as face {first}")
            }
            DegenerateFaces { faces } => {
                write!(f, "faces with (almost) zero plan area: {}", ids(faces))
            }
            NonManifoldEdge { edge, faces } => write!(
                f,
                "non-manifold edge ({}, {}) is shared by faces {}",
                edge[0],
                edge[1],
                ids(faces)
            ),
            NonManifoldVertex { vertex } => {
                write!(f, "non-manifold vertex {vertex}: its faces do not form one fan")
            }
            InconsistentOrientation { edge, faces } => write!(
                f,
                "inconsistent orientation: faces {} and {} traverse edge ({}, {}) in the same direction",
                faces[0], faces[1], edge[0], edge[1]
            ),
            FlippedFaces { faces } => write!(
                f,
                "the plan overlaps itself: faces flipped against the majority: {}",
                ids(faces)
            ),
            OverlappingPlan { vertices } => write!(
                f,
                "the plan overlaps itself around vertices {}",
                ids(vertices)
            ),
            OverlappingFaces { faces } => write!(
                f,
                "the plan overlaps itself: faces {} and {} overlap in plan",
                faces[0], faces[1]
            ),
            UnsupportedComponent { component, vertices } => write!(
                f,
                "connected component {component} has no anchored vertex (it contains vertices {})",
                ids(vertices)
            ),
            NoSupports => write!(f, "no vertex is anchored: a vault needs supports"),
            HoleNotCuttable { hole, vertex } => write!(
                f,
                "hole {hole} (at vertex {vertex}) cannot be joined to the outer boundary or another hole through interior vertices"
            ),
            Numerical { what } => write!(f, "numerical failure: {what}"),
            Io { path, reason } => write!(f, "{path}: {reason}"),
            Parse { path, line, reason } => write!(f, "{path}:{line}: {reason}"),
            Malformed {
                path,
                element,
                reason,
            } => write!(f, "{path}: {element}: {reason}"),
        }
    }
}

impl std::error::Error for Error {}

/// A failed sparse Cholesky factorisation of `matrix` as an [`Error::Numerical`] in words
/// (faer's own `Display` of these errors is their `Debug` text), for the shape step's
/// factorisations (`src/shape`).
pub(crate) fn factorisation_failure(matrix: &str, e: &faer::sparse::linalg::LltError) -> Error {
    use faer::sparse::linalg::LltError;
    let why = match e {
        LltError::Numeric(faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot {
            index,
        }) => format!(
            "the Cholesky factorisation met a non-positive pivot at row {index}: the matrix is \
             not positive definite"
        ),
        LltError::Generic(g) => faer_failure(g),
    };
    Error::Numerical {
        what: format!("{matrix}: {why}"),
    }
}

/// faer's non-numerical failures in words (a symbolic analysis fails with these alone).
pub(crate) fn faer_failure(e: &faer::sparse::FaerError) -> String {
    match e {
        faer::sparse::FaerError::IndexOverflow => {
            "the matrix has more entries than its index type can count".to_string()
        }
        faer::sparse::FaerError::OutOfMemory => "memory ran out".to_string(),
        _ => "the sparse matrix library failed".to_string(),
    }
}

/// Shorthand used across the crate.
pub type Result<T> = std::result::Result<T, Error>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factorisation_failures_are_sentences() {
        use faer::linalg::cholesky::llt::factor::LltError as Dense;
        use faer::sparse::linalg::LltError;
        let pivot = LltError::Numeric(Dense::NonPositivePivot { index: 1 });
        let text = factorisation_failure("shape system", &pivot).to_string();
        assert_eq!(
            text,
            "numerical failure: shape system: the Cholesky factorisation met a non-positive \
             pivot at row 1: the matrix is not positive definite"
        );
        let memory = LltError::Generic(faer::sparse::FaerError::OutOfMemory);
        let text = factorisation_failure("shape system", &memory).to_string();
        assert_eq!(text, "numerical failure: shape system: memory ran out");
    }
}
