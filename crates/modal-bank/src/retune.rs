//! Retune a bank to a new material and/or size without a new eigen solve.
//!
//! Exact for linear elasticity (`shared/reference/materials.md`). With the
//! same Poisson's ratio ν, `K ∝ E` and `M ∝ ρ`, so for new E', ρ':
//! `λ' = λ · (E'/E) / (ρ'/ρ)` and mass-normalized shapes `φ' = φ · √(ρ/ρ')`.
//! For a uniform geometric scale γ (all lengths × γ): `K ∝ γ`, `M ∝ γ³`, so
//! `ω' = ω / γ` and `φ' = φ · γ^{-3/2}`; positions and centre of mass × γ,
//! volume × γ³, mass × γ³ · ρ'/ρ, inertia × γ⁵ · ρ'/ρ.
//! Damping is recomputed from the new α, β at the new frequencies;
//! relative residuals are invariant. A different ν changes the mode shapes
//! and needs a new solve.

use crate::validate::check_material;
use crate::{BankError, CacheKey, ModeBank, RadiationTable};
use modal_fem::Material;

/// Prefix of the `input_hash` of a retuned bank.
pub const RETUNED_PREFIX: &str = "retuned:";

/// What to change. `None` keeps the bank's material / size.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RetuneSpec {
    /// The new material; its ν must equal the bank's.
    pub material: Option<Material>,
    /// Uniform geometric scale γ > 0 applied to all lengths.
    pub scale: Option<f64>,
}

/// Largest |ν' − ν| accepted as "the same Poisson's ratio".
const POISSON_TOL: f64 = 1e-12;

/// A new bank for `spec`'s material and size (see the module docs). Its
/// `info.input_hash` becomes `retuned:<hex>` (hash of the old hash and the
/// spec), so it is never served as a cache hit for a fresh solve.
pub fn retune(bank: &ModeBank, spec: RetuneSpec) -> Result<ModeBank, BankError> {
    let f = Factors::of(bank, &spec)?;
    let (gamma, density) = (f.gamma, f.density);
    let (g3, g5) = (gamma.powi(3), gamma.powi(5));

    let mut out = bank.clone();
    out.frequencies_hz.iter_mut().for_each(|x| *x *= f.frequency);
    out.shapes.iter_mut().for_each(|v| *v = (f64::from(*v) * f.shape) as f32);
    out.surface.positions.iter_mut().flatten().for_each(|x| *x *= gamma);
    let m = &mut out.mass;
    m.volume_m3 *= g3;
    m.mass_kg *= g3 * density;
    m.center_of_mass_m.iter_mut().for_each(|x| *x *= gamma);
    m.inertia_kg_m2.iter_mut().flatten().for_each(|x| *x *= g5 * density);
    out.material = spec.material.clone().unwrap_or_else(|| bank.material.clone());
    out.recompute_damping();
    out.info.input_hash = retuned_hash(bank, &spec, gamma);
    out.validate()?;
    Ok(out)
}

/// `material` with `bank`'s Poisson's ratio, which a retune cannot change
/// (module doc), and the ratio it asked for when that differed (`None`: the
/// same). A preset so changed is named `+custom`, as any overridden preset
/// is. For "this bank, in aluminium": E and ρ carry the material, and ν
/// moves the frequencies far less (see [`poisson_shift`]).
pub fn keeping_poisson(bank: &ModeBank, mut material: Material) -> (Material, Option<f64>) {
    let (kept, asked) = (bank.material.poisson, material.poisson);
    if (asked - kept).abs() <= POISSON_TOL {
        return (material, None);
    }
    material.poisson = kept;
    if let Some(name) = material.name.as_mut().filter(|n| !n.ends_with("+custom")) {
        name.push_str("+custom");
    }
    (material, Some(asked))
}

