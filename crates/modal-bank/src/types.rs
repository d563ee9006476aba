//! The in-memory mode bank.

use modal_fem::{MassProperties, Material};
use modal_mesh::Surface;
use serde::{Deserialize, Serialize};

/// How the modes were computed (what `modal info` reports).
///
/// Stored as JSON in the bank metadata key `solve_info`; fields missing from
/// the JSON read as their defaults.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(default)]
pub struct SolveInfo {
    /// Element order used, 1 or 2.
    pub order: u8,
    /// Number of free degrees of freedom of the FEM system.
    pub dofs: usize,
    /// Rigid-body modes deflated (6 per free connected part).
    pub rigid_modes_removed: usize,
    /// Sylvester inertia check: eigenvalues below the check shift expected
    /// from the inertia count ...
    pub inertia_expected: usize,
    /// ... and the number the solver found.
    pub inertia_found: usize,
    /// Seconds spent assembling K and M.
    pub assemble_s: f64,
    /// Seconds spent in sparse factorizations.
    pub factor_s: f64,
    /// Seconds spent in the eigen iteration.
    pub solve_s: f64,
    /// Hex digest of every input that determines the result: the cache key
    /// the bank is stored under (see `BankCache`). Retuned banks carry
    /// `retuned:<hex>` instead, so they never match a fresh solve's key.
    pub input_hash: String,
    /// Estimated discretization error of each mode's frequency, in percent of
    /// the frequency: `|f − f_converged| / f_converged · 100` as estimated by
    /// `modal-precompute` (module `accuracy`), one entry per mode; `None`
    /// where a mode could not be matched between the discretization levels.
    /// Empty when no estimate was made (banks from before the field, banks
    /// of prescribed tet meshes). Stored additively in the `solve_info` JSON
    /// (omitted when empty, so older banks keep their bytes); a relative
    /// error is invariant under the exact scalings of [`crate::retune`].
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub error_estimate_pct: Vec<Option<f64>>,
    /// How `error_estimate_pct` was obtained, one line (e.g. the levels and
    /// the convergence order used); empty when no estimate was made.
    #[serde(skip_serializing_if = "String::is_empty")]
    pub error_estimate_method: String,
}

/// Elastic modes of one object, restricted to its surface.
///
/// Mode `i` has undamped natural frequency `frequencies_hz[i]` (ascending),
/// Rayleigh decay rate `decay_rates[i]` [1/s] and damping ratio
/// `damping_ratios[i]`. Its mass-normalized shape (`φᵀ M φ = 1`, units
/// 1/√kg) at surface node `k` is
/// `shapes[(i * n_surface + k) * 3 .. + 3]`.
#[derive(Clone, Debug, PartialEq)]
pub struct ModeBank {
    /// Undamped natural frequencies √λ/2π [Hz], ascending.
    pub frequencies_hz: Vec<f64>,
    /// Damping ratios ξ [-].
    pub damping_ratios: Vec<f64>,
    /// Decay rates d = (α + β ω²)/2 [1/s].
    pub decay_rates: Vec<f64>,
    /// Relative residuals ‖Kw − λMw‖ / (λ‖Mw‖) of the solve.
    pub residuals: Vec<f64>,
    /// Mode shapes at surface nodes, mode-major, xyz interleaved [1/√kg].
    pub shapes: Vec<f32>,
    /// The surface the shapes live on.
    pub surface: Surface,
    /// The material the modes were computed (or retuned) for.
    pub material: Material,
    /// Mass properties of the solid.
    pub mass: MassProperties,
    /// Provenance of the solve.
    pub info: SolveInfo,
}

impl ModeBank {
    /// Number of modes.
    pub fn mode_count(&self) -> usize {
        self.frequencies_hz.len()
    }

    /// Number of surface nodes.
    pub fn surface_node_count(&self) -> usize {
        self.surface.positions.len()
    }

    /// Shape of mode `mode` at surface node `node` [1/√kg].
    pub fn shape_at(&self, mode: usize, node: usize) -> [f32; 3] {
        let base = (mode * self.surface_node_count() + node) * 3;
        [self.shapes[base], self.shapes[base + 1], self.shapes[base + 2]]
    }

    /// Time for mode `i` to decay by 60 dB, `ln(1000)/d` [s]; infinite when
    /// the decay rate `d` is 0. Panics if `i >= mode_count()`.
    pub fn t60_s(&self, i: usize) -> f64 {
        crate::damping::t60_s(self.decay_rates[i])
    }

    /// Damped natural frequency of mode `i`, `f √(1 − ξ²)` [Hz]; 0 when the
    /// mode is critically damped or overdamped (ξ ≥ 1). Panics if
    /// `i >= mode_count()`.
    pub fn damped_frequency_hz(&self, i: usize) -> f64 {
        crate::damping::damped_frequency_hz(self.frequencies_hz[i], self.damping_ratios[i])
    }

    /// Recomputes `damping_ratios` and `decay_rates` from the frequencies and
    /// the material's Rayleigh α, β (see [`crate::rayleigh`]).
    pub fn recompute_damping(&mut self) {
        let (alpha, beta) = (self.material.alpha, self.material.beta);
        let (ratios, rates) = self.frequencies_hz.iter().map(|&f| crate::rayleigh(alpha, beta, f)).unzip();
        self.damping_ratios = ratios;
        self.decay_rates = rates;
    }
}
