//! The triangle surface read from a file, before any repair.

use std::io::Write;
use std::ops::Range;

use crate::TetraError;

/// A triangle soup with optional named parts, coordinates in metres.
///
/// Nothing is repaired here: duplicate vertices, flipped or degenerate
/// triangles and holes are kept as read and reported by
/// [`crate::diagnose`]; the inside test copes with them.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct TriSurface {
    /// Vertex positions (m).
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as vertex indices, counter-clockwise seen from outside when
    /// the file is well oriented.
    pub triangles: Vec<[usize; 3]>,
    /// Named parts (OBJ objects/groups): name and range of `triangles`.
    pub parts: Vec<(String, Range<usize>)>,
}

impl TriSurface {
    /// Axis-aligned bounding box `(min, max)` of the referenced vertices (m).
    /// `None` when there are no triangles.
    pub fn bounding_box(&self) -> Option<([f64; 3], [f64; 3])> {
        let corners = self.triangles.iter().flatten().map(|&v| self.vertices[v]);
        (!self.triangles.is_empty()).then(|| crate::geom::bounds(corners))
    }

    /// Length of the bounding-box diagonal (m) (0 when empty).
    pub fn diagonal(&self) -> f64 {
        self.bounding_box().map(|(lo, hi)| crate::geom::norm(crate::geom::sub(hi, lo))).unwrap_or(0.0)
    }

    /// Checks that every coordinate is finite and every index in range.
    pub fn validate(&self) -> Result<(), TetraError> {
        if let Some(v) = self.vertices.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(TetraError::NonFiniteVertex { vertex: v });
        }
        let count = self.vertices.len();
        for (t, tri) in self.triangles.iter().enumerate() {
            if let Some(&v) = tri.iter().find(|&&v| v >= count) {
                return Err(TetraError::IndexOutOfRange { triangle: t, vertex: v, count });
            }
        }
        if self.triangles.is_empty() {
            return Err(TetraError::Empty);
        }
        Ok(())
    }

    /// Keeps only the triangles of the part called `name` (vertices are
    /// kept as they are; unused ones do no harm).
    pub fn select_part(&mut self, name: &str) -> Result<(), TetraError> {
        let Some((n, range)) = self.parts.iter().find(|(n, _)| n == name).cloned() else {
            let available = if self.parts.is_empty() {
                "(no named parts)".to_string()
            } else {
                self.parts.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>().join(", ")
            };
            return Err(TetraError::UnknownPart { requested: name.to_string(), available });
        };
        self.triangles = self.triangles[range.clone()].to_vec();
        self.parts = vec![(n, 0..range.len())];
        Ok(())
    }

    /// Multiplies every coordinate by `scale`.
    pub fn scale(&mut self, scale: f64) {
        for p in &mut self.vertices {
            for c in p.iter_mut() {
                *c *= scale;
            }
        }
    }
}

/// Writes `surface` as Wavefront OBJ (`o` per part, 1-based `f` lines).
pub fn write_obj(surface: &TriSurface, mut out: impl Write) -> std::io::Result<()> {
    writeln!(out, "# written by modal-tetra; units: metres")?;
    for p in &surface.vertices {
        writeln!(out, "v {} {} {}", p[0], p[1], p[2])?;
    }
    let parts = if surface.parts.is_empty() {
        vec![("body".to_string(), 0..surface.triangles.len())]
    } else {
        surface.parts.clone()
    };
    for (name, range) in parts {
        writeln!(out, "o {name}")?;
        let triangles = surface.triangles.get(range.clone()).ok_or_else(|| {
            let n = surface.triangles.len();
            std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("part '{name}' spans triangles {range:?} but the surface has {n}"),
            )
        })?;
        for t in triangles {
            writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
        }
    }
    Ok(())
}
