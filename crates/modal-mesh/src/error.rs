//! The crate's error type: one clear line naming the offending file
//! position, element or node.

use std::fmt;

/// Where in an input file a problem was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Location {
    /// 1-based line of a text file (or of the text part of a binary file).
    Line(usize),
    /// 0-based byte offset inside binary data.
    Byte(usize),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(l) => write!(f, "line {l}"),
            Location::Byte(b) => write!(f, "byte {b}"),
        }
    }
}

/// Everything that can go wrong reading, checking or generating a mesh.
///
/// Element and node numbers in messages are 0-based indices into the mesh
/// (`TetMesh::cells` / `TetMesh::nodes`) unless the message says "tag"
/// (the number written in the file).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// The file could not be opened, read or written.
    #[error("{path}: {message}")]
    Io {
        /// File path as given.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// A problem inside a named file (wraps the other variants).
    #[error("{path}: {source}")]
    InFile {
        /// File path as given.
        path: String,
        /// What went wrong.
        source: Box<MeshError>,
    },
    /// The file extension does not name a supported format.
    #[error("unknown mesh format `{extension}` (expected .msh, .node/.ele or .mesh)")]
    UnknownFormat {
        /// The extension found (may be empty).
        extension: String,
    },
    /// Malformed, truncated or unsupported file content.
    #[error("{at}: {message}")]
    Syntax {
        /// Where the problem was found.
        at: Location,
        /// What was expected or found.
        message: String,
    },
    /// The file holds no 4-node or 10-node tetrahedra.
    #[error("mesh has no tetrahedra (only 4-node and 10-node tets are read)")]
    NoTets,
    /// The file mixes 4-node and 10-node tets.
    #[error("mesh mixes 4-node and 10-node tets; convert it to a single order first")]
    MixedOrders,
    /// A node coordinate is NaN or infinite.
    #[error("node {node} has a non-finite coordinate {coordinate:?}")]
    NonFiniteCoordinate {
        /// Node index.
        node: usize,
        /// Its coordinates.
        coordinate: [f64; 3],
    },
    /// An element references a node index past the end of the node list.
    #[error("element {element} references node {node}, but the mesh has only {node_count} nodes")]
    NodeOutOfRange {
        /// Element index.
        element: usize,
        /// The bad node index.
        node: usize,
        /// Number of nodes in the mesh.
        node_count: usize,
    },
    /// An element uses the same node twice.
    #[error("element {element} uses node {node} twice")]
    RepeatedNode {
        /// Element index.
        element: usize,
        /// The repeated node.
        node: usize,
    },
    /// Two elements have the same corner nodes.
    #[error("element {element} has the same corners as element {first}")]
    DuplicateTet {
        /// The later element.
        element: usize,
        /// The earlier element with the same corners.
        first: usize,
    },
    /// Two tets sharing a face lie on the same side of it: the mesh is folded
    /// (an inverted element inside a good mesh, not a vertex-order convention).
    #[error(
        "elements {first} and {element} overlap: they lie on the same side of their shared face \
         (a folded or tangled mesh; untangle or remesh it)"
    )]
    FoldedTets {
        /// The later element.
        element: usize,
        /// The earlier element sharing the face.
        first: usize,
    },
    /// Three or more tets share one face.
    #[error("elements {first}, {second} and {element} share one face: overlapping elements")]
    OverlappingTets {
        /// The third element found on the face.
        element: usize,
        /// The first element on the face.
        first: usize,
        /// The second element on the face.
        second: usize,
    },
    /// A tet has (nearly) zero volume.
    #[error(
        "element {element} is degenerate: volume {volume:e} m^3 is below {tolerance:e} m^3 \
         (1e-10 x its longest edge cubed)"
    )]
    DegenerateTet {
        /// Element index.
        element: usize,
        /// Its signed volume (m³).
        volume: f64,
        /// The threshold it fell below (m³).
        tolerance: f64,
    },
    /// A 10-node tet is inverted somewhere inside (curved too much).
    #[error(
        "10-node element {element} has a non-positive Jacobian determinant at reference point \
         {point:?} (det J = {det:e})"
    )]
    InvertedTet10 {
        /// Element index.
        element: usize,
        /// Reference coordinates (ξ, η, ζ) of the failing sample point.
        point: [f64; 3],
        /// The Jacobian determinant there.
        det: f64,
    },
    /// A generator or reader parameter is out of range.
    #[error("invalid parameter `{name}`: {message}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Why it is rejected.
        message: String,
    },
    /// A generated mesh would be absurdly large.
    #[error(
        "the requested mesh would have {} tets, more than the limit {limit}, even at the default size if none \
         was given; give a larger element size (`--h`, or `element_size` in a scene)",
        if *count == u64::MAX { "more than 1.8e19".to_string() } else { format!("{:.3e}", *count as f64) }
    )]
    TooManyElements {
        /// Requested tet count.
        count: u64,
        /// The cap.
        limit: u64,
    },
}

impl MeshError {
    /// Wraps the error with the path of the file it came from.
    pub fn in_file(self, path: &std::path::Path) -> MeshError {
        MeshError::InFile { path: path.display().to_string(), source: Box::new(self) }
    }
}
