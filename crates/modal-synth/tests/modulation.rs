//! Time-varying complex output weights (`ModalVoice::set_modulation`):
//! the rendered `Σ Re(m_i(t) W_i z_i)` against an independent per-sample
//! evaluation built from unmodulated voices.
//!
//! Reference: for one mode with `W = g(−i s)` (velocity output), `s = −d + iω_d`,
//! `Re(W z) = g q̇` and `Im(W z) = g (d (q̇ + d q)/ω_d + ω_d q)` (from
//! `q = Im z`, `q̇ = Im(s z)`), so `Re(m W z) = Re(m) g q̇ − Im(m) Im(W z)`
//! with `q̇`, `q` rendered by two unmodulated f64 voices that see only that
//! mode, and `m(t)` evaluated exactly at every sample.

mod common;

use std::sync::Arc;

use modal_synth::{Kernel, ModalVoice, OutputGain, OutputModulation, OutputQuantity, SynthOptions, C64};

/// `m_i(t) = c_i e^{(α_i + iΩ_i) t}`, or `cos(Ω_i t + φ_i)` (a dipole seen
/// from a body spinning at Ω_i).
struct Source {
    kind: Kind,
    params: Vec<(C64, f64, f64)>,
}

#[derive(Clone, Copy)]
enum Kind {
    Exponential,
    Cosine,
}

impl Source {
    fn at(&self, i: usize, t: f64) -> C64 {
        let (c, a, w) = self.params[i];
        match self.kind {
            Kind::Exponential => c * C64::new(a * t, w * t).exp(),
            Kind::Cosine => C64::new((w * t + a).cos(), 0.0),
        }
    }
}

impl OutputModulation for Source {
    fn factors(&self, time_s: f64, modes: &[usize], out: &mut [C64]) {
        for (o, &i) in out.iter_mut().zip(modes) {
            *o = self.at(i, time_s);
        }
    }
}

const FS: f64 = 48_000.0;
const LEN: usize = 24_000;

fn opts(gain: Vec<f64>, quantity: OutputQuantity, kernel: Kernel) -> SynthOptions {
    SynthOptions {
        sample_rate: FS,
        cull_db: None,
        gain: OutputGain::PerMode(gain),
        quantity,
        kernel,
        parallel: false,
        ..SynthOptions::default()
    }
}

fn strike(v: &mut ModalVoice) {
    v.add_impulse(0.01, [0.07, 0.02, 0.004], [0.3, -1.0, 0.2], 0.0).unwrap();
    v.add_impulse(0.2137, [0.21, 0.0, 0.006], [0.0, 1.0, -0.4], 1e-4).unwrap();
}

fn render(bank: &modal_bank::ModeBank, o: SynthOptions, m: Option<Arc<Source>>) -> Vec<f32> {
    let mut v = ModalVoice::new(bank, o).unwrap();
    if let Some(m) = m {
        v.set_modulation(m);
    }
    strike(&mut v);
    let mut out = vec![0.0f32; LEN];
    // Uneven calls: the result must not depend on the split.
    v.render(&mut out[..1000], 0);
    v.render(&mut out[1000..], 1000);
    out
}

/// The exact per-sample reference (module doc).
fn reference(bank: &modal_bank::ModeBank, gains: &[f64], src: &Source) -> Vec<f64> {
    let n = bank.mode_count();
    let mut y = vec![0.0f64; LEN];
    for i in 0..n {
        let mut only = vec![0.0; n];
        only[i] = 1.0;
        let qd = render(bank, opts(only.clone(), OutputQuantity::Velocity, Kernel::Reference), None);
        let q = render(bank, opts(only, OutputQuantity::Displacement, Kernel::Reference), None);
        let f = bank.frequencies_hz[i];
        let d = bank.decay_rates[i];
        let xi = bank.damping_ratios[i];
        let wd = 2.0 * std::f64::consts::PI * f * (1.0 - xi * xi).sqrt();
        for k in 0..LEN {
            let (qd, q) = (qd[k] as f64, q[k] as f64);
            let m = src.at(i, k as f64 / FS);
            let im_wz = gains[i] * (d * (qd + d * q) / wd + wd * q);
            y[k] += m.re * gains[i] * qd - m.im * im_wz;
        }
    }
    y
}

fn max_err(a: &[f32], b: &[f64]) -> (f64, f64) {
    let peak = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let err = a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((*x as f64 - y).abs()));
    (err, peak)
}

fn bank() -> modal_bank::ModeBank {
    common::bank(&[180.0, 731.0, 2450.0, 9120.0], &[3.0, 8.0, 20.0, 60.0])
}

#[test]
fn exponential_factors_are_reproduced_exactly_by_the_geometric_ramp() {
    let bank = bank();
    let gains = vec![1.0, 0.5, -0.8, 0.3];
    let src = Source {
        kind: Kind::Exponential,
        params: vec![
            (C64::new(0.8, -0.6), -1.5, 2.0 * std::f64::consts::PI * 1.3),
            (C64::new(-0.2, 1.1), 0.7, -9.0),
            (C64::new(1.0, 0.0), 0.0, 40.0),
            (C64::new(0.0, 0.5), -3.0, 0.5),
        ],
    };
    let want = reference(&bank, &gains, &src);
    let src = Arc::new(src);
    for kernel in [Kernel::Reference, Kernel::Auto] {
        let got = render(&bank, opts(gains.clone(), OutputQuantity::Velocity, kernel), Some(src.clone()));
        let (err, peak) = max_err(&got, &want);
        eprintln!("exponential factors, {kernel:?}: max error {:.2e} of peak", err / peak);
        assert!(peak > 1e-3);
        let bound = if kernel == Kernel::Reference { 1e-6 } else { 1e-5 };
        assert!(err < bound * peak, "{kernel:?}: {err} vs peak {peak}");
    }
}

