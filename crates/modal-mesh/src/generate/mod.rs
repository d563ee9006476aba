//! Mesh generators for tests, benchmarks and the demo: a box of Kuhn-split
//! hexahedra and mapped structured meshes of a cylinder, tube, sphere and
//! hemispherical bowl. All tets are positively oriented and conforming.
//!
//! [`generate`] is the single entry point for the CLI: it validates the
//! parameters, picks cell counts from the target element size `h` (m) and
//! returns a 4-node (`order` 1) or 10-node (`order` 2) mesh. Quadratic
//! meshes of curved shapes have their mid-edge nodes on the true surface.

mod boxes;
mod mapped;
mod shapes;

pub use boxes::box_mesh;
pub use mapped::MAX_GENERATED_TETS;
pub use shapes::{bowl, cylinder, sphere, tube};

use crate::{to_quadratic, MeshError, TetMesh};
use mapped::positive;

/// A shape to mesh; all lengths in metres.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// Box `[0, size[0]] × [0, size[1]] × [0, size[2]]`.
    Box {
        /// Edge lengths (m).
        size: [f64; 3],
    },
    /// Solid cylinder along z from z = 0, axis through the origin.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Length along z (m).
        length: f64,
    },
    /// Hollow cylinder along z from z = 0.
    Tube {
        /// Inner radius (m).
        inner_radius: f64,
        /// Outer radius (m) (> inner).
        outer_radius: f64,
        /// Length along z (m).
        length: f64,
    },
    /// Ball centred at the origin.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// Hemispherical shell opening towards +z, rim in the plane z = 0,
    /// centre of curvature at the origin.
    Bowl {
        /// Outer radius (m).
        radius: f64,
        /// Wall thickness (m) (< radius).
        thickness: f64,
    },
}

impl Shape {
    /// (D_min, D_max) [m]: the thinnest dimension (shortest side, diameter,
    /// wall or shell thickness) and the largest overall dimension.
    pub fn extents(&self) -> (f64, f64) {
        match *self {
            Shape::Box { size } => {
                (size.iter().copied().fold(f64::INFINITY, f64::min), size.iter().copied().fold(0.0, f64::max))
            }
            Shape::Cylinder { radius, length } => ((2.0 * radius).min(length), (2.0 * radius).max(length)),
            Shape::Tube { inner_radius, outer_radius, length } => {
                ((outer_radius - inner_radius).min(length), (2.0 * outer_radius).max(length))
            }
            Shape::Sphere { radius } => (2.0 * radius, 2.0 * radius),
            Shape::Bowl { radius, thickness } => (thickness, 2.0 * radius),
        }
    }

    /// Default element size h [m] at element `order`, chosen by the accuracy
    /// study (docs/benchmarks/accuracy.md, `modal bench accuracy`):
    /// - order 2: h = min(D_min/2, D_max/4) — the cheapest measured rule with
    ///   a max error ≤ 0.72 % on the first 12–20 modes of the free bar
    ///   (D_min/2 binds), the cantilever (D_min/2) and the sphere (D_max/4);
    /// - order 1: h = min(D_min/8, D_max/20) — ≈ 3.3 % on the bar and 1.6 % on
    ///   the sphere; linear tets lock in bending, so 1 % is out of reach at a
    ///   sane cost.
    ///
    /// Invalid dimensions give 1 m, so that the generator reports them.
    pub fn default_element_size(&self, order: u8) -> f64 {
        let (thinnest, largest) = self.extents();
        let h = if order == 1 {
            (thinnest / 8.0).min(largest / 20.0)
        } else {
            (thinnest / 2.0).min(largest / 4.0)
        };
        if h.is_finite() && h > 0.0 {
            h
        } else {
            1.0
        }
    }

    /// Exact volume of the shape (m³) (the meshes approach it as h → 0).
    pub fn volume(&self) -> f64 {
        use std::f64::consts::PI;
        match *self {
            Shape::Box { size } => size[0] * size[1] * size[2],
            Shape::Cylinder { radius, length } => PI * radius * radius * length,
            Shape::Tube { inner_radius, outer_radius, length } => {
                PI * (outer_radius * outer_radius - inner_radius * inner_radius) * length
            }
            Shape::Sphere { radius } => 4.0 / 3.0 * PI * radius.powi(3),
            Shape::Bowl { radius, thickness } => {
                2.0 / 3.0 * PI * (radius.powi(3) - (radius - thickness).powi(3))
            }
        }
    }
}

/// Meshes `shape` with elements of size about `h` (m) at element `order`
/// (1: 4-node, 2: 10-node). Errors on non-finite or non-positive lengths,
/// an inner radius not below the outer one, a thickness not below the
/// radius, an order other than 1 or 2, or a mesh of more than
/// [`MAX_GENERATED_TETS`] tets.
pub fn generate(shape: &Shape, h: f64, order: u8) -> Result<TetMesh, MeshError> {
    positive("h", h)?;
    mapped::check_order(order)?;
    match *shape {
        Shape::Box { size } => {
            for (name, s) in ["size x", "size y", "size z"].into_iter().zip(size) {
                positive(name, s)?;
            }
            let cells = size.map(|s| shapes::cells_for(s, h));
            mapped::check_count(mapped::tet_count(cells))?;
            let linear = box_mesh(size, cells);
            Ok(if order == 2 { to_quadratic(&linear) } else { linear })
        }
        Shape::Cylinder { radius, length } => cylinder(radius, length, h, order),
        Shape::Tube { inner_radius, outer_radius, length } => {
            tube(inner_radius, outer_radius, length, h, order)
        }
        Shape::Sphere { radius } => sphere(radius, h, order),
        Shape::Bowl { radius, thickness } => bowl(radius, thickness, h, order),
    }
}
