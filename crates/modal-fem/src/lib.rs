//! `modal-fem`: linear-elastic finite elements on tetrahedral meshes.

mod mass_properties;
mod material;
pub use mass_properties::MassProperties;
pub use material::{Material, MaterialError};
