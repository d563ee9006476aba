//! Per-mode acoustic transfer stored with a bank (format version 2).
//!
//! Mode `i` vibrating harmonically with unit modal velocity amplitude
//! radiates, outside the sphere of radius `fit_radius_m / 2` about
//! `centre_m` (time convention `e^{−iωt}`),
//!
//! `p(x) = Σ_{l ≤ L} Σ_{|m| ≤ l} a_lm h_l(k r) Y_l^m(x̂)` [Pa],
//!
//! `r = |x − c|`, `h_l` the spherical Hankel function of the first kind,
//! `Y_l^m` the orthonormal complex spherical harmonics with the
//! Condon–Shortley phase, `a_lm` stored at index `l² + l + m`. Written by
//! `modal radiation --store` (crate `modal-radiation`, which evaluates it);
//! this crate only stores and validates it. The table is optional: banks
//! without it (and every version-1 bank) load as before.

use crate::BankError;

/// Largest fit radius accepted, in body radii about the centre.
pub const MAX_FIT_RADII: f64 = 1000.0;
/// Largest relative distance accepted between a stored wavenumber's
/// frequency `kc/2π` and its mode's (the solver groups modes within 10⁻³).
pub const WAVENUMBER_TOL: f64 = 0.01;

/// The stored far-field representation of some of a bank's modes.
#[derive(Clone, Debug, PartialEq)]
pub struct RadiationTable {
    /// Expansion centre (the centre of mass) [m].
    pub centre_m: [f64; 3],
    /// Radius the expansions were fitted at (twice the body's radius about
    /// the centre); accurate to `tolerance` for `r ≥ fit_radius_m` [m].
    pub fit_radius_m: f64,
    /// Air density used [kg/m³].
    pub air_density_kg_m3: f64,
    /// Speed of sound used [m/s].
    pub sound_speed_m_s: f64,
    /// Relative RMS truncation error at `fit_radius_m`.
    pub tolerance: f64,
    /// One entry per radiating mode, ascending mode index.
    pub modes: Vec<ModeTransfer>,
}

/// The stored radiation of one mode.
#[derive(Clone, Debug, PartialEq)]
pub struct ModeTransfer {
    /// Mode index in the bank.
    pub mode: usize,
    /// Wavenumber the expansion was solved at [1/m].
    pub wavenumber: f64,
    /// Highest degree L.
    pub order: usize,
    /// `a_lm` as `[re, im]` at `l² + l + m`, `(L+1)²` values [Pa].
    pub coefficients: Vec<[f64; 2]>,
    /// Radiated power at unit modal velocity amplitude [W].
    pub power_w: f64,
    /// Radiation efficiency `P / (½ρ₀c∫|v_n|²dS)`.
    pub efficiency: f64,
}

impl RadiationTable {
    /// The entry of mode `mode`, if stored.
    pub fn mode(&self, mode: usize) -> Option<&ModeTransfer> {
        self.modes.binary_search_by_key(&mode, |m| m.mode).ok().map(|i| &self.modes[i])
    }

    /// [`RadiationTable::validate`], then the table against the bank it is
    /// stored with: the centre within the surface's bounding box, the fit
    /// sphere enclosing the surface (and at most [`MAX_FIT_RADII`] body radii),
    /// and each wavenumber within [`WAVENUMBER_TOL`] of its mode's frequency.
    /// A table that passes the first check alone (a crafted or damaged file
    /// with a valid checksum, a centre at 1e300 m) gave NaN gains later.
    pub fn validate_for(&self, bank: &crate::ModeBank) -> Result<(), BankError> {
        self.validate(bank.mode_count())?;
        let bad = |field: String, value: f64, rule: &str| {
            Err(BankError::OutOfRange { field, value, rule: rule.into() })
        };
        let points = &bank.surface.positions;
        if !points.is_empty() {
            let (lo, hi) = modal_mesh::bounding_box(points.iter().copied());
            let slack = 1e-6 * modal_mesh::bounding_diagonal(points);
            for q in 0..3 {
                let c = self.centre_m[q];
                if c < lo[q] - slack || c > hi[q] + slack {
                    return bad(
                        format!("radiation.centre_m[{q}]"),
                        c,
                        "must lie within the surface's bounding box",
                    );
                }
            }
            let body_radius = points
                .iter()
                .map(|p| (0..3).map(|q| (p[q] - self.centre_m[q]).powi(2)).sum::<f64>().sqrt())
                .fold(0.0, f64::max);
            let fit = self.fit_radius_m;
            if fit < body_radius * (1.0 - 1e-9) || fit > MAX_FIT_RADII * body_radius {
                return bad(
                    "radiation.fit_radius_m".into(),
                    fit,
                    "must enclose the surface, within 1000 body radii of the centre",
                );
            }
        }
        for (i, m) in self.modes.iter().enumerate() {
            let f = m.wavenumber * self.sound_speed_m_s / (2.0 * std::f64::consts::PI);
            let mode_hz = bank.frequencies_hz[m.mode];
            if (f - mode_hz).abs() > WAVENUMBER_TOL * mode_hz {
                return bad(
                    format!("radiation_wavenumbers[{i}]"),
                    m.wavenumber,
                    "must be the wavenumber of its mode's frequency (within 1 %)",
                );
            }
        }
        Ok(())
    }

    /// Checks the table against a bank with `mode_count` modes: entries
    /// ascending and unique, modes in range, `(L+1)²` coefficients, finite
    /// values, positive wavenumbers, air and radius.
    pub fn validate(&self, mode_count: usize) -> Result<(), BankError> {
        let bad = |field: String, value: f64, rule: &str| {
            Err(BankError::OutOfRange { field, value, rule: rule.into() })
        };
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !self.centre_m.iter().all(|c| c.is_finite()) {
            return bad("radiation.centre_m".into(), f64::NAN, "must be finite");
        }
        for (name, v) in [
            ("radiation.fit_radius_m", self.fit_radius_m),
            ("radiation.air_density_kg_m3", self.air_density_kg_m3),
            ("radiation.sound_speed_m_s", self.sound_speed_m_s),
            ("radiation.tolerance", self.tolerance),
        ] {
            if !positive(v) {
                return bad(name.into(), v, "must be finite and positive");
            }
        }
        let mut last = None;
        for (i, m) in self.modes.iter().enumerate() {
            if m.mode >= mode_count {
                return bad(format!("radiation_modes[{i}]"), m.mode as f64, "must name a mode of the bank");
            }
            if last.is_some_and(|l| m.mode <= l) {
                return bad(format!("radiation_modes[{i}]"), m.mode as f64, "must be strictly ascending");
            }
            last = Some(m.mode);
            if !positive(m.wavenumber) {
                return bad(
                    format!("radiation_wavenumbers[{i}]"),
                    m.wavenumber,
                    "must be finite and positive",
                );
            }
            if m.coefficients.len() != (m.order + 1) * (m.order + 1) {
                return bad(format!("radiation_orders[{i}]"), m.order as f64, "needs (L+1)² coefficients");
            }
            if m.coefficients.iter().flatten().any(|c| !c.is_finite()) {
                return bad(format!("radiation_coefficients of mode {}", m.mode), f64::NAN, "must be finite");
            }
            for (name, v) in [("radiation_power_w", m.power_w), ("radiation_efficiency", m.efficiency)] {
                if !(v.is_finite() && v >= 0.0) {
                    return bad(format!("{name}[{i}]"), v, "must be finite and ≥ 0");
                }
            }
        }
        Ok(())
    }
}
