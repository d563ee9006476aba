//! Synthetic mode banks for benchmarks and stress tests (no FEM solve).
//!
//! `n` modes log-spaced between `f_min` and `f_max`
//! (`f_k = f_min (f_max/f_min)^{k/(n−1)}`), Rayleigh damping of a material
//! (`d = (α + β ω²)/2`, `ξ = d/ω`, the convention of `modal-fem`), and
//! seeded pseudo-random mass-normalized shapes, uniform in [−1, 1] 1/√kg
//! per component, on the 8 corners of a box surface (12 triangles). The
//! random generator is SplitMix64, so a seed gives the same bank on every
//! machine.

use modal_bank::{ModeBank, SolveInfo};
use modal_fem::{MassProperties, Material};
use modal_mesh::Surface;
use std::f64::consts::PI;

/// SplitMix64: a tiny, well-mixed, seedable generator.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> SplitMix64 {
        SplitMix64(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
}

/// Recipe of a synthetic bank (module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct SyntheticBank {
    /// Number of modes.
    pub modes: usize,
    /// Lowest frequency \[Hz\].
    pub f_min_hz: f64,
    /// Highest frequency \[Hz\].
    pub f_max_hz: f64,
    /// Material: density for the mass, Rayleigh α \[1/s\] and β \[s\] for damping.
    pub material: Material,
    /// Box edge lengths \[m\].
    pub size_m: [f64; 3],
    /// Seed of the shapes.
    pub seed: u64,
}

impl SyntheticBank {
    /// `modes` modes log-spaced over 50 Hz – 20 kHz with the damping of the
    /// material preset `name` (e.g. `"steel"`: α = 5/s, β = 3e-8 s), on a
    /// 0.2 × 0.1 × 0.05 m box, seed 1.
    ///
    /// # Panics
    /// When `name` is not a preset of `modal_fem::Material` (a caller bug).
    pub fn preset(name: &str, modes: usize) -> SyntheticBank {
        SyntheticBank {
            modes,
            f_min_hz: 50.0,
            f_max_hz: 20_000.0,
            material: Material::preset(name).expect("a material preset name"),
            size_m: [0.2, 0.1, 0.05],
            seed: 1,
        }
    }

    /// Frequencies \[Hz\] of the bank, ascending.
    pub fn frequencies(&self) -> Vec<f64> {
        let n = self.modes;
        let ratio = self.f_max_hz / self.f_min_hz;
        (0..n)
            .map(
                |k| {
                    if n == 1 {
                        self.f_min_hz
                    } else {
                        self.f_min_hz * ratio.powf(k as f64 / (n - 1) as f64)
                    }
                },
            )
            .collect()
    }

    /// Builds the bank.
    pub fn build(&self) -> ModeBank {
        let surface = box_surface(self.size_m);
        let frequencies_hz = self.frequencies();
        let omega = |f: f64| 2.0 * PI * f;
        let decay_rates = frequencies_hz.iter().map(|&f| self.material.decay_rate(omega(f))).collect();
        let damping_ratios = frequencies_hz.iter().map(|&f| self.material.damping_ratio(omega(f))).collect();
        let mut rng = SplitMix64::new(self.seed);
        let shapes =
            (0..self.modes * surface.positions.len() * 3).map(|_| rng.range(-1.0, 1.0) as f32).collect();
        let [a, b, c] = self.size_m;
        let mass = a * b * c * self.material.density_kg_m3;
        let inertia = [(b * b + c * c), (a * a + c * c), (a * a + b * b)].map(|x| mass * x / 12.0);
        ModeBank {
            residuals: vec![0.0; self.modes],
            frequencies_hz,
            decay_rates,
            damping_ratios,
            shapes,
            surface,
            material: self.material.clone(),
            mass: MassProperties {
                volume_m3: a * b * c,
                mass_kg: mass,
                center_of_mass_m: [a / 2.0, b / 2.0, c / 2.0],
                inertia_kg_m2: [[inertia[0], 0.0, 0.0], [0.0, inertia[1], 0.0], [0.0, 0.0, inertia[2]]],
            },
            info: SolveInfo::default(),
        }
    }
}

/// `n` seeded gains uniform in [−1, 1] (for `OutputGain::PerMode`).
pub fn random_gains(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = SplitMix64::new(seed ^ 0x5EED_6A1E);
    (0..n).map(|_| rng.range(-1.0, 1.0)).collect()
}

/// A closed box surface `[0, lx] × [0, ly] × [0, lz]`: 8 corner nodes and
/// 12 triangles wound counter-clockwise seen from outside.
pub fn box_surface(l: [f64; 3]) -> Surface {
    let positions = (0..8)
        .map(|k| {
            [
                if k & 1 == 1 { l[0] } else { 0.0 },
                if k & 2 == 2 { l[1] } else { 0.0 },
                if k & 4 == 4 { l[2] } else { 0.0 },
            ]
        })
        .collect();
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let triangles = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    Surface { node_ids: (0..8).collect(), positions, triangles, triangle_edge_nodes: None }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_spacing_and_rayleigh_damping() {
        let s = SyntheticBank::preset("steel", 5);
        let b = s.build();
        assert_eq!(b.mode_count(), 5);
        assert!((b.frequencies_hz[0] - 50.0).abs() < 1e-12 && (b.frequencies_hz[4] - 20_000.0).abs() < 1e-9);
        // Ratio between neighbours is constant: 400^(1/4).
        let r = 400f64.powf(0.25);
        assert!(b.frequencies_hz.windows(2).all(|w| (w[1] / w[0] - r).abs() < 1e-12));
        // Steel: d = (5 + 3e-8 ω²)/2.
        let w = 2.0 * PI * 20_000.0;
        assert!((b.decay_rates[4] - (5.0 + 3e-8 * w * w) / 2.0).abs() < 1e-9);
        assert!((b.damping_ratios[4] - b.decay_rates[4] / w).abs() < 1e-15);
        assert_eq!(b.shapes.len(), 5 * 8 * 3);
        assert!(b.shapes.iter().all(|x| (-1.0..1.0).contains(x)));
        assert_eq!(s.build(), b, "seeded: deterministic");
        let mut other = s.clone();
        other.seed = 2;
        assert_ne!(other.build().shapes, b.shapes);
    }
}
