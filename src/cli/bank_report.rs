//! The `--json` contract of `precompute`, `info` and `retune`, and the human
//! table that mirrors it.

use std::f64::consts::PI;
use std::io::Write;

use modal_bank::ModeBank;
use serde::Serialize;

/// One elastic mode as printed by `--json`.
#[derive(Debug, Serialize)]
pub struct ModeJson {
    pub frequency_hz: f64,
    pub damped_frequency_hz: f64,
    pub damping_ratio: f64,
    pub decay_rate: f64,
    pub residual: f64,
    /// Seconds until the mode decayed by 60 dB (null when undamped).
    pub t60_s: Option<f64>,
    /// Radiated power at unit modal velocity amplitude [W] (null: not stored
    /// in the bank; `modal radiation BANK --store OUT` computes it).
    pub radiated_power_w: Option<f64>,
    /// Radiation efficiency P / (½ρ₀c∫|v_n|²dS) (null: not stored).
    pub radiation_efficiency: Option<f64>,
    /// Estimated discretization error of `frequency_hz` [% of it] (null: no
    /// estimate — a prescribed tet mesh, an older bank, or a mode not matched
    /// between the discretization levels). A contract: see docs/bank-format.md.
    pub error_estimate_pct: Option<f64>,
}

/// Sylvester inertia count: eigenvalues below the check shift.
#[derive(Debug, Serialize)]
pub struct InertiaJson {
    pub expected: usize,
    pub found: usize,
}

/// Seconds per phase of the original solve.
#[derive(Debug, Serialize)]
pub struct TimingsJson {
    pub assemble: f64,
    pub factor: f64,
    pub solve: f64,
}

/// The object `precompute --json` and `info --json` print.
#[derive(Debug, Serialize)]
pub struct BankJson {
    pub modes: Vec<ModeJson>,
    pub dofs: usize,
    pub order: u8,
    pub mass_kg: f64,
    pub rigid_modes_removed: usize,
    pub inertia_check: InertiaJson,
    pub cached: bool,
    pub timings_s: TimingsJson,
    pub surface_nodes: usize,
    pub surface_triangles: usize,
    pub material: modal_fem::Material,
    pub input_hash: String,
    /// How the per-mode `error_estimate_pct` was obtained (null: no estimate).
    pub error_estimate_method: Option<String>,
}

impl BankJson {
    /// Describes `bank`; `cached` says whether it was served from the cache.
    pub fn new(bank: &ModeBank, cached: bool) -> Self {
        let modes = (0..bank.mode_count()).map(|i| mode_json(bank, i)).collect();
        let info = &bank.info;
        BankJson {
            modes,
            dofs: info.dofs,
            order: info.order,
            mass_kg: bank.mass.mass_kg,
            rigid_modes_removed: info.rigid_modes_removed,
            inertia_check: InertiaJson { expected: info.inertia_expected, found: info.inertia_found },
            cached,
            timings_s: TimingsJson { assemble: info.assemble_s, factor: info.factor_s, solve: info.solve_s },
            surface_nodes: bank.surface_node_count(),
            surface_triangles: bank.surface.triangles.len(),
            material: bank.material.clone(),
            input_hash: info.input_hash.clone(),
            error_estimate_method: (!info.error_estimate_method.is_empty())
                .then(|| info.error_estimate_method.clone()),
        }
    }

    /// Fills each mode's radiated power and efficiency from a stored table.
    pub fn with_radiation(mut self, table: Option<&modal_bank::RadiationTable>) -> Self {
        if let Some(table) = table {
            for (i, mode) in self.modes.iter_mut().enumerate() {
                if let Some(t) = table.mode(i) {
                    mode.radiated_power_w = Some(t.power_w);
                    mode.radiation_efficiency = Some(t.efficiency);
                }
            }
        }
        self
    }

