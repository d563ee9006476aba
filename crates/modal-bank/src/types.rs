//! The in-memory mode bank.

use modal_fem::{MassProperties, Material};
use modal_mesh::Surface;
use serde::{Deserialize, Serialize};

/// How the modes were computed (what `modal info` reports).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
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
    /// Hex digest of every input that determines the result (cache key).
    pub input_hash: String,
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
}
