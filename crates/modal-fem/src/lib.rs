//! `modal-fem`: linear-elastic finite elements on tetrahedral meshes.
//!
//! Input: a [`modal_mesh::TetMesh`] (4- or 10-node tets, metres) and a
//! [`Material`]. Output: the global stiffness `K` and consistent mass `M`
//! as faer sparse matrices ([`assemble`]), rigid-body mass properties
//! ([`mass_properties`]), rigid-body displacement fields, clamping helpers,
//! and MatrixMarket / CSV export for cross-checking with other tools.
//!
//! Conventions: SI units; DOF `3i + c` is component `c` of node `i`;
//! reference tet and quadrature in [`quadrature`]; shape functions and
//! element matrices in [`element`]; default element order 2 (10-node tets).

// Index loops mirror the tensor notation of the equations in the docs.
#![allow(clippy::needless_range_loop)]

mod assembly;
mod constraints;
pub mod element;
mod error;
mod export;
mod mass_properties;
mod material;
pub mod quadrature;
mod rigid;

pub use assembly::{
    assemble, matrices_bytes, min_quadratic_matrices_bytes, prepare_mesh, Assembly, SparsityPattern,
    DEFAULT_ORDER, MIN_NODE_PAIRS_PER_QUADRATIC_TET,
};
pub use constraints::{fix_box, restrict, DofMap, Restricted};
pub use error::FemError;
pub use export::{write_matrix_market, write_nodes_csv};
pub use mass_properties::{mass_properties, MassProperties};
pub use material::{Lame, Material, MaterialError, MaterialOverrides, ResolvedMaterial};
pub use rigid::{m_orthonormalize, node_parts, rigid_body_fields};
