//! Stand-in mode banks for tests, benchmarks and examples: a real surface and
//! real FEM mass properties of a tet mesh, with synthetic modes at chosen
//! frequencies (no eigen solve). Mode `i` has the smooth, nowhere-trivial
//! shape `φ_i(x) = (cos(k_i x + i), sin(k_i y + 1), cos(k_i z + 2)) / √m`,
//! `k_i = 40 + 17 i` [1/m], about the size of a mass-normalized mode.

use modal_bank::{ModeBank, SolveInfo};
use modal_fem::{mass_properties, Material};
use modal_mesh::{boundary_surface, TetMesh};

/// A bank on `mesh` with modes at `freqs_hz`, damped by `material`.
pub fn synthetic_bank(mesh: &TetMesh, material: Material, freqs_hz: &[f64]) -> ModeBank {
    let surface = boundary_surface(mesh);
    let mass = mass_properties(mesh, material.density_kg_m3);
    let norm = 1.0 / mass.mass_kg.sqrt();
    let mut shapes = Vec::with_capacity(freqs_hz.len() * surface.positions.len() * 3);
    for i in 0..freqs_hz.len() {
        let k = 40.0 + 17.0 * i as f64;
        for p in &surface.positions {
            shapes.push((norm * (k * p[0] + i as f64).cos()) as f32);
            shapes.push((norm * (k * p[1] + 1.0).sin()) as f32);
            shapes.push((norm * (k * p[2] + 2.0).cos()) as f32);
        }
    }
    let omega: Vec<f64> = freqs_hz.iter().map(|f| 2.0 * std::f64::consts::PI * f).collect();
    ModeBank {
        frequencies_hz: freqs_hz.to_vec(),
        damping_ratios: omega.iter().map(|w| material.damping_ratio(*w)).collect(),
        decay_rates: omega.iter().map(|w| material.decay_rate(*w)).collect(),
        residuals: vec![0.0; freqs_hz.len()],
        shapes,
        surface,
        material,
        mass,
        info: SolveInfo { order: mesh.order(), ..Default::default() },
    }
}
