//! Invariants of a [`ModeBank`], checked before every save, after every load
//! and on every retune result.
//!
//! - per-mode arrays all have `n` entries and `shapes` has `n · s · 3`;
//! - frequencies finite, > 0 and non-decreasing (repeated eigenvalues allowed);
//! - damping ratios, decay rates and residuals finite and ≥ 0, and
//!   `d = ξ ω` for every mode (relative 1e-9; true for any viscous modal
//!   damping, Rayleigh or measured — the damping need not come from the
//!   material's α, β, although [`crate::retune`] recomputes it from them);
//! - `info.error_estimate_pct` empty or one finite, non-negative (or absent)
//!   value per mode;
//! - shapes and positions finite; surface indices name surface nodes;
//! - material physically possible; mass properties finite, mass and volume ≥ 0.

use crate::{BankError, ModeBank};
use modal_fem::{MassProperties, Material};
use modal_mesh::Surface;
use std::f64::consts::PI;

/// Relative tolerance of the check `d = ξ ω`.
const DAMPING_RTOL: f64 = 1e-9;

impl ModeBank {
    /// Checks every invariant of the bank (see the module docs); the first
    /// violation is returned as a typed error naming the field and index.
    pub fn validate(&self) -> Result<(), BankError> {
        check_counts(self)?;
        check_material(&self.material)?;
        check_frequencies(&self.frequencies_hz)?;
        check_damping(self)?;
        check_nonnegative("residuals", &self.residuals)?;
        check_error_estimates(self)?;
        check_shapes(self)?;
        check_surface(&self.surface)?;
        check_mass(&self.mass)
    }
}

fn check_counts(bank: &ModeBank) -> Result<(), BankError> {
    let n = bank.frequencies_hz.len();
    for (name, len) in [
        ("damping_ratios", bank.damping_ratios.len()),
        ("decay_rates", bank.decay_rates.len()),
        ("residuals", bank.residuals.len()),
    ] {
        if len != n {
            return Err(BankError::Inconsistent(format!(
                "{name} has {len} entries but frequencies_hz has {n}"
            )));
        }
    }
    let s = bank.surface.positions.len();
    let expected = n.checked_mul(s).and_then(|v| v.checked_mul(3));
    if expected != Some(bank.shapes.len()) {
        return Err(BankError::Inconsistent(format!(
            "shapes has {} values, expected {n} modes × {s} surface nodes × 3",
            bank.shapes.len()
        )));
    }
    if bank.surface.node_ids.len() != s {
        return Err(BankError::Inconsistent(format!(
            "surface has {} node ids but {s} positions",
            bank.surface.node_ids.len()
        )));
    }
    if let Some(edges) = &bank.surface.triangle_edge_nodes {
        if edges.len() != bank.surface.triangles.len() {
            return Err(BankError::Inconsistent(format!(
                "surface has {} triangles but {} triangle edge-node triples",
                bank.surface.triangles.len(),
                edges.len()
            )));
        }
    }
    Ok(())
}

/// `info.error_estimate_pct`: empty (no estimate) or one entry per mode,
/// each finite and ≥ 0 when present.
fn check_error_estimates(bank: &ModeBank) -> Result<(), BankError> {
    let estimates = &bank.info.error_estimate_pct;
    let n = bank.frequencies_hz.len();
    if !estimates.is_empty() && estimates.len() != n {
        return Err(BankError::Inconsistent(format!(
            "solve_info.error_estimate_pct has {} entries but frequencies_hz has {n}",
            estimates.len()
        )));
    }
    for (i, e) in estimates.iter().enumerate() {
        if let Some(e) = *e {
            if !(e.is_finite() && e >= 0.0) {
                return Err(BankError::Inconsistent(format!(
                    "solve_info.error_estimate_pct[{i}] = {e} is not a finite number >= 0"
                )));
            }
        }
    }
    Ok(())
}

/// Fails on the first NaN/infinite value of `values`, named `field[i]`.
pub(crate) fn check_finite(field: &str, values: impl IntoIterator<Item = f64>) -> Result<(), BankError> {
    match values.into_iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((i, value)) => Err(BankError::NonFinite { field: format!("{field}[{i}]"), value }),
        None => Ok(()),
    }
}

fn check_nonnegative(field: &str, values: &[f64]) -> Result<(), BankError> {
    check_finite(field, values.iter().copied())?;
    match values.iter().enumerate().find(|(_, &v)| v < 0.0) {
        Some((i, &value)) => {
            Err(BankError::OutOfRange { field: format!("{field}[{i}]"), value, rule: "must be ≥ 0".into() })
        }
        None => Ok(()),
    }
}

