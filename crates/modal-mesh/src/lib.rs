//! `modal-mesh`: tetrahedral meshes in, checked tetrahedral meshes out.
//!
//! Inputs: Gmsh `.msh` (4.1 ASCII/binary, 2.2 ASCII), TetGen `.node`/`.ele`,
//! Medit `.mesh`, or a generator (box, cylinder, tube, sphere, bowl).
//! Output: a [`TetMesh`] in metres whose tets are positively oriented, with
//! unused nodes dropped and connected parts counted; plus its boundary
//! [`Surface`] (used by the mode bank and the synthesizer).
//!
//! Conventions, stated once for the whole project:
//! - Corner order: a tet `[a, b, c, d]` is positively oriented when
//!   `(b − a) × (c − a) · (d − a) > 0` (six times its signed volume).
//! - 10-node tets use the VTK edge order, see [`TET10_EDGES`]: node `4 + e`
//!   sits on edge `TET10_EDGES[e]`. Gmsh stores the last two edge nodes the
//!   other way round; its reader swaps them.

mod error;
mod types;
pub use error::{Location, MeshError};
pub use types::*;

pub mod io;
mod quality;
mod surface;
pub use quality::{dihedral_angles_deg, min_dihedral_angle_deg};
mod validate;
pub use io::{read_mesh, write_msh41, write_msh41_file};
pub use surface::boundary_surface;
pub use validate::{check, connected_parts, tet10_shape_gradients, MeshReport, DEGENERATE_VOLUME_RATIO};

pub mod generate;
mod promote;
pub use promote::{to_linear, to_quadratic, to_quadratic_with};
