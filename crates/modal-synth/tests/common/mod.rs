//! Synthetic in-memory banks and the closed-form response for tests.
#![allow(dead_code)]

use modal_bank::{ModeBank, SolveInfo};
use modal_fem::{MassProperties, Material};
use modal_mesh::Surface;
use std::f64::consts::PI;

/// A closed box surface `[0, lx] × [0, ly] × [0, lz]` (8 nodes, 12 outward triangles).
pub fn box_surface(l: [f64; 3]) -> Surface {
    let mut positions = Vec::new();
    for k in 0..8 {
        positions.push([
            if k & 1 == 1 { l[0] } else { 0.0 },
            if k & 2 == 2 { l[1] } else { 0.0 },
            if k & 4 == 4 { l[2] } else { 0.0 },
        ]);
    }
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let mut triangles = Vec::new();
    for q in quads {
        triangles.push([q[0], q[1], q[2]]);
        triangles.push([q[0], q[2], q[3]]);
    }
    Surface { node_ids: (0..8).collect(), positions, triangles, triangle_edge_nodes: None }
}

/// A bank on a 0.3 × 0.02 × 0.01 m box with the given undamped
/// frequencies [Hz] and decay rates [1/s], smooth pseudo-random shapes of
/// size ≈ 1/√kg.
pub fn bank(freqs: &[f64], decays: &[f64]) -> ModeBank {
    let surface = box_surface([0.3, 0.02, 0.01]);
    let n = surface.positions.len();
    let mut shapes = Vec::new();
    for i in 0..freqs.len() {
        for k in 0..n {
            let (a, b) = (i as f64, k as f64);
            shapes.push((1.3 * (1.7 * a + 2.3 * b + 0.4).sin()) as f32);
            shapes.push((1.1 * (0.9 * a - 1.3 * b + 1.0).cos()) as f32);
            shapes.push((1.7 * (2.9 * a + 0.7 * b + 2.0).sin()) as f32);
        }
    }
    let damping_ratios = freqs.iter().zip(decays).map(|(f, d)| d / (2.0 * PI * f)).collect();
    ModeBank {
        frequencies_hz: freqs.to_vec(),
        damping_ratios,
        decay_rates: decays.to_vec(),
        residuals: vec![0.0; freqs.len()],
        shapes,
        surface,
        material: Material {
            name: None,
            youngs_pa: 2e11,
            poisson: 0.3,
            density_kg_m3: 7850.0,
            alpha: 0.0,
            beta: 0.0,
        },
        mass: MassProperties {
            volume_m3: 6e-5,
            mass_kg: 0.471,
            center_of_mass_m: [0.15, 0.01, 0.005],
            inertia_kg_m2: [[0.0; 3]; 3],
        },
        info: SolveInfo::default(),
    }
}

/// A bank of `n` modes spread over 100 Hz .. 18 kHz with light damping.
pub fn many_modes(n: usize) -> ModeBank {
    let f: Vec<f64> = (0..n).map(|i| 100.0 + 17_900.0 * (i as f64 + 0.5) / n as f64).collect();
    let d: Vec<f64> = f.iter().map(|f| 1.0 + 1e-4 * f).collect();
    bank(&f, &d)
}

/// Interpolated shape of mode `i` at a point given by its triangle and barycentrics (linear).
pub fn shape_at(b: &ModeBank, i: usize, tri: usize, bary: [f64; 3]) -> [f64; 3] {
    let t = b.surface.triangles[tri];
    let mut s = [0.0; 3];
    for (c, &node) in t.iter().enumerate() {
        let v = b.shape_at(i, node);
        for k in 0..3 {
            s[k] += bary[c] * v[k] as f64;
        }
    }
    s
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Closed-form contact-mic velocity at the struck point (ideal impulse `j` at
/// time `t0`, mic normal `n`): `Σ g_i a_i e^{−d(t−t0)} (cos ω_d τ − d/ω_d sin ω_d τ)`.
pub fn closed_form(
    b: &ModeBank,
    tri: usize,
    bary: [f64; 3],
    n: [f64; 3],
    j: [f64; 3],
    t0: f64,
    t: f64,
) -> f64 {
    if t < t0 {
        return 0.0;
    }
    let tau = t - t0;
    (0..b.mode_count())
        .map(|i| {
            let phi = shape_at(b, i, tri, bary);
            let (g, a) = (dot(phi, n), dot(phi, j));
            let d = b.decay_rates[i];
            let wd = 2.0 * PI * b.frequencies_hz[i] * (1.0 - b.damping_ratios[i].powi(2)).sqrt();
            g * a * (-d * tau).exp() * ((wd * tau).cos() - d / wd * (wd * tau).sin())
        })
        .sum()
}

/// Largest |x|.
pub fn peak(x: &[f32]) -> f64 {
    x.iter().fold(0.0f64, |m, &v| m.max((v as f64).abs()))
}

/// Largest |a − b| (elementwise).
pub fn max_diff(a: &[f32], b: &[f32]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).fold(0.0f64, |m, (&x, &y)| m.max((x as f64 - y as f64).abs()))
}

/// Hann-windowed spectrum of `y` (windowed in place), bin k at k·fs/len.
pub fn hann_spectrum(y: &mut [f32]) -> Vec<realfft::num_complex::Complex<f32>> {
    let n = y.len();
    for (k, x) in y.iter_mut().enumerate() {
        *x *= (0.5 - 0.5 * (2.0 * PI * k as f64 / n as f64).cos()) as f32;
    }
    let fft = realfft::RealFftPlanner::<f32>::new().plan_fft_forward(n);
    let mut spec = fft.make_output_vec();
    fft.process(y, &mut spec).unwrap();
    spec
}

/// The loudest bin within ±20 bins of fractional bin `target`.
pub fn peak_bin_near(spec: &[realfft::num_complex::Complex<f32>], target: f64) -> usize {
    let centre = target.round() as usize;
    (centre.saturating_sub(20)..=(centre + 20).min(spec.len() - 1))
        .max_by(|&a, &b| spec[a].norm().total_cmp(&spec[b].norm()))
        .unwrap()
}
