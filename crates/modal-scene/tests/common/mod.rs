//! In-memory mode banks for scene tests: real generated surfaces and FEM mass
//! properties, with a few synthetic modes at chosen frequencies.

#![allow(dead_code)]

use modal_bank::{ModeBank, SolveInfo};
use modal_fem::{mass_properties, Material};
use modal_mesh::{boundary_surface, TetMesh};

/// A bank on `mesh` with modes at `freqs_hz` for `material`. Mode `i` has the
/// smooth, nowhere-trivial shape `φ_i(x) = (cos(k_i x + i), sin(k_i y + 1),
/// cos(k_i z + 2)) / √m` with `k_i` a few waves across the body, roughly the
/// size of a mass-normalized elastic mode.
pub fn bank_on(mesh: &TetMesh, material: Material, freqs_hz: &[f64]) -> ModeBank {
    let surface = boundary_surface(mesh);
    let mass = mass_properties(mesh, material.density_kg_m3);
    let n = surface.positions.len();
    let norm = 1.0 / mass.mass_kg.sqrt();
    let mut shapes = Vec::with_capacity(freqs_hz.len() * n * 3);
    for (i, _) in freqs_hz.iter().enumerate() {
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
        info: SolveInfo { order: 1, ..Default::default() },
    }
}

/// A steel ball of radius `r` with modes at `freqs_hz`.
pub fn ball(r: f64, freqs_hz: &[f64]) -> ModeBank {
    ball_of(r, freqs_hz, Material::preset("steel").expect("steel"))
}

/// A ball of radius `r` and `material` with modes at `freqs_hz`.
pub fn ball_of(r: f64, freqs_hz: &[f64], material: Material) -> ModeBank {
    let mesh = modal_mesh::generate::sphere(r, r / 2.0, 1).expect("sphere mesh");
    bank_on(&mesh, material, freqs_hz)
}

/// A wooden box of `size` with modes at `freqs_hz`.
pub fn block(size: [f64; 3], freqs_hz: &[f64]) -> ModeBank {
    let mesh = modal_mesh::generate::box_mesh(size, [2, 2, 2]);
    bank_on(&mesh, Material::preset("wood").expect("wood"), freqs_hz)
}

/// Sample index of the first |x| above `fraction` of the peak.
pub fn onset(x: &[f32], fraction: f32) -> Option<usize> {
    let peak = x.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    x.iter().position(|v| v.abs() > fraction * peak)
}

/// Peak |x|.
pub fn peak(x: &[f32]) -> f32 {
    x.iter().fold(0.0f32, |m, v| m.max(v.abs()))
}

/// Magnitude spectrum of `x` (Hann window), bin width fs / len.
pub fn spectrum(x: &[f32]) -> Vec<f64> {
    let n = x.len();
    let mut planner = realfft::RealFftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(n);
    let mut input: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(i, v)| *v as f64 * (0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos()))
        .collect();
    let mut out = fft.make_output_vec();
    fft.process(&mut input, &mut out).expect("fft");
    out.iter().map(|c| c.norm()).collect()
}
