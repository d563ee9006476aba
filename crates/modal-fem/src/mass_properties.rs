//! Rigid-body mass properties of a tet mesh (exact integrals).

use serde::{Deserialize, Serialize};

/// Volume, mass, centre of mass and inertia of a solid, SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MassProperties {
    /// Volume [m³].
    pub volume_m3: f64,
    /// Mass [kg].
    pub mass_kg: f64,
    /// Centre of mass [m].
    pub center_of_mass_m: [f64; 3],
    /// Inertia tensor about the centre of mass [kg·m²], symmetric.
    pub inertia_kg_m2: [[f64; 3]; 3],
}
