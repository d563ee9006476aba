//! Wavefront OBJ through `tobj` (file vertex order kept); polygons are
//! triangulated by `polygon`, not by `tobj`, whose fan crosses the outline
//! of a concave face.

use std::io::Cursor;

use super::polygon::Triangulator;
use crate::{TetraError, TriSurface};

/// Parses OBJ bytes; each object/group becomes a part.
pub(super) fn parse(bytes: &[u8]) -> Result<TriSurface, TetraError> {
    let options = tobj::LoadOptions { triangulate: false, single_index: false, ..Default::default() };
    let (models, _) =
        tobj::load_obj_buf(&mut Cursor::new(bytes), &options, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| TetraError::Parse { format: "OBJ", message: e.to_string() })?;
    let mut surface = TriSurface::default();
    let mut triangulator = Triangulator::new();
    let mut face = Vec::new();
    for (m, model) in models.iter().enumerate() {
        let mesh = &model.mesh;
        let offset = surface.vertices.len();
        let first = surface.triangles.len();
        surface.vertices.extend(mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        let count = mesh.positions.len() / 3;
        // `face_arities` is empty when every face is a triangle.
        let arities = (!mesh.face_arities.is_empty()).then_some(&mesh.face_arities);
        let faces = arities.map_or(mesh.indices.len() / 3, |a| a.len());
        let mut next = 0;
        for f in 0..faces {
            let arity = arities.map_or(3, |a| a[f] as usize);
            let ids = mesh.indices.get(next..next + arity).ok_or(TetraError::Parse {
                format: "OBJ",
                message: format!("face {f} of part {m} names corners past the end of its index list"),
            })?;
            next += arity;
            if arity < 3 {
                continue;
            }
            face.clear();
            for &v in ids {
                let v = v as usize;
                if v >= count {
                    return Err(TetraError::IndexOutOfRange {
                        triangle: surface.triangles.len(),
                        vertex: v,
                        count,
                    });
                }
                face.push(v + offset);
            }
            triangulator.push(&surface.vertices, &face, &mut surface.triangles);
        }
        let name = if model.name.is_empty() { format!("part{m}") } else { model.name.clone() };
        surface.parts.push((name, first..surface.triangles.len()));
    }
    Ok(surface)
}
