//! Isotropic linear-elastic materials with Rayleigh damping `C = αM + βK`.
//!
//! For a mode of undamped angular frequency ω \[rad/s\]: decay rate
//! `d = (α + β ω²)/2` \[1/s\], damping ratio `ξ = (α/ω + β ω)/2`
//! (`shared/reference/materials.md`). α multiplies the mass matrix, β the
//! stiffness matrix — some codes swap the two names; we do not.
//!
//! Lamé parameters: `λ = Eν/((1+ν)(1−2ν))`, `μ = G = E/(2(1+ν))`.
//!
//! Presets: the set shared by KleinPAT (Wang & James 2019, Table 4),
//! NeuralSound and the KHR_audio_modal draft, plus aluminium and brass whose
//! E, ν, ρ are handbook values. The Rayleigh pair of aluminium and brass is
//! NOT from that source: we use the "metal" pair fitted by Ren, Yeh & Lin
//! 2013 (α = 6.3035 1/s, β = 2.1160e-8 s), rounded to α = 6.3, β = 2.1e-8.

use serde::{Deserialize, Serialize};

/// An isotropic material, SI units.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Preset name, if the material came from one.
    pub name: Option<String>,
    /// Young's modulus E \[Pa\].
    pub youngs_pa: f64,
    /// Poisson's ratio ν \[-\], −1 < ν < 0.5.
    pub poisson: f64,
    /// Density ρ \[kg/m³\].
    pub density_kg_m3: f64,
    /// Rayleigh mass-proportional damping α \[1/s\].
    pub alpha: f64,
    /// Rayleigh stiffness-proportional damping β \[s\].
    pub beta: f64,
}

/// A material parameter that is physically impossible, or a preset that
/// does not exist.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MaterialError {
    /// Unknown preset name: the name, then the known names comma-separated.
    #[error("unknown material '{0}' (known: {1})")]
    UnknownPreset(String, String),
    /// A value outside its physical range.
    #[error("invalid material: {0}")]
    Invalid(String),
    /// Without a preset, this value must be given explicitly.
    #[error("material: {0} is required when no preset material is given")]
    Missing(&'static str),
}

/// One preset: name, ρ \[kg/m³\], E \[Pa\], ν, α \[1/s\], β \[s\].
struct Preset {
    name: &'static str,
    density: f64,
    youngs: f64,
    poisson: f64,
    alpha: f64,
    beta: f64,
}

/// Young's moduli accepted [Pa]: from soft gels (≈ 10³) to beyond diamond
/// (≈ 1.1·10¹²). Outside, a value is a unit mistake, and the solve would
/// end in "did not converge" or frequencies of 10¹⁵² Hz.
pub const YOUNGS_RANGE_PA: std::ops::RangeInclusive<f64> = 1e3..=1e13;
/// Densities accepted [kg/m³]: from aerogels (≈ 0.2) to beyond osmium (22 590).
pub const DENSITY_RANGE_KG_M3: std::ops::RangeInclusive<f64> = 0.1..=1e5;

const fn preset(
    name: &'static str,
    density: f64,
    youngs: f64,
    poisson: f64,
    alpha: f64,
    beta: f64,
) -> Preset {
    Preset { name, density, youngs, poisson, alpha, beta }
}

/// The presets (see the module doc for sources).
const PRESETS: [Preset; 10] = [
    preset("ceramic", 2700.0, 7.2e10, 0.19, 6.0, 1e-7),
    preset("glass", 2600.0, 6.2e10, 0.20, 1.0, 1e-7),
    preset("wood", 750.0, 1.1e10, 0.25, 60.0, 2e-6),
    preset("plastic", 1070.0, 1.4e9, 0.35, 30.0, 1e-6),
    preset("iron", 8000.0, 2.1e11, 0.28, 5.0, 1e-7),
    preset("polycarbonate", 1190.0, 2.4e9, 0.37, 0.5, 4e-7),
    preset("steel", 7850.0, 2.0e11, 0.29, 5.0, 3e-8),
    preset("tin", 7265.0, 5.0e10, 0.325, 2.0, 3e-8),
    preset("aluminium", 2700.0, 7.0e10, 0.33, 6.3, 2.1e-8),
    preset("brass", 8500.0, 1.0e11, 0.34, 6.3, 2.1e-8),
];

