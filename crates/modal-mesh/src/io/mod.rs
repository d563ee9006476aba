//! Mesh files in and out.
//!
//! Readers: Gmsh `.msh` (4.1 ASCII/binary, 2.2 ASCII/binary), TetGen
//! `.node`/`.ele`, Medit `.mesh`. All return a raw [`TetMesh`] whose
//! coordinates are the file's numbers times the caller's `scale` (files are
//! taken to be in metres; pass 1e-3 for millimetres). Readers check syntax,
//! counts and finiteness; run [`crate::check`] for the geometric checks.
//!
//! Hostile input never panics or allocates more than the file could hold:
//! every count read from a file is checked against the bytes left.

mod cursor;
mod medit;
mod msh;
mod tetgen;
mod write;

use std::path::{Path, PathBuf};

pub use medit::read_medit;
pub use msh::read_msh;
pub use tetgen::read_tetgen;
pub use write::{bounding_box, write_msh41, write_msh41_file};

use crate::{MeshError, TetMesh};

/// Reads a mesh file, choosing the format from the extension: `.msh`
/// (Gmsh, ASCII or binary detected from its header), `.node` or `.ele`
/// (TetGen; the other file of the pair is found next to it), `.mesh`
/// (Medit). Coordinates are multiplied by `scale` (must be finite and > 0).
/// Errors name the file.
pub fn read_mesh(path: &Path, scale: f64) -> Result<TetMesh, MeshError> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(MeshError::InvalidParameter {
            name: "scale",
            message: format!("{scale} is not a finite positive number"),
        });
    }
    let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    match extension.as_str() {
        "msh" => read_msh(&read_file(path)?, scale).map_err(|e| e.in_file(path)),
        "mesh" => read_medit(&read_file(path)?, scale).map_err(|e| e.in_file(path)),
        "node" | "ele" => {
            let (node, ele) = (path.with_extension("node"), path.with_extension("ele"));
            let node_data = read_file(&node)?;
            let ele_data = read_file(&ele)?;
            read_tetgen(&node_data, &ele_data, scale).map_err(|e| e.in_file(&tetgen_pair_name(&ele)))
        }
        _ => Err(MeshError::UnknownFormat { extension }.in_file(path)),
    }
}

/// `x.ele` → `x.node/.ele`, for messages about a TetGen pair.
fn tetgen_pair_name(ele: &Path) -> PathBuf {
    ele.with_extension("node/.ele")
}

fn read_file(path: &Path) -> Result<Vec<u8>, MeshError> {
    std::fs::read(path)
        .map_err(|e| MeshError::Io { path: path.display().to_string(), message: e.to_string() })
}