fn check_frequencies(freqs: &[f64]) -> Result<(), BankError> {
    check_finite("frequencies_hz", freqs.iter().copied())?;
    if let Some((i, &value)) = freqs.iter().enumerate().find(|(_, &f)| f <= 0.0) {
        return Err(BankError::OutOfRange {
            field: format!("frequencies_hz[{i}]"),
            value,
            rule: "elastic modes have frequency > 0".into(),
        });
    }
    match freqs.windows(2).position(|w| w[1] < w[0]) {
        Some(i) => Err(BankError::NotAscending { index: i + 1, value: freqs[i + 1], previous: freqs[i] }),
        None => Ok(()),
    }
}

fn check_damping(bank: &ModeBank) -> Result<(), BankError> {
    check_nonnegative("damping_ratios", &bank.damping_ratios)?;
    check_nonnegative("decay_rates", &bank.decay_rates)?;
    for (i, &f) in bank.frequencies_hz.iter().enumerate() {
        let (ratio, rate) = (bank.damping_ratios[i], bank.decay_rates[i]);
        let expected = ratio * 2.0 * PI * f;
        if (rate - expected).abs() > DAMPING_RTOL * expected.abs().max(rate.abs()) {
            return Err(BankError::Inconsistent(format!(
                "decay_rates[{i}] = {rate} 1/s but damping_ratios[{i}] = {ratio} at {f} Hz gives d = ξω = {expected} 1/s"
            )));
        }
    }
    Ok(())
}

fn check_shapes(bank: &ModeBank) -> Result<(), BankError> {
    let s = bank.surface.positions.len().max(1);
    // One branch-free (vectorized) pass; the position only on failure.
    if bank.shapes.iter().fold(true, |ok, v| ok & v.is_finite()) {
        return Ok(());
    }
    match bank.shapes.iter().position(|v| !v.is_finite()) {
        Some(k) => Err(BankError::NonFinite {
            field: format!("shapes[mode {}, surface node {}, component {}]", k / 3 / s, (k / 3) % s, k % 3),
            value: f64::from(bank.shapes[k]),
        }),
        None => Ok(()),
    }
}

fn check_indices<'a>(
    field: &str,
    rows: impl IntoIterator<Item = &'a [usize; 3]>,
    count: usize,
) -> Result<(), BankError> {
    for (t, row) in rows.into_iter().enumerate() {
        if let Some(c) = row.iter().position(|&v| v >= count) {
            return Err(BankError::BadIndex {
                field: format!("{field}[{t}][{c}]"),
                value: row[c] as i128,
                count,
            });
        }
    }
    Ok(())
}

fn check_surface(surface: &Surface) -> Result<(), BankError> {
    check_finite("surface_positions", surface.positions.iter().flatten().copied())?;
    let s = surface.positions.len();
    check_indices("surface_triangles", &surface.triangles, s)?;
    if let Some(edges) = &surface.triangle_edge_nodes {
        check_indices("surface_triangle_edge_nodes", edges, s)?;
    }
    Ok(())
}

/// Checks that `material` is physically possible: E, ρ > 0, −1 < ν < 0.5,
/// α, β ≥ 0, all finite.
pub(crate) fn check_material(m: &Material) -> Result<(), BankError> {
    let values = [
        ("youngs_pa", m.youngs_pa),
        ("poisson", m.poisson),
        ("density_kg_m3", m.density_kg_m3),
        ("alpha", m.alpha),
        ("beta", m.beta),
    ];
    if let Some((name, v)) = values.iter().find(|(_, v)| !v.is_finite()) {
        return Err(BankError::InvalidMaterial(format!("{name} = {v} is not finite")));
    }
    let rule = if m.youngs_pa <= 0.0 {
        Some(format!("youngs_pa = {} must be > 0", m.youngs_pa))
    } else if m.density_kg_m3 <= 0.0 {
        Some(format!("density_kg_m3 = {} must be > 0", m.density_kg_m3))
    } else if !(m.poisson > -1.0 && m.poisson < 0.5) {
        Some(format!("poisson = {} must be in (-1, 0.5)", m.poisson))
    } else if m.alpha < 0.0 || m.beta < 0.0 {
        Some(format!("Rayleigh alpha = {} and beta = {} must be ≥ 0", m.alpha, m.beta))
    } else {
        None
    };
    rule.map_or(Ok(()), |r| Err(BankError::InvalidMaterial(r)))
}

fn check_mass(m: &MassProperties) -> Result<(), BankError> {
    check_finite("center_of_mass_m", m.center_of_mass_m)?;
    check_finite("inertia_kg_m2", m.inertia_kg_m2.iter().flatten().copied())?;
    for (field, value) in [("volume_m3", m.volume_m3), ("mass_kg", m.mass_kg)] {
        if !value.is_finite() {
            return Err(BankError::NonFinite { field: field.into(), value });
        }
        if value < 0.0 {
            return Err(BankError::OutOfRange { field: field.into(), value, rule: "must be ≥ 0".into() });
        }
    }
    Ok(())
}
