//! PLY (ASCII or binary) through `ply-rs-bw`: element `vertex` with x, y, z
//! and element `face` with a `vertex_indices` (or `vertex_index`) list;
//! polygons are triangulated by `polygon`.

use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use super::polygon::Triangulator;
use crate::{TetraError, TriSurface};

fn parse_err(message: impl Into<String>) -> TetraError {
    TetraError::Parse { format: "PLY", message: message.into() }
}

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => v.into(),
        Property::UChar(v) => v.into(),
        Property::Short(v) => v.into(),
        Property::UShort(v) => v.into(),
        Property::Int(v) => v.into(),
        Property::UInt(v) => v.into(),
        Property::Float(v) => v.into(),
        Property::Double(v) => v,
        _ => return None,
    })
}

fn index_list(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListShort(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListInt(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x.into()).collect(),
        _ => return None,
    })
}

/// Parses PLY bytes into one part named "ply".
pub(super) fn parse(bytes: &[u8]) -> Result<TriSurface, TetraError> {
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut std::io::Cursor::new(bytes))
        .map_err(|e| parse_err(e.to_string()))?;
    let vertices = ply.payload.get("vertex").ok_or_else(|| parse_err("no `vertex` element"))?;
    let mut surface = TriSurface::default();
    for (i, v) in vertices.iter().enumerate() {
        let coord = |k: &str| {
            v.get(k).and_then(scalar).ok_or_else(|| parse_err(format!("vertex {i} has no numeric `{k}`")))
        };
        surface.vertices.push([coord("x")?, coord("y")?, coord("z")?]);
    }
    let faces = ply.payload.get("face").ok_or_else(|| parse_err("no `face` element"))?;
    let count = surface.vertices.len();
    let mut triangulator = Triangulator::new();
    for (f, face) in faces.iter().enumerate() {
        let list = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .and_then(index_list)
            .ok_or_else(|| parse_err(format!("face {f} has no `vertex_indices` list")))?;
        if list.len() < 3 {
            return Err(TetraError::BadFace { face: f, corners: list.len() });
        }
        let mut idx = Vec::with_capacity(list.len());
        for &v in &list {
            match usize::try_from(v) {
                Ok(u) if u < count => idx.push(u),
                _ => {
                    let vertex = usize::try_from(v).unwrap_or(usize::MAX);
                    return Err(TetraError::IndexOutOfRange { triangle: f, vertex, count });
                }
            }
        }
        triangulator.push(&surface.vertices, &idx, &mut surface.triangles);
    }
    surface.parts.push(("ply".to_string(), 0..surface.triangles.len()));
    Ok(surface)
}