    /// Writes the human-readable table.
    pub fn write_table(&self, out: &mut impl Write) -> std::io::Result<()> {
        let m = &self.material;
        writeln!(
            out,
            "{} modes  |  {} DOF, order {}  |  mass {:.6} kg  |  {} rigid modes removed  |  inertia check {}/{}{}",
            self.modes.len(),
            self.dofs,
            self.order,
            self.mass_kg,
            self.rigid_modes_removed,
            self.inertia_check.found,
            self.inertia_check.expected,
            if self.cached { "  |  from cache" } else { "" },
        )?;
        writeln!(
            out,
            "material {}: E = {:.4e} Pa, nu = {}, rho = {} kg/m^3, alpha = {} 1/s, beta = {:e} s",
            m.name.as_deref().unwrap_or("custom"),
            m.youngs_pa,
            m.poisson,
            m.density_kg_m3,
            m.alpha,
            m.beta
        )?;
        let radiation = self.modes.iter().any(|m| m.radiated_power_w.is_some());
        let estimated = self.modes.iter().any(|m| m.error_estimate_pct.is_some());
        write!(
            out,
            "{:>5}  {:>14}  {:>13}  {:>11}  {:>10}",
            "mode", "frequency Hz", "damping ratio", "T60 s", "residual"
        )?;
        if estimated {
            write!(out, "  {:>8}", "error %")?;
        }
        if radiation {
            write!(out, "  {:>12}  {:>10}", "radiated W", "rad. eff.")?;
        }
        writeln!(out)?;
        for (i, mode) in self.modes.iter().enumerate() {
            let t60 = mode.t60_s.map_or("inf".to_string(), |t| format!("{t:.4}"));
            write!(
                out,
                "{:>5}  {:>14.3}  {:>13.3e}  {:>11}  {:>10.2e}",
                i, mode.frequency_hz, mode.damping_ratio, t60, mode.residual
            )?;
            if estimated {
                let e = mode.error_estimate_pct.map_or("-".to_string(), |e| format!("{e:.3}"));
                write!(out, "  {e:>8}")?;
            }
            if radiation {
                let p = mode.radiated_power_w.map_or("-".to_string(), |p| format!("{p:.3e}"));
                let e = mode.radiation_efficiency.map_or("-".to_string(), |e| format!("{e:.3e}"));
                write!(out, "  {p:>12}  {e:>10}")?;
            }
            writeln!(out)?;
        }
        match &self.error_estimate_method {
            Some(method) => {
                writeln!(out, "error %: estimated discretization error of the frequency ({method})")?
            }
            // A bank with no mode in its band has nothing to estimate.
            None if self.modes.is_empty() => {}
            None => writeln!(
                out,
                "error %: no estimate in this bank (prescribed tet mesh, --accuracy off or older bank)"
            )?,
        }
        let t = &self.timings_s;
        writeln!(
            out,
            "timings: assemble {:.3} s, factor {:.3} s, solve {:.3} s",
            t.assemble, t.factor, t.solve
        )
    }
}

fn mode_json(bank: &ModeBank, i: usize) -> ModeJson {
    let frequency_hz = bank.frequencies_hz[i];
    let damping_ratio = bank.damping_ratios[i];
    let decay_rate = bank.decay_rates[i];
    // ω_d = ω √(1 − ξ²); an overdamped mode does not oscillate.
    let damped_frequency_hz =
        if damping_ratio < 1.0 { frequency_hz * (1.0 - damping_ratio * damping_ratio).sqrt() } else { 0.0 };
    debug_assert!((2.0 * PI * frequency_hz).is_finite());
    ModeJson {
        frequency_hz,
        damped_frequency_hz,
        damping_ratio,
        decay_rate,
        residual: bank.residuals[i],
        t60_s: (decay_rate > 0.0).then(|| 1000f64.ln() / decay_rate),
        radiated_power_w: None,
        radiation_efficiency: None,
        error_estimate_pct: bank.info.error_estimate_pct.get(i).copied().flatten(),
    }
}
