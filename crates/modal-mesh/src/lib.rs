//! `modal-mesh`: tetrahedral meshes in, checked tetrahedral meshes out.
//!
//! Inputs: Gmsh `.msh` (4.1 ASCII/binary, 2.2 ASCII/binary), TetGen
//! `.node`/`.ele`, Medit `.mesh` ([`read_mesh`], module [`io`]), or a
//! generator (box, cylinder, tube, sphere, bowl; [`generate::generate`]).
//! [`check`] turns a raw mesh into one the FEM can trust: positively
//! oriented tets, no degenerate or inverted elements, unused nodes dropped,
//! parts found through shared faces, parts that touch only at an edge or a
//! vertex (hinges) split into separate bodies ([`MeshReport`], [`face_parts`]). [`boundary_surface`] extracts
//! the outward boundary [`Surface`] (used by the mode bank and the
//! synthesizer); [`to_quadratic`] / [`to_linear`] change the element order;
//! [`write_msh41`] writes Gmsh MSH 4.1 that Gmsh and meshio open.
//!
//! Conventions, stated once for the whole project:
//! - Units: metres; readers multiply file coordinates by a caller's scale.
//!   Files carry no unit, so a size that suggests millimetres is judged in
//!   one place ([`unit_warning`], [`unstated_size_refusal`]).
//! - Corner order: a tet `[a, b, c, d]` is positively oriented when
//!   `(b − a) × (c − a) · (d − a) > 0` (six times its signed volume).
//! - 10-node tets use the VTK edge order, see [`TET10_EDGES`]: node `4 + e`
//!   sits on edge `TET10_EDGES[e]`. Gmsh stores the last two edge nodes the
//!   other way round; its reader and writer swap them.
//! - Reference tet: `(ξ, η, ζ)` with barycentrics `L0 = 1 − ξ − η − ζ`,
//!   `L1 = ξ`, `L2 = η`, `L3 = ζ` (see [`tet10_shape_gradients`]).
//!
//! Errors are [`MeshError`] values whose message is one line naming the
//! file position, element or node; nothing here panics on user data.

mod closest;
mod disc;
mod disjoint;
mod error;
mod icosphere;
mod measure;
mod overlap;
mod parts;
mod promote;
mod quality;
mod stats;
mod surface;
mod triangle6;
mod types;
mod units;
mod validate;

pub mod generate;
pub mod io;

pub use closest::closest_point_on_triangle;
pub use disc::disc_surface;
pub use disjoint::DisjointSets;
pub use error::{Location, MeshError};
pub use icosphere::icosphere;
pub use io::{read_mesh, write_msh41, write_msh41_file};
pub use measure::{mesh_volume, tet_volume};
pub use parts::{describe_hinges, face_parts, split_hinges, FaceParts, Hinge};
pub use promote::{to_linear, to_quadratic, to_quadratic_with};
pub use quality::{dihedral_angles_deg, min_dihedral_angle_deg};
pub use stats::weighted_median;
pub use surface::boundary_surface;
pub use triangle6::quadratic_triangle_normal;
pub use types::*;
pub use units::{
    bounding_box, bounding_diagonal, readable, scale_refusal, unit_warning, unstated_size_refusal,
    LARGEST_PLAIN_DIAGONAL_M, LARGEST_UNREMARKED_DIAGONAL_M, SCALE_RANGE, SMALLEST_PLAIN_DIAGONAL_M,
};
pub use validate::{
    check, connected_parts, tet10_shape_gradients, MeshReport, DEGENERATE_VOLUME_RATIO, SLIVER_ANGLE_DEG,
};