/// Alternative spellings accepted by [`Material::preset`].
const ALIASES: [(&str, &str); 2] = [("aluminum", "aluminium"), ("abs", "plastic")];

/// Explicit values that override a preset's, or define a material alone.
/// `None` keeps the preset's value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaterialOverrides {
    /// Young's modulus E \[Pa\].
    pub youngs: Option<f64>,
    /// Poisson's ratio ν.
    pub poisson: Option<f64>,
    /// Density ρ \[kg/m³\].
    pub density: Option<f64>,
    /// Rayleigh α \[1/s\].
    pub alpha: Option<f64>,
    /// Rayleigh β \[s\].
    pub beta: Option<f64>,
}

/// A validated material and whether its damping silently defaulted to zero
/// (no preset and neither α nor β given), so the caller can warn.
#[derive(Clone, Debug, PartialEq)]
pub struct ResolvedMaterial {
    /// The validated material.
    pub material: Material,
    /// True when α and β were both defaulted to 0 (undamped).
    pub damping_defaulted_to_zero: bool,
}

/// Lamé parameters λ and μ (= shear modulus G) \[Pa\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lame {
    /// First Lamé parameter λ \[Pa\].
    pub lambda: f64,
    /// Shear modulus μ = G \[Pa\].
    pub mu: f64,
}

