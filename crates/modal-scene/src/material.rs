//! Scene material specs → [`modal_fem::Material`] (presets and validation
//! come from `modal-fem`, see `shared/reference/materials.md`).

use modal_fem::Material;

use crate::spec::MaterialSpec;

/// Names of the known presets, comma separated.
pub fn preset_names() -> String {
    Material::preset_names().join(", ")
}

/// The validated material a spec describes; the error is a one-line reason.
pub fn resolve_material(spec: &MaterialSpec) -> Result<Material, String> {
    match spec {
        MaterialSpec::Preset(name) => Material::preset(name),
        MaterialSpec::Explicit(m) => Material::custom(m.youngs, m.poisson, m.density, m.alpha, m.beta),
    }
    .map_err(|e| e.to_string())
}

/// Plane-strain modulus `E/(1 − ν²)` [Pa], the per-body term of Hertz's `E*`.
pub fn plane_strain_modulus(m: &Material) -> f64 {
    m.youngs_pa / (1.0 - m.poisson * m.poisson)
}
