//! Surface readers: Wavefront OBJ (tobj), STL ASCII/binary (stl_io), PLY
//! ASCII/binary (ply-rs-bw), OFF (ASCII, read here: see [`off`]) and glTF
//! 2.0 (gltf: the meshes a scene places), all into a [`TriSurface`] in
//! metres.
//!
//! Coordinates are taken as metres and never rescaled silently; `scale`
//! multiplies them. Third-party parsers run under `catch_unwind` as a last
//! resort so that a parser bug on hostile bytes becomes a
//! [`TetraError::Parse`] instead of a panic in the caller.

mod gltf_file;
mod obj;
mod off;
mod ply;
mod polygon;
mod stl;
mod uri;

pub use gltf_file::{gltf_buffers, gltf_uri_buffers};

use std::path::Path;

use crate::{diagnose, SurfaceReport, TetraError, TriSurface};

/// Supported surface file formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceFormat {
    /// Wavefront OBJ (polygons are triangulated; objects become parts).
    Obj,
    /// STL, ASCII or binary.
    Stl,
    /// Stanford PLY, ASCII or binary (`vertex` x/y/z, `face` vertex_indices).
    Ply,
    /// Geomview OFF, ASCII (ModelNet's and the Princeton Shape Benchmark's
    /// format; polygons are triangulated).
    Off,
    /// glTF 2.0, `.glb` or `.gltf` (the triangles of every mesh the default
    /// scene places, in world coordinates; each placed mesh is a part).
    Gltf,
}

impl SurfaceFormat {
    /// Format from a file extension (case-insensitive), if supported.
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Self::Obj),
            "stl" => Some(Self::Stl),
            "ply" => Some(Self::Ply),
            "off" => Some(Self::Off),
            "glb" | "gltf" => Some(Self::Gltf),
            _ => None,
        }
    }
}

/// Reads a surface file, multiplies coordinates by `scale`, keeps only the
/// part named `part` if given, and diagnoses it.
///
/// Several objects in one file are kept together (one body) unless `part`
/// picks one; an unknown part name is an error listing the names present.
pub fn read_surface(
    path: impl AsRef<Path>,
    scale: f64,
    part: Option<&str>,
) -> Result<(TriSurface, SurfaceReport), TetraError> {
    let path = path.as_ref();
    let format = SurfaceFormat::from_path(path)
        .ok_or_else(|| TetraError::UnsupportedFormat { path: path.to_path_buf() })?;
    let bytes = std::fs::read(path).map_err(|source| TetraError::Io { path: path.to_path_buf(), source })?;
    parse_surface_beside(&bytes, format, scale, part, path.parent())
}

/// Like [`read_surface`] but from bytes already in memory (a `.gltf` whose
/// buffers are files cannot be read this way: give the path, or a `.glb`).
pub fn parse_surface(
    bytes: &[u8],
    format: SurfaceFormat,
    scale: f64,
    part: Option<&str>,
) -> Result<(TriSurface, SurfaceReport), TetraError> {
    parse_surface_beside(bytes, format, scale, part, None)
}

/// [`parse_surface`] with a `.gltf`'s buffer files looked up in `folder`.
fn parse_surface_beside(
    bytes: &[u8],
    format: SurfaceFormat,
    scale: f64,
    part: Option<&str>,
    folder: Option<&Path>,
) -> Result<(TriSurface, SurfaceReport), TetraError> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(TetraError::InvalidOption {
            name: "scale",
            reason: format!("{scale} is not a positive finite number"),
        });
    }
    let mut surface = guarded(format_name(format), || match format {
        SurfaceFormat::Obj => obj::parse(bytes),
        SurfaceFormat::Stl => stl::parse(bytes),
        SurfaceFormat::Ply => ply::parse(bytes),
        SurfaceFormat::Off => off::parse(bytes),
        SurfaceFormat::Gltf => gltf_file::parse(bytes, folder),
    })?;
    surface.validate()?;
    if let Some(name) = part {
        surface.select_part(name)?;
    }
    surface.scale(scale);
    surface.validate()?;
    let report = diagnose(&surface);
    Ok((surface, report))
}

fn format_name(format: SurfaceFormat) -> &'static str {
    match format {
        SurfaceFormat::Obj => "OBJ",
        SurfaceFormat::Stl => "STL",
        SurfaceFormat::Ply => "PLY",
        SurfaceFormat::Off => "OFF",
        SurfaceFormat::Gltf => "glTF",
    }
}

/// Runs a parser, turning a panic inside a third-party crate into an error.
fn guarded(
    format: &'static str,
    f: impl FnOnce() -> Result<TriSurface, TetraError>,
) -> Result<TriSurface, TetraError> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|_| {
        Err(TetraError::Parse { format, message: "the parser failed on malformed input".into() })
    })
}