#[test]
fn a_spinning_dipole_follows_its_cosine_within_the_interpolation_error() {
    let bank = bank();
    let gains = vec![1.0, 0.7, 0.4, 0.2];
    let spin = 2.0 * std::f64::consts::PI * 2.0; // 2 rev/s
    let src =
        Source { kind: Kind::Cosine, params: (0..4).map(|i| (C64::ZERO, 0.3 * i as f64, spin)).collect() };
    let want = reference(&bank, &gains, &src);
    let got = render(&bank, opts(gains.clone(), OutputQuantity::Velocity, Kernel::Auto), Some(Arc::new(src)));
    let (err, peak) = max_err(&got, &want);
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    let diff: Vec<f64> = got.iter().zip(&want).map(|(a, b)| *a as f64 - b).collect();
    let rel_rms = rms(&diff) / rms(&want);
    eprintln!("spinning dipole 2 rev/s: max error {:.2e} of peak, rms error {:.2e}", err / peak, rel_rms);
    // The geometric path misses only near the zero crossings of the cosine.
    assert!(err < 0.05 * peak, "{err} vs {peak}");
    assert!(rel_rms < 0.01, "{rel_rms}");
    // Unmodulated output is clearly different (the modulation acts).
    let plain = render(&bank, opts(gains, OutputQuantity::Velocity, Kernel::Auto), None);
    let (dev, _) = max_err(&plain, &want);
    assert!(dev > 0.3 * peak);
}

#[test]
fn unit_factors_equal_the_unmodulated_voice() {
    let bank = bank();
    let gains = vec![1.0, 0.5, -0.8, 0.3];
    let src = Arc::new(Source { kind: Kind::Exponential, params: vec![(C64::new(1.0, 0.0), 0.0, 0.0); 4] });
    let a = render(&bank, opts(gains.clone(), OutputQuantity::Velocity, Kernel::Auto), Some(src));
    let b = render(&bank, opts(gains, OutputQuantity::Velocity, Kernel::Auto), None);
    let peak = b.iter().fold(0.0f32, |m, x| m.max(x.abs())) as f64;
    let err = a.iter().zip(&b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs() as f64));
    assert!(err < 1e-6 * peak, "{err} vs {peak}");
}

#[test]
fn constant_phases_are_a_fixed_complex_gain_per_mode() {
    // What `strike` hears at a listener: `Re(c_i W_i z_i)` with each mode's
    // transfer phase `c_i` (`SynthOptions::phases`), against the per-sample
    // reference, on both kernels.
    let bank = bank();
    let gains = vec![1.0, 0.5, 0.8, 0.3];
    let c = vec![C64::new(0.6, 0.8), C64::new(-1.0, 0.0), C64::new(0.0, -1.0), C64::new(0.28, -0.96)];
    let fixed = Source { kind: Kind::Exponential, params: c.iter().map(|&c| (c, 0.0, 0.0)).collect() };
    let want = reference(&bank, &gains, &fixed);
    let with = |phases: Vec<C64>, kernel| SynthOptions {
        phases: Some(phases),
        ..opts(gains.clone(), OutputQuantity::Velocity, kernel)
    };
    for kernel in [Kernel::Reference, Kernel::Auto] {
        let (err, peak) = max_err(&render(&bank, with(c.clone(), kernel), None), &want);
        assert!(peak > 1e-3 && err < 1e-5 * peak, "{kernel:?}: {err} vs peak {peak}");
    }
    // One finite factor per mode.
    assert!(ModalVoice::new(&bank, with(c[..3].to_vec(), Kernel::Auto)).is_err());
    let mut bad = c;
    bad[1] = C64::new(f64::NAN, 0.0);
    assert!(ModalVoice::new(&bank, with(bad, Kernel::Auto)).is_err());
}

/// Cost of the modulation against real gains: a 600-mode voice, 2 s at
/// 48 kHz, five repetitions each, medians printed. Timing only, no
/// assertion on it:
/// `cargo test --release -p modal-synth --test modulation -- --ignored --nocapture`
#[test]
#[ignore]
fn cost_of_complex_time_varying_weights_against_real_gains() {
    let bank = common::many_modes(600);
    let n = bank.mode_count();
    let gains = vec![1.0; n];
    let src = Arc::new(Source {
        kind: Kind::Exponential,
        params: (0..n).map(|i| (C64::new(0.5, 0.5), -0.1, 3.0 + 0.01 * i as f64)).collect(),
    });
    let time = |m: Option<Arc<Source>>| {
        let mut runs: Vec<f64> = (0..5)
            .map(|_| {
                let mut v =
                    ModalVoice::new(&bank, opts(gains.clone(), OutputQuantity::Velocity, Kernel::Auto))
                        .unwrap();
                if let Some(m) = &m {
                    v.set_modulation(m.clone());
                }
                v.add_impulse(0.0, [0.07, 0.02, 0.004], [0.3, -1.0, 0.2], 0.0).unwrap();
                let mut out = vec![0.0f32; 96_000];
                let t = std::time::Instant::now();
                v.render(&mut out, 0);
                t.elapsed().as_secs_f64()
            })
            .collect();
        runs.sort_by(f64::total_cmp);
        runs[2]
    };
    let plain = time(None);
    let modulated = time(Some(src));
    eprintln!(
        "600 modes, 2 s at 48 kHz: real gains {:.1} ms, modulated {:.1} ms (x{:.2})",
        plain * 1e3,
        modulated * 1e3,
        modulated / plain
    );
}
