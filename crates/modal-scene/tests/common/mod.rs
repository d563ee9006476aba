//! In-memory mode banks for scene tests: real generated surfaces and FEM mass
//! properties, with a few synthetic modes at chosen frequencies.

#![allow(dead_code)]

use modal_bank::ModeBank;
use modal_fem::Material;
use modal_mesh::TetMesh;

/// A stand-in bank on `mesh` (see `modal_scene::stand_in`).
pub fn bank_on(mesh: &TetMesh, material: Material, freqs_hz: &[f64]) -> ModeBank {
    modal_scene::stand_in::synthetic_bank(mesh, material, freqs_hz)
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

/// Serves a 6 cm glass bowl (4 mm wall, modes 900/2100 Hz) as "bowl" and a
/// steel ball of radius `ball_radius_m` (mode 4 kHz) as "sphere".
pub fn bowl_and_ball(ball_radius_m: f64) -> modal_scene::InMemoryProvider {
    let glass = Material::preset("glass").expect("glass");
    let bowl = modal_mesh::generate::bowl(BOWL_RADIUS_M, 0.004, 0.008, 1).expect("bowl mesh");
    let mut p = modal_scene::InMemoryProvider::new();
    p.insert("bowl", bank_on(&bowl, glass, &[900.0, 2100.0]));
    p.insert("sphere", ball(ball_radius_m, &[4000.0]));
    p
}

/// Radius of the bowl of [`bowl_and_ball`] [m].
pub const BOWL_RADIUS_M: f64 = 0.06;

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

/// Hann-windowed magnitude spectrum of `n` samples from the onset of `y`
/// (first sample above 1 % of the peak), for checking which modes ring.
pub struct Spectrum {
    magnitudes: Vec<f64>,
    bin_hz: f64,
}

impl Spectrum {
    /// The spectrum of `y[onset .. onset + n]` at `sample_rate` (Hz).
    pub fn after_onset(y: &[f32], n: usize, sample_rate: f64) -> Self {
        let start = onset(y, 1e-2).expect("sound");
        Spectrum { magnitudes: spectrum(&y[start..start + n]), bin_hz: sample_rate / n as f64 }
    }

    /// Largest magnitude within ±2 bins of `f` (Hz).
    pub fn level(&self, f: f64) -> f64 {
        let k = (f / self.bin_hz).round() as usize;
        self.magnitudes[k - 2..=k + 2].iter().cloned().fold(0.0, f64::max)
    }

    /// Median magnitude: the noise floor the peaks are compared with.
    pub fn median(&self) -> f64 {
        let mut s = self.magnitudes.clone();
        s.sort_by(f64::total_cmp);
        s[s.len() / 2]
    }
}
