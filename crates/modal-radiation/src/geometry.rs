//! The boundary mesh the solver sees: flat triangular panels with outward
//! normals, and the inside test for field points.
//!
//! A quadratic (6-node) surface triangle is split into four flat panels
//! through its mid-edge nodes, so every panel corner lies on the curved
//! surface. The inside test sums the signed solid angles of all panels
//! (Van Oosterom–Strackee, `tan(Ω/2) = a·(b×c) / (abc + (a·b)c + (b·c)a +
//! (c·a)b)`): `Ω = 4π` inside a closed outward-oriented surface, `0`
//! outside.

use crate::error::RadiationError;

/// One flat triangular panel.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Corner indices into [`BoundaryMesh::vertices`], counter-clockwise
    /// seen from outside.
    pub corners: [usize; 3],
    /// Centroid (the collocation point) [m].
    pub centroid: [f64; 3],
    /// Unit outward normal.
    pub normal: [f64; 3],
    /// Area [m²].
    pub area: f64,
    /// Longest edge [m].
    pub diameter: f64,
}

/// Flat-panel boundary of one or more closed bodies.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundaryMesh {
    /// Panel corner positions [m].
    pub vertices: Vec<[f64; 3]>,
    /// The panels.
    pub panels: Vec<Panel>,
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

impl BoundaryMesh {
    /// Panels from corner triangles (outward, counter-clockwise). Errors on
    /// an empty mesh, an out-of-range index, a non-finite position or a
    /// degenerate (zero-area) triangle.
    pub fn new(vertices: Vec<[f64; 3]>, triangles: &[[usize; 3]]) -> Result<Self, RadiationError> {
        if triangles.is_empty() {
            return Err(RadiationError::EmptySurface);
        }
        if let Some(i) = vertices.iter().position(|v| v.iter().any(|c| !c.is_finite())) {
            return Err(RadiationError::NonFinitePosition { vertex: i });
        }
        let mut panels = Vec::with_capacity(triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            if tri.iter().any(|&i| i >= vertices.len()) {
                return Err(RadiationError::BadTriangle { triangle: t });
            }
            let [a, b, c] = tri.map(|i| vertices[i]);
            let n = cross(sub(b, a), sub(c, a));
            let twice_area = norm(n);
            let diameter = norm(sub(b, a)).max(norm(sub(c, b))).max(norm(sub(a, c)));
            if twice_area <= 1e-14 * diameter * diameter || twice_area == 0.0 {
                return Err(RadiationError::DegenerateTriangle { triangle: t });
            }
            panels.push(Panel {
                corners: *tri,
                centroid: [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0),
                normal: n.map(|x| x / twice_area),
                area: 0.5 * twice_area,
                diameter,
            });
        }
        Ok(BoundaryMesh { vertices, panels })
    }