/// The largest relative change of a frequency that setting Poisson's ratio
/// from `from` to `to` at fixed E and ρ could make: the largest change of
/// the three wave speeds that set a solid's and a thin wall's modes,
/// shear `c_s ∝ (1+ν)^{-1/2}`, compression `c_p ∝ ((1−ν)/((1+ν)(1−2ν)))^{1/2}`
/// and plate bending `∝ (1−ν²)^{-1/2}` (ω ∝ √D). From 0.29 to 0.33: 1.5 %,
/// 6.3 % and 1.4 %; a mode mixes them, so it moves by at most the largest.
pub fn poisson_shift(from: f64, to: f64) -> f64 {
    let shear = |nu: f64| (1.0 + nu).powf(-0.5);
    let compression = |nu: f64| ((1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))).sqrt();
    let bending = |nu: f64| (1.0 - nu * nu).powf(-0.5);
    [shear(to) / shear(from), compression(to) / compression(from), bending(to) / bending(from)]
        .into_iter()
        .map(|ratio| (ratio - 1.0).abs())
        .fold(0.0, f64::max)
}

/// The stored acoustic transfer of `bank` for the bank [`retune`] makes of
/// it with `spec`, or `None` when it does not carry over.
///
/// The exterior problem of a mode depends on `ka` (wavenumber times size)
/// and is linear in the surface velocity. When `ω'γ = ω` (only the damping
/// changes, or the size with `E/ρ` kept) every `ka` is unchanged: the field
/// of the retuned mode at `γx` is the old one at `x` times the shape factor
/// `s = φ'/φ`. So the centre and fit radius scale by `γ`, wavenumbers by
/// `1/γ`, coefficients (of `h_l(kr)`, `kr` unchanged) by `s`, power by
/// `s²γ²`, and the efficiency stays. Otherwise (`E/ρ` changed) the modes
/// sit at new `ka`, and only a new solve gives their transfer.
pub fn retune_radiation(
    bank: &ModeBank,
    table: &RadiationTable,
    spec: &RetuneSpec,
) -> Option<RadiationTable> {
    let f = Factors::of(bank, spec).ok()?;
    if (f.frequency * f.gamma - 1.0).abs() > KA_TOL {
        return None;
    }
    let mut out = table.clone();
    out.centre_m.iter_mut().for_each(|x| *x *= f.gamma);
    out.fit_radius_m *= f.gamma;
    for m in &mut out.modes {
        m.wavenumber /= f.gamma;
        m.coefficients.iter_mut().flatten().for_each(|c| *c *= f.shape);
        m.power_w *= f.shape * f.shape * f.gamma * f.gamma;
    }
    Some(out)
}

/// Largest relative change of `ka` taken as none (rounding of `√(E'ρ/Eρ')`).
const KA_TOL: f64 = 1e-12;

/// The exact scale factors of a retune (module doc).
struct Factors {
    /// Geometric scale γ.
    gamma: f64,
    /// ρ'/ρ.
    density: f64,
    /// ω'/ω = √((E'/E)/(ρ'/ρ)) / γ.
    frequency: f64,
    /// φ'/φ = √(ρ/ρ') γ^{-3/2}.
    shape: f64,
}

impl Factors {
    fn of(bank: &ModeBank, spec: &RetuneSpec) -> Result<Factors, BankError> {
        let old = &bank.material;
        let new = spec.material.as_ref().unwrap_or(old);
        check_material(new)?;
        if (new.poisson - old.poisson).abs() > POISSON_TOL {
            return Err(BankError::PoissonChanged { bank: old.poisson, requested: new.poisson });
        }
        let gamma = spec.scale.unwrap_or(1.0);
        if !(gamma.is_finite() && gamma > 0.0) {
            return Err(BankError::InvalidScale(gamma));
        }
        let stiffness = new.youngs_pa / old.youngs_pa;
        let density = new.density_kg_m3 / old.density_kg_m3;
        Ok(Factors {
            gamma,
            density,
            frequency: (stiffness / density).sqrt() / gamma,
            shape: (1.0 / density).sqrt() * gamma.powf(-1.5),
        })
    }
}

fn retuned_hash(bank: &ModeBank, spec: &RetuneSpec, gamma: f64) -> String {
    let material = serde_json::to_string(&spec.material).unwrap_or_default();
    let key = CacheKey::new("modal-retune-v1")
        .add_str("parent_input_hash", &bank.info.input_hash)
        .add_str("material", &material)
        .add_f64("scale", gamma)
        .finish();
    format!("{RETUNED_PREFIX}{key}")
}