impl Material {
    /// Names of all presets (canonical spelling).
    pub fn preset_names() -> Vec<&'static str> {
        PRESETS.iter().map(|p| p.name).collect()
    }

    /// The named preset, case-insensitive ("aluminum" and "abs" accepted as
    /// aliases).
    pub fn preset(name: &str) -> Result<Material, MaterialError> {
        let lower = name.trim().to_ascii_lowercase();
        let canonical = ALIASES.iter().find(|(a, _)| *a == lower).map_or(lower.as_str(), |(_, c)| c);
        let p = PRESETS
            .iter()
            .find(|p| p.name == canonical)
            .ok_or_else(|| MaterialError::UnknownPreset(name.to_string(), Self::preset_names().join(", ")))?;
        Ok(Material {
            name: Some(p.name.to_string()),
            youngs_pa: p.youngs,
            poisson: p.poisson,
            density_kg_m3: p.density,
            alpha: p.alpha,
            beta: p.beta,
        })
    }

    /// A custom, validated material from E \[Pa\], ν, ρ \[kg/m³\], α \[1/s\], β \[s\].
    pub fn custom(
        youngs_pa: f64,
        poisson: f64,
        density_kg_m3: f64,
        alpha: f64,
        beta: f64,
    ) -> Result<Material, MaterialError> {
        let m = Material { name: None, youngs_pa, poisson, density_kg_m3, alpha, beta };
        m.validate()?;
        Ok(m)
    }

    /// Applies `overrides` over the preset `preset` (if any) and validates.
    /// Without a preset, E, ν and ρ are required and α, β default to 0.
    /// A preset whose values were overridden keeps its name with a `+custom`
    /// suffix, so reports do not claim pure preset values.
    pub fn resolve(
        preset: Option<&str>,
        overrides: &MaterialOverrides,
    ) -> Result<ResolvedMaterial, MaterialError> {
        let o = overrides;
        let (material, damping_defaulted_to_zero) = match preset {
            Some(name) => {
                let mut m = Material::preset(name)?;
                let changed = o.youngs.is_some()
                    || o.poisson.is_some()
                    || o.density.is_some()
                    || o.alpha.is_some()
                    || o.beta.is_some();
                m.youngs_pa = o.youngs.unwrap_or(m.youngs_pa);
                m.poisson = o.poisson.unwrap_or(m.poisson);
                m.density_kg_m3 = o.density.unwrap_or(m.density_kg_m3);
                m.alpha = o.alpha.unwrap_or(m.alpha);
                m.beta = o.beta.unwrap_or(m.beta);
                if changed {
                    m.name = m.name.map(|n| format!("{n}+custom"));
                }
                (m, false)
            }
            None => {
                let m = Material {
                    name: None,
                    youngs_pa: o.youngs.ok_or(MaterialError::Missing("Young's modulus (youngs)"))?,
                    poisson: o.poisson.ok_or(MaterialError::Missing("Poisson's ratio (poisson)"))?,
                    density_kg_m3: o.density.ok_or(MaterialError::Missing("density"))?,
                    alpha: o.alpha.unwrap_or(0.0),
                    beta: o.beta.unwrap_or(0.0),
                };
                (m, o.alpha.is_none() && o.beta.is_none())
            }
        };
        material.validate()?;
        Ok(ResolvedMaterial { material, damping_defaulted_to_zero })
    }

    /// Checks physical admissibility: E > 0, −1 < ν < 0.5, ρ > 0, α ≥ 0,
    /// β ≥ 0, all finite. The error names the offending field and value.
    pub fn validate(&self) -> Result<(), MaterialError> {
        let bad = |what: &str, v: f64, rule: &str| {
            Err(MaterialError::Invalid(format!("{what} = {} ({rule})", modal_mesh::readable(v))))
        };
        let fields = [
            ("Young's modulus E [Pa]", self.youngs_pa),
            ("Poisson's ratio ν", self.poisson),
            ("density ρ [kg/m³]", self.density_kg_m3),
            ("Rayleigh α [1/s]", self.alpha),
            ("Rayleigh β [s]", self.beta),
        ];
        if let Some((what, v)) = fields.iter().find(|(_, v)| !v.is_finite()) {
            return bad(what, *v, "must be finite");
        }
        if self.youngs_pa <= 0.0 {
            return bad(fields[0].0, self.youngs_pa, "must be > 0");
        }
        if !YOUNGS_RANGE_PA.contains(&self.youngs_pa) {
            return bad(
                fields[0].0,
                self.youngs_pa,
                "softer than a gel or stiffer than diamond: solids lie within 1e3 to 1e13 Pa; is it in Pa?",
            );
        }
        if !(self.poisson > -1.0 && self.poisson < 0.5) {
            return bad(fields[1].0, self.poisson, "must satisfy -1 < ν < 0.5");
        }
        if self.density_kg_m3 <= 0.0 {
            return bad(fields[2].0, self.density_kg_m3, "must be > 0");
        }
        if !DENSITY_RANGE_KG_M3.contains(&self.density_kg_m3) {
            return bad(
                fields[2].0,
                self.density_kg_m3,
                "lighter than an aerogel or denser than osmium: solids lie within 0.1 to 1e5 kg/m³; is it in kg/m³?",
            );
        }
        if self.alpha < 0.0 {
            return bad(fields[3].0, self.alpha, "must be >= 0");
        }
        if self.beta < 0.0 {
            return bad(fields[4].0, self.beta, "must be >= 0");
        }
        Ok(())
    }

    /// Modal decay rate `d = (α + β ω²)/2` \[1/s\] at angular frequency ω \[rad/s\].
    pub fn decay_rate(&self, omega_rad_s: f64) -> f64 {
        0.5 * (self.alpha + self.beta * omega_rad_s * omega_rad_s)
    }

    /// Modal damping ratio `ξ = (α/ω + β ω)/2` at angular frequency ω \[rad/s\] (> 0).
    pub fn damping_ratio(&self, omega_rad_s: f64) -> f64 {
        0.5 * (self.alpha / omega_rad_s + self.beta * omega_rad_s)
    }

    /// Lamé parameters λ, μ \[Pa\].
    pub fn lame(&self) -> Lame {
        let (e, nu) = (self.youngs_pa, self.poisson);
        Lame { lambda: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu: e / (2.0 * (1.0 + nu)) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_is_valid_and_case_insensitive() {
        for name in Material::preset_names() {
            let m = Material::preset(&name.to_uppercase()).unwrap();
            m.validate().unwrap();
            assert_eq!(m.name.as_deref(), Some(name));
        }
        let steel = Material::preset("Steel").unwrap();
        assert_eq!(
            (steel.youngs_pa, steel.poisson, steel.density_kg_m3, steel.alpha, steel.beta),
            (2.0e11, 0.29, 7850.0, 5.0, 3e-8)
        );
        assert_eq!(Material::preset("aluminum").unwrap().density_kg_m3, 2700.0);
        assert_eq!(Material::preset("brass").unwrap().youngs_pa, 1.0e11);
    }

    #[test]
    fn unknown_preset_lists_known_names() {
        let err = Material::preset("unobtainium").unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("unobtainium") && msg.contains("steel") && msg.contains("brass"), "{msg}");
    }

    #[test]
    fn validation_rejects_impossible_values() {
        let ok = |e, nu, rho, a, b| Material::custom(e, nu, rho, a, b).is_ok();
        assert!(ok(200e9, 0.3, 7850.0, 0.0, 0.0));
        assert!(ok(200e9, -0.99, 7850.0, 0.0, 0.0));
        assert!(!ok(200e9, 0.5, 7850.0, 0.0, 0.0));
        assert!(!ok(200e9, -1.0, 7850.0, 0.0, 0.0));
        assert!(!ok(0.0, 0.3, 7850.0, 0.0, 0.0));
        assert!(!ok(200e9, 0.3, -1.0, 0.0, 0.0));
        assert!(!ok(200e9, 0.3, 7850.0, -1.0, 0.0));
        assert!(!ok(200e9, 0.3, 7850.0, 0.0, -1e-9));
        assert!(!ok(f64::NAN, 0.3, 7850.0, 0.0, 0.0));
        assert!(!ok(200e9, 0.3, f64::INFINITY, 0.0, 0.0));
        // Absurd values (a unit mistake, a typo) are refused, not solved into
        // "did not converge" or 1e152 Hz.
        for (e, rho) in [(1e300, 7850.0), (200.0, 7850.0), (200e9, 1e-300), (200e9, 1e300)] {
            let why = Material::custom(e, 0.3, rho, 0.0, 0.0).unwrap_err().to_string();
            assert!(why.contains("is it in"), "E {e}, ρ {rho}: {why}");
        }
        assert!(ok(1e3, 0.3, 0.1, 0.0, 0.0) && ok(1e13, 0.3, 1e5, 0.0, 0.0));
        let msg = Material::custom(200e9, 0.5, 7850.0, 0.0, 0.0).unwrap_err().to_string();
        assert!(msg.contains("Poisson") && msg.contains("0.5"), "{msg}");
    }

    #[test]
    fn overrides_merge_over_preset_or_stand_alone() {
        let o = MaterialOverrides { poisson: Some(0.3), ..Default::default() };
        let r = Material::resolve(Some("steel"), &o).unwrap();
        assert_eq!((r.material.poisson, r.material.youngs_pa, r.material.alpha), (0.3, 2.0e11, 5.0));
        assert!(!r.damping_defaulted_to_zero);
        assert_eq!(r.material.name.as_deref(), Some("steel+custom"));

        let alone = MaterialOverrides {
            youngs: Some(1e9),
            poisson: Some(0.3),
            density: Some(1000.0),
            ..Default::default()
        };
        let r = Material::resolve(None, &alone).unwrap();
        assert!(r.damping_defaulted_to_zero);
        assert_eq!((r.material.alpha, r.material.beta), (0.0, 0.0));
        let with_beta = MaterialOverrides { beta: Some(1e-7), ..alone };
        assert!(!Material::resolve(None, &with_beta).unwrap().damping_defaulted_to_zero);

        let missing = MaterialOverrides { youngs: Some(1e9), ..Default::default() };
        assert!(matches!(Material::resolve(None, &missing), Err(MaterialError::Missing(_))));
        let bad = MaterialOverrides { poisson: Some(0.7), ..Default::default() };
        assert!(matches!(Material::resolve(Some("glass"), &bad), Err(MaterialError::Invalid(_))));
    }

    #[test]
    fn damping_and_lame_follow_the_stated_convention() {
        let m = Material::custom(200e9, 0.3, 7850.0, 4.0, 2e-8).unwrap();
        let w = 1000.0;
        assert_eq!(m.decay_rate(w), 0.5 * (4.0 + 2e-8 * 1e6));
        assert!((m.damping_ratio(w) - m.decay_rate(w) / w).abs() < 1e-18);
        let l = m.lame();
        assert!((l.mu - 200e9 / 2.6).abs() < 1e-3);
        assert!((l.lambda - 200e9 * 0.3 / (1.3 * 0.4)).abs() < 1e-3);
    }
}
