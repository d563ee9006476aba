//! Isotropic linear-elastic materials with Rayleigh damping `C = αM + βK`.
//!
//! For a mode of undamped angular frequency ω [rad/s]: decay rate
//! `d = (α + β ω²)/2` [1/s], damping ratio `ξ = (α/ω + β ω)/2`.

use serde::{Deserialize, Serialize};

/// An isotropic material, SI units.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Preset name, if the material came from one.
    pub name: Option<String>,
    /// Young's modulus E [Pa].
    pub youngs_pa: f64,
    /// Poisson's ratio ν [-], −1 < ν < 0.5.
    pub poisson: f64,
    /// Density ρ [kg/m³].
    pub density_kg_m3: f64,
    /// Rayleigh mass-proportional damping α [1/s].
    pub alpha: f64,
    /// Rayleigh stiffness-proportional damping β [s].
    pub beta: f64,
}

/// A material parameter that is physically impossible.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MaterialError {
    /// Unknown preset name.
    #[error("unknown material '{0}' (known: {1})")]
    UnknownPreset(String, String),
    /// A value outside its physical range.
    #[error("invalid material: {0}")]
    Invalid(String),
}