    /// Panels from 6-node triangles: corners `triangles[t]` and mid-edge
    /// nodes `edge_nodes[t]` of edges (0,1), (1,2), (2,0); each triangle
    /// becomes four flat panels (panel `4t + j`).
    pub fn quadratic(
        vertices: Vec<[f64; 3]>,
        triangles: &[[usize; 3]],
        edge_nodes: &[[usize; 3]],
    ) -> Result<Self, RadiationError> {
        if edge_nodes.len() != triangles.len() {
            return Err(RadiationError::BadTriangle { triangle: triangles.len().min(edge_nodes.len()) });
        }
        let split: Vec<[usize; 3]> = triangles
            .iter()
            .zip(edge_nodes)
            .flat_map(|(&[a, b, c], &[ab, bc, ca])| [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]])
            .collect();
        Self::new(vertices, &split)
    }

    /// Number of panels (unknowns of the solve).
    pub fn len(&self) -> usize {
        self.panels.len()
    }

    /// True when there are no panels (never, for a constructed mesh).
    pub fn is_empty(&self) -> bool {
        self.panels.is_empty()
    }

    /// Total area [m²].
    pub fn area(&self) -> f64 {
        self.panels.iter().map(|p| p.area).sum()
    }

    /// Area-weighted centroid of the surface [m].
    pub fn surface_centroid(&self) -> [f64; 3] {
        let a = self.area();
        [0, 1, 2].map(|k| self.panels.iter().map(|p| p.area * p.centroid[k]).sum::<f64>() / a)
    }

    /// Largest distance from `centre` to a panel corner [m].
    pub fn radius_about(&self, centre: [f64; 3]) -> f64 {
        self.panels
            .iter()
            .flat_map(|p| p.corners)
            .map(|i| norm(sub(self.vertices[i], centre)))
            .fold(0.0, f64::max)
    }

    /// Sum of the signed solid angles of all panels seen from `x`, divided
    /// by 4π: ≈ 1 inside a closed body, ≈ 0 outside.
    pub fn winding_number(&self, x: [f64; 3]) -> f64 {
        let mut total = 0.0;
        for p in &self.panels {
            let [a, b, c] = p.corners.map(|i| sub(self.vertices[i], x));
            let (la, lb, lc) = (norm(a), norm(b), norm(c));
            let num = dot(a, cross(b, c));
            let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
            total += 2.0 * num.atan2(den);
        }
        total / (4.0 * std::f64::consts::PI)
    }

    /// True when `x` lies inside one of the closed bodies.
    pub fn contains(&self, x: [f64; 3]) -> bool {
        self.winding_number(x) > 0.5
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Icosphere of radius `r` centred at `c`, `subdiv` subdivisions
    /// (20·4^subdiv panels), corners projected onto the sphere.
    pub fn icosphere(r: f64, c: [f64; 3], subdiv: u32) -> BoundaryMesh {
        let (v, t) = modal_mesh::icosphere(subdiv);
        let v = v.iter().map(|p| [0, 1, 2].map(|k| c[k] + r * p[k])).collect();
        BoundaryMesh::new(v, &t).unwrap()
    }

    /// Ellipsoid with semi-axes `axes` [m] about the origin: the unit
    /// icosphere of `subdiv` subdivisions scaled along x, y and z (the
    /// non-spherical test surface of the solver's unit tests).
    pub fn ellipsoid(axes: [f64; 3], subdiv: u32) -> BoundaryMesh {
        let (v, t) = modal_mesh::icosphere(subdiv);
        let v = v.iter().map(|p| [0, 1, 2].map(|k| axes[k] * p[k])).collect();
        BoundaryMesh::new(v, &t).unwrap()
    }

    #[test]
    fn sphere_area_normals_and_inside_test() {
        let m = icosphere(0.5, [1.0, 0.0, 0.0], 3);
        assert_eq!(m.len(), 1280);
        let area = 4.0 * std::f64::consts::PI * 0.25;
        assert!((m.area() - area).abs() < 0.01 * area);
        for p in &m.panels {
            let r = sub(p.centroid, [1.0, 0.0, 0.0]);
            assert!(dot(r, p.normal) > 0.99 * norm(r));
        }
        assert!((m.winding_number([1.1, 0.1, -0.2]) - 1.0).abs() < 1e-9);
        assert!(m.winding_number([2.0, 0.1, -0.2]).abs() < 1e-9);
        assert!(m.contains([1.0, 0.0, 0.0]) && !m.contains([0.0, 0.0, 0.0]));
    }

    #[test]
    fn bad_triangles_are_errors() {
        let v = vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        assert!(matches!(
            BoundaryMesh::new(v.clone(), &[[0, 1, 2]]),
            Err(RadiationError::DegenerateTriangle { .. })
        ));
        assert!(matches!(
            BoundaryMesh::new(v.clone(), &[[0, 1, 3]]),
            Err(RadiationError::BadTriangle { .. })
        ));
        assert!(matches!(BoundaryMesh::new(v, &[]), Err(RadiationError::EmptySurface)));
    }
}
