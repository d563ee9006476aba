//! Polygons to triangles, for the readers whose faces may have more than
//! three corners (OBJ, PLY, OFF).
//!
//! A fan from the first corner is kept where it is a triangulation: every
//! fan triangle turns the way the polygon does (its area vector has a
//! non-negative component along Newell's normal `n = ½ Σ pᵢ × pᵢ₊₁`), so the
//! polygon is star-shaped about that corner, as every convex polygon is.
//! Files of convex faces therefore read as they always did. Any other
//! polygon is projected on the plane normal to `n` and ear-clipped by
//! `earcut`; its triangles are turned to face along `n`.
//!
//! Why not the fan everywhere: on a planar polygon the fan's triangles sum
//! to the polygon's winding number even where they cross its outline, so the
//! enclosed solid is right, but they are not its surface. A concave face (an
//! L-shaped cap written as one hexagon, as Blender's OBJ export writes
//! n-gons) put triangles outside the object that the mesh then followed.

use earcut::Earcut;

use crate::geom::{area_vector, cross, dot, V3};

/// Reusable buffers for triangulating one polygon after another.
pub(super) struct Triangulator {
    earcut: Earcut<f64>,
    corners: Vec<[f64; 3]>,
    projected: Vec<[f64; 2]>,
    local: Vec<usize>,
}

impl Triangulator {
    pub(super) fn new() -> Self {
        Self { earcut: Earcut::new(), corners: Vec::new(), projected: Vec::new(), local: Vec::new() }
    }

    /// Appends the triangles of the polygon with corners `ids` (indices into
    /// `vertices`, at least three) to `triangles`.
    pub(super) fn push(&mut self, vertices: &[V3], ids: &[usize], triangles: &mut Vec<[usize; 3]>) {
        debug_assert!(ids.len() >= 3);
        if ids.len() > 3 {
            let normal = newell(vertices, ids);
            let tolerance = -1e-12 * dot(normal, normal);
            let fan_turns_along = (1..ids.len() - 1)
                .all(|k| dot(area_of(vertices, [ids[0], ids[k], ids[k + 1]]), normal) >= tolerance);
            if !fan_turns_along && self.ear_clip(vertices, ids, normal, triangles) {
                return;
            }
        }
        triangles.extend((1..ids.len() - 1).map(|k| [ids[0], ids[k], ids[k + 1]]));
    }

    /// Ear-clips the polygon in its plane; false (nothing appended) when
    /// `earcut` cannot give all `n − 2` triangles (a self-crossing outline).
    fn ear_clip(
        &mut self,
        vertices: &[V3],
        ids: &[usize],
        normal: V3,
        triangles: &mut Vec<[usize; 3]>,
    ) -> bool {
        self.corners.clear();
        self.corners.extend(ids.iter().map(|&v| vertices[v]));
        if !earcut::utils3d::project3d_to_2d(&self.corners, ids.len(), &mut self.projected) {
            return false;
        }
        self.earcut.earcut(self.projected.iter().copied(), &[], &mut self.local);
        if self.local.len() != 3 * (ids.len() - 2) {
            return false;
        }
        triangles.extend(self.local.chunks_exact(3).map(|t| {
            let tri = [ids[t[0]], ids[t[1]], ids[t[2]]];
            if dot(area_of(vertices, tri), normal) < 0.0 {
                [tri[0], tri[2], tri[1]]
            } else {
                tri
            }
        }));
        true
    }
}

/// Newell's normal of a polygon: twice its vector area, exact for planar
/// polygons and a least-squares plane normal for warped ones.
fn newell(vertices: &[V3], ids: &[usize]) -> V3 {
    let mut n = [0.0; 3];
    for (k, &a) in ids.iter().enumerate() {
        let c = cross(vertices[a], vertices[ids[(k + 1) % ids.len()]]);
        (0..3).for_each(|i| n[i] += c[i]);
    }
    n
}

/// A triangle's vector area, by corner indices.
fn area_of(vertices: &[V3], [a, b, c]: [usize; 3]) -> V3 {
    area_vector(vertices[a], vertices[b], vertices[c])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::sub;

    fn triangulate(vertices: &[V3], ids: &[usize]) -> Vec<[usize; 3]> {
        let mut out = Vec::new();
        Triangulator::new().push(vertices, ids, &mut out);
        out
    }

    fn area(vertices: &[V3], triangles: &[[usize; 3]], normal: V3) -> f64 {
        triangles.iter().map(|&t| dot(area_of(vertices, t), normal)).sum()
    }

    /// An orthonormal pair spanning a plane out of every coordinate plane.
    const U: V3 = [0.6, 0.8, 0.0];
    const V: V3 = [-0.48, 0.36, 0.8];

    /// A point of that plane, shifted off the origin.
    fn on_plane(x: f64, y: f64) -> V3 {
        std::array::from_fn(|c| 1.0 + x * U[c] + y * V[c])
    }

    /// The L of the module doc, 10 cm × 8 cm with arms 3 cm wide, tilted.
    fn tilted_l() -> Vec<V3> {
        let l = [[0.0, 0.0], [0.1, 0.0], [0.1, 0.03], [0.03, 0.03], [0.03, 0.08], [0.0, 0.08]];
        l.iter().map(|&[x, y]| on_plane(x, y)).collect()
    }

    #[test]
    fn a_convex_polygon_keeps_its_fan() {
        let square = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(triangulate(&square, &[0, 1, 2, 3]), vec![[0, 1, 2], [0, 2, 3]]);
        // Collinear corners (a T-junction on an edge) do not break the fan.
        let t = [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]];
        assert_eq!(triangulate(&t, &[0, 1, 2, 3]), vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn a_concave_polygon_is_ear_clipped_inside_its_outline() {
        let l = tilted_l();
        // Fanned from corner 1, triangle (1, 3, 4) covers the notch.
        let ids = [1, 2, 3, 4, 5, 0];
        let normal = newell(&l, &ids);
        let unit = normal.map(|c| c / dot(normal, normal).sqrt());
        let triangles = triangulate(&l, &ids);
        assert_eq!(triangles.len(), 4);
        let expected = 0.1 * 0.03 + 0.03 * 0.05;
        for &t in &triangles {
            let a = dot(area_of(&l, t), unit);
            assert!(a > 0.0, "{t:?} faces along the polygon");
        }
        assert!((area(&l, &triangles, unit) - expected).abs() < 1e-14);
        // The notch's centre is inside no triangle.
        let notch = on_plane(0.06, 0.05);
        for t in &triangles {
            let inside = (0..3).all(|k| {
                let (a, b) = (l[t[k]], l[t[(k + 1) % 3]]);
                dot(cross(sub(b, a), sub(notch, a)), unit) > 0.0
            });
            assert!(!inside, "{t:?} covers the notch");
        }
    }

    #[test]
    fn a_self_crossing_polygon_still_gives_its_triangles() {
        // A bow tie: no triangulation exists; earcut's or the fan's two triangles.
        let bow = [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(triangulate(&bow, &[0, 1, 2, 3]).len(), 2);
    }
}
