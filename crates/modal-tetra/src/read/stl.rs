//! STL (ASCII or binary) through `stl_io`, triangles read one at a time so a
//! lying triangle count in a binary header allocates nothing.

use std::collections::HashMap;
use std::io::Cursor;

use crate::{TetraError, TriSurface};

/// Parses STL bytes; vertices with bit-identical coordinates are shared.
pub(super) fn parse(bytes: &[u8]) -> Result<TriSurface, TetraError> {
    let err = |e: std::io::Error| TetraError::Parse { format: "STL", message: e.to_string() };
    let mut cursor = Cursor::new(bytes);
    let reader = stl_io::create_stl_reader(&mut cursor).map_err(err)?;
    let mut surface = TriSurface::default();
    let mut index: HashMap<[u32; 3], usize> = HashMap::new();
    for tri in reader {
        let tri = tri.map_err(err)?;
        let ids = tri.vertices.map(|v| {
            let key = v.0.map(|c| (c + 0.0).to_bits());
            *index.entry(key).or_insert_with(|| {
                surface.vertices.push(v.0.map(f64::from));
                surface.vertices.len() - 1
            })
        });
        surface.triangles.push(ids);
    }
    surface.parts.push(("solid".to_string(), 0..surface.triangles.len()));
    Ok(surface)
}
