//! The crate's error type: data errors naming the offending element, node or value.

use crate::MaterialError;

/// An FEM input that cannot be processed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum FemError {
    /// The material is physically impossible.
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// The Jacobian determinant of an element is ≤ 0 (or not finite) at a
    /// quadrature point: the tet is inverted, degenerate or too curved.
    #[error("element {element}: Jacobian determinant {det:e} <= 0 at a quadrature point (inverted, degenerate or over-curved tet)")]
    NonPositiveJacobian {
        /// Element index in the mesh.
        element: usize,
        /// The offending determinant (6 × signed volume scale).
        det: f64,
    },
    /// An element refers to a node that does not exist.
    #[error("element {element}: node index {node} out of range (mesh has {node_count} nodes)")]
    NodeOutOfRange {
        /// Element index.
        element: usize,
        /// The bad node index.
        node: usize,
        /// Number of nodes in the mesh.
        node_count: usize,
    },
    /// The mesh has no elements.
    #[error("mesh has no tetrahedra")]
    EmptyMesh,
    /// Element order other than 1 or 2 requested.
    #[error("unsupported element order {0} (use 1 for 4-node or 2 for 10-node tets)")]
    UnsupportedOrder(u8),
    /// A per-DOF array of the wrong length.
    #[error("{what}: length {got} does not match the {expected} degrees of freedom")]
    DofCountMismatch {
        /// Which argument.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// A node-indexed array or part index that does not fit the mesh.
    #[error("{0}")]
    InvalidArgument(String),
    /// The assembled matrices alone would not fit the memory limit.
    #[error(
        "the mesh has {dofs} DOF: its stiffness and mass matrices alone would need ≈ {:.1} GB, above the memory \
         limit of {:.1} GB; use a coarser mesh (a larger element size or --cell) or --order 1",
        *needed_bytes as f64 / 1e9,
        *limit_bytes as f64 / 1e9
    )]
    TooLarge {
        /// Degrees of freedom.
        dofs: usize,
        /// Bytes K, M and their pattern would hold.
        needed_bytes: u64,
        /// The limit [bytes].
        limit_bytes: u64,
    },
}
