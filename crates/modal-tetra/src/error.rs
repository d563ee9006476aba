//! Typed errors of the surface readers and the tetrahedralizer.

use std::path::PathBuf;

/// Everything that can go wrong between a surface file and a tet mesh.
/// Each message is one line naming the offending file, item or option.
#[derive(Debug, thiserror::Error)]
pub enum TetraError {
    /// The file could not be opened or read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// File that failed.
        path: PathBuf,
        /// Underlying I/O error.
        source: std::io::Error,
    },
    /// The extension is not one of obj, stl, ply, off, glb, gltf.
    #[error("{path}: unsupported surface format (expected .obj, .stl, .ply, .off, .glb or .gltf)")]
    UnsupportedFormat {
        /// File with the unknown extension.
        path: PathBuf,
    },
    /// The third-party parser rejected the file (garbage, truncated, ...).
    #[error("{format} parse error: {message}")]
    Parse {
        /// "OBJ", "STL", "PLY", "OFF" or "glTF".
        format: &'static str,
        /// Parser message.
        message: String,
    },
    /// A coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFiniteVertex {
        /// Offending vertex index (0-based, file order).
        vertex: usize,
    },
    /// A triangle references a vertex that does not exist.
    #[error("triangle {triangle} references vertex {vertex}, but there are only {count} vertices")]
    IndexOutOfRange {
        /// Offending triangle (0-based).
        triangle: usize,
        /// Referenced vertex.
        vertex: usize,
        /// Number of vertices.
        count: usize,
    },
    /// A PLY face is not a polygon with at least three corners.
    #[error("face {face} has {corners} corners (need at least 3)")]
    BadFace {
        /// Offending face (0-based).
        face: usize,
        /// Its corner count.
        corners: usize,
    },
    /// The file (or the chosen part) holds no triangle.
    #[error("the surface has no triangles")]
    Empty,
    /// `part` names an object the file does not contain.
    #[error("no part named {requested:?}; the file has: {available}")]
    UnknownPart {
        /// Requested name.
        requested: String,
        /// Comma-separated list of the names present.
        available: String,
    },
    /// A bad option value (scale, cell size, ...).
    #[error("invalid option {name}: {reason}")]
    InvalidOption {
        /// Option name, e.g. `scale` or `cell`.
        name: &'static str,
        /// Why it was rejected.
        reason: String,
    },
    /// The requested resolution would exceed `TetOptions::max_tets`.
    #[error(
        "cell size {cell_m:.3e} m would make about {estimated} tets, above the limit of {limit}: give --cell {:.2e} or \
         larger (cells much wider than a thin wall lose parts of it; the warnings say where)",
        cell_within(*cell_m, *estimated, *limit)
    )]
    TooManyTets {
        /// Cell size that was asked for or derived (m).
        cell_m: f64,
        /// Estimated number of tets.
        estimated: u64,
        /// The configured limit.
        limit: usize,
    },
    /// The repair left out every triangle (all of zero area, or all of
    /// double-sided open sheets).
    #[error("no triangle is left to mesh: {reason}")]
    NothingLeft {
        /// Why, and what to do.
        reason: String,
    },
    /// The surface encloses no volume at the chosen resolution.
    #[error("no tets at cell size {cell_m:.3e} m: {hint}")]
    NoVolume {
        /// Cell size used (m).
        cell_m: f64,
        /// What to do: a cell that works, or why none will.
        hint: String,
    },
}

/// The cell size [m] at which a resolution estimated at `estimated` tets
/// with cell `cell_m` would hold about `limit`: the count goes as `cell⁻³`
/// (a lattice of cubes, 12 tets each), plus 1 % for the lattice's rounding.
fn cell_within(cell_m: f64, estimated: u64, limit: usize) -> f64 {
    cell_m * (estimated as f64 / limit.max(1) as f64).cbrt() * 1.01
}
