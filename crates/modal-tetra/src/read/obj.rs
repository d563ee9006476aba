//! Wavefront OBJ through `tobj` (polygons triangulated, file vertex order kept).

use std::io::Cursor;

use crate::{TetraError, TriSurface};

/// Parses OBJ bytes; each object/group becomes a part.
pub(super) fn parse(bytes: &[u8]) -> Result<TriSurface, TetraError> {
    let options = tobj::LoadOptions { triangulate: true, single_index: false, ..Default::default() };
    let (models, _) =
        tobj::load_obj_buf(&mut Cursor::new(bytes), &options, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| TetraError::Parse { format: "OBJ", message: e.to_string() })?;
    let mut surface = TriSurface::default();
    for (m, model) in models.iter().enumerate() {
        let mesh = &model.mesh;
        let offset = surface.vertices.len();
        let first = surface.triangles.len();
        surface.vertices.extend(mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        let count = mesh.positions.len() / 3;
        for (t, tri) in mesh.indices.chunks_exact(3).enumerate() {
            let idx = [tri[0] as usize, tri[1] as usize, tri[2] as usize];
            if let Some(&v) = idx.iter().find(|&&v| v >= count) {
                return Err(TetraError::IndexOutOfRange { triangle: first + t, vertex: v, count });
            }
            surface.triangles.push(idx.map(|v| v + offset));
        }
        let name = if model.name.is_empty() { format!("part{m}") } else { model.name.clone() };
        surface.parts.push((name, first..surface.triangles.len()));
    }
    Ok(surface)
}
