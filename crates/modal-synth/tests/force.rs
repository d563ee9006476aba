//! The force-driven path (`DrivenVoice`): exactness of the first-order hold,
//! the impulse limit, block-size independence, energy, bad input.

mod common;
use common::*;
use modal_synth::force::{foh_coefficients, phi12};
use modal_synth::synthetic::SplitMix64;
use modal_synth::*;
use std::f64::consts::PI;

const AT: [f64; 3] = [0.1, 0.02, 0.004];

fn opts(quantity: OutputQuantity, n: usize) -> SynthOptions {
    SynthOptions {
        cull_db: None,
        gain: OutputGain::PerMode(vec![1.0; n]),
        quantity,
        kernel: Kernel::Reference,
        ..SynthOptions::default()
    }
}

fn driven(b: &modal_bank::ModeBank, quantity: OutputQuantity) -> DrivenVoice {
    let model = std::sync::Arc::new(SynthModel::new(b).unwrap());
    DrivenVoice::from_model(model, opts(quantity, b.mode_count())).unwrap()
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[test]
fn phi_functions_agree_across_the_series_switch() {
    // Either side of |x| = 1/2 the series and the closed form agree.
    for x in [C64::new(0.0, 0.4999), C64::new(-0.3, 0.39), C64::new(0.0, 0.5001), C64::new(-0.31, 0.3905)] {
        let (p1, p2) = phi12(x);
        let e = x.exp();
        let d1 = (p1 * x) - (e - C64::new(1.0, 0.0));
        let d2 = (p2 * x * x) - (e - C64::new(1.0, 0.0) - x);
        assert!(d1.abs() < 1e-15 && d2.abs() < 1e-15, "{x:?}: {d1:?} {d2:?}");
    }
    // Small arguments: φ₁ → 1, φ₂ → 1/2 (no cancellation).
    let x = C64::new(-1e-9, 1e-7);
    let (p1, p2) = phi12(x);
    let (w1, w2) = (C64::new(1.0, 0.0) + x.scale(0.5), C64::new(0.5, 0.0) + x.scale(1.0 / 6.0));
    assert!((p1 - w1).abs() < 1e-14 && (p2 - w2).abs() < 1e-14, "{p1:?} {p2:?}");
    // a + b integrates a constant force exactly: (e^{sh} − 1)/(s ω_d).
    let s = C64::new(-3.0, 2.0 * PI * 440.0);
    let h = 1.0 / 48_000.0;
    let (a, b) = foh_coefficients(s, h);
    let want = (s.scale(h).exp() - C64::new(1.0, 0.0)).quot(s).scale(1.0 / s.im);
    assert!((a + b - want).abs() < 1e-15 * want.abs().max(1e-12) * 1e3, "{:?} vs {want:?}", a + b);
}

/// A constant force switched on at t = 0 (a step): the closed-form response
/// `q(t) = (g/ω²)(1 − e^{−dt}(cos ω_d t + (d/ω_d) sin ω_d t))` is met to
/// f64 precision by the state, whatever the sample rate.
#[test]
fn step_force_response_is_exact() {
    let b = bank(&[330.0, 2500.0, 9000.0], &[2.0, 40.0, 300.0]);
    let force = [0.3, -1.2, 2.0];
    for fs in [8_000.0, 48_000.0, 192_000.0] {
        let model = std::sync::Arc::new(SynthModel::new(&b).unwrap());
        let o = SynthOptions { sample_rate: fs, ..opts(OutputQuantity::Displacement, 3) };
        let mut v = DrivenVoice::from_model(model, o).unwrap();
        let len = (0.05 * fs) as usize;
        let p = v
            .add_segment(ForceSegment {
                start: 0,
                oversample: 1,
                point: ImpactPoint::Position(AT),
                forces: vec![force; len + 2],
            })
            .unwrap();
        let mut out = vec![0.0f32; len];
        v.render(&mut out, 0);
        let t = len as f64 / fs;
        for i in 0..3 {
            if 9000.0 >= 0.45 * fs && i == 2 {
                continue;
            }
            let g = dot(shape_at(&b, i, p.triangle, p.bary), force);
            let (d, w) = (b.decay_rates[i], 2.0 * PI * b.frequencies_hz[i]);
            let wd = (w * w - d * d).sqrt();
            let q = g / (w * w) * (1.0 - (-d * t).exp() * ((wd * t).cos() + d / wd * (wd * t).sin()));
            let qd = g / (w * w) * (-d * t).exp() * (w * w / wd) * (wd * t).sin();
            let z = v.modal_state(i);
            let s = v.complex_frequency(i);
            let scale = g.abs() / (w * w);
            assert!((z.im - q).abs() < 1e-9 * scale, "fs {fs} mode {i}: q {} vs {q}", z.im);
            assert!(((s * z).im - qd).abs() < 1e-9 * scale * w, "fs {fs} mode {i}: q̇ {} vs {qd}", (s * z).im);
        }
    }
}

/// Triangle pulses of area J and width 2h, h → 0, converge to the impulse
/// path (`ModalVoice`, ideal impulse at the pulse centre); at h = 1/(4096 fs)
/// they agree to 1e-6 of the peak (state and samples).
#[test]
fn vanishing_force_pulse_equals_the_impulse_path() {
    let b = bank(&[220.0, 1250.0, 4400.0, 9100.0, 15_000.0], &[1.0, 8.0, 30.0, 90.0, 200.0]);
    let n = b.mode_count();
    let j = [0.002, -0.001, 0.004];
    let fs = 48_000.0;
    let len = 4000;
    let centre_sample = 100u64;
    let mut errors = Vec::new();
    for m in [1u32, 16, 4096] {
        // Peak at a fractional sample time: centre_sample + 1/3.
        let k_peak = centre_sample * m as u64 + (m as u64) / 3;
        let t0 = k_peak as f64 / (m as f64 * fs);
        let h = 1.0 / (m as f64 * fs);
        let mut dv = driven(&b, OutputQuantity::Velocity);
        dv.add_segment(ForceSegment {
            start: k_peak - 1,
            oversample: m,
            point: ImpactPoint::Position(AT),
            forces: vec![[0.0; 3], j.map(|x| x / h), [0.0; 3]],
        })
        .unwrap();
        let mut a = vec![0.0f32; len];
        dv.render(&mut a, 0);
        let mut iv = ModalVoice::new(&b, opts(OutputQuantity::Velocity, n)).unwrap();
        let p = iv.add_impulse(t0, AT, j, 0.0).unwrap();
        let mut want = vec![0.0f32; len];
        iv.render(&mut want, 0);
        let err = max_diff(&a, &want) / peak(&want);
        // State after the render, against the closed form (J·φ/ω_d) e^{s(t − t0)}.
        let t = len as f64 / fs;
        let mut state_err = 0.0f64;
        for i in 0..n {
            let s = dv.complex_frequency(i);
            let a_i = dot(shape_at(&b, i, p.triangle, p.bary), j);
            let z = s.scale(t - t0).exp().scale(a_i / s.im);
            state_err = state_err.max((dv.modal_state(i) - z).abs() / z.abs());
        }
        errors.push((m, err, state_err));
    }
    let (m1, e1, _) = errors[0];
    assert!(e1 > 1e-4, "m = {m1}: a two-sample pulse is not an impulse ({e1})");
    let (_, e, se) = errors[2];
    assert!(e < 1e-6 && se < 1e-6, "{errors:?}");
    assert!(errors[1].2 > errors[2].2, "{errors:?}");
}

fn test_segments() -> Vec<ForceSegment> {
    let mut segs = Vec::new();
    let mut rng = SplitMix64::new(7);
    // Chained per-"step" segments at moving points, plus an overlapping one.
    for k in 0..12u64 {
        let x = [0.02 + 0.02 * k as f64, 0.02, 0.004];
        let forces =
            (0..49).map(|_| [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)]).collect();
        segs.push(ForceSegment {
            start: 300 + 48 * k,
            oversample: 1,
            point: ImpactPoint::Position(x),
            forces,
        });
    }
    let forces = (0..800).map(|i| [0.0, (i as f64 * 0.01).sin(), 0.0]).collect();
    segs.push(ForceSegment { start: 1000, oversample: 1, point: ImpactPoint::Position(AT), forces });
    let forces = vec![[0.0; 3], [0.0, 0.0, 1e3], [0.0; 3]];
    segs.push(ForceSegment { start: 3 * 2000 + 1, oversample: 3, point: ImpactPoint::Position(AT), forces });
    segs
}

#[test]
fn energy_never_grows_without_force() {
    let b = many_modes(40);
    let mut v = with_test_segments(&b, Kernel::Reference);
    // The last force knot is at sample 1799 (and the fine pulse at 2000..2001).
    let (checked, last) = assert_energy_never_grows(&mut v, 1, 8000, 2001);
    assert!(checked > 5000 && last > 0.0);
}

/// Renders `calls` calls of `chunk` samples each; from call `first_free` on
/// (no force acts any more) the modes' total energy must not grow from one
/// call to the next. Returns how many calls were checked and the last energy.
fn assert_energy_never_grows(v: &mut DrivenVoice, chunk: usize, calls: u64, first_free: u64) -> (usize, f64) {
    let mut out = vec![0.0f32; chunk];
    let mut before = f64::INFINITY;
    let mut checked = 0;
    for k in 0..calls {
        v.render(&mut out, k * chunk as u64);
        let e: f64 = v.mode_energies().iter().sum();
        if k >= first_free {
            assert!(e <= before * (1.0 + 1e-12), "energy grew at call {k} (chunk {chunk}): {before} -> {e}");
            checked += 1;
        }
        before = e;
    }
    (checked, before)
}

#[test]
fn bad_force_input_is_refused() {
    let b = many_modes(4);
    let mut v = driven(&b, OutputQuantity::Velocity);
    let seg = |forces: Vec<[f64; 3]>, start: u64, oversample: u32| ForceSegment {
        start,
        oversample,
        point: ImpactPoint::Position(AT),
        forces,
    };
    let err = v.add_segment(seg(vec![[0.0, f64::NAN, 0.0]; 3], 0, 1)).unwrap_err();
    assert!(matches!(err, SynthError::InvalidForce(_)), "{err}");
    assert!(v.add_segment(seg(vec![[1e12, 0.0, 0.0]; 3], 0, 1)).is_err());
    assert!(v.add_segment(seg(vec![[1.0; 3]; 3], 0, 0)).is_err());
    let mut out = vec![0.0f32; 100];
    v.render(&mut out, 0);
    let err = v.add_segment(seg(vec![[1.0; 3]; 3], 50, 1)).unwrap_err();
    assert!(err.to_string().contains("before the render position"), "{err}");
    let far =
        ForceSegment { point: ImpactPoint::Position([9.0, 9.0, 9.0]), ..seg(vec![[1.0; 3]; 3], 200, 1) };
    assert!(matches!(v.add_segment(far).unwrap_err(), SynthError::PointFarFromSurface { .. }));
    assert!(v.is_silent());
}

/// A driven voice on `b` with the given kernel.
fn driven_on(b: &modal_bank::ModeBank, kernel: Kernel) -> DrivenVoice {
    let model = std::sync::Arc::new(SynthModel::new(b).unwrap());
    let o = SynthOptions { kernel, ..opts(OutputQuantity::Velocity, b.mode_count()) };
    DrivenVoice::from_model(model, o).unwrap()
}

/// A driven voice on `b` with the given kernel, holding every [`test_segments`].
fn with_test_segments(b: &modal_bank::ModeBank, kernel: Kernel) -> DrivenVoice {
    let mut v = driven_on(b, kernel);
    for s in test_segments() {
        v.add_segment(s).unwrap();
    }
    v
}

/// Renders `total` samples of [`test_segments`] in calls of `chunk`.
fn render_segments(b: &modal_bank::ModeBank, kernel: Kernel, total: usize, chunk: usize) -> Vec<f32> {
    let mut v = with_test_segments(b, kernel);
    let mut out = vec![0.0f32; total];
    let mut at = 0;
    while at < total {
        let len = chunk.min(total - at);
        v.render(&mut out[at..at + len], at as u64);
        at += len;
    }
    out
}

/// The f32 tile kernels (`Auto`: AVX-512/AVX2 when present; `Portable`)
/// against the f64 reference: chained and overlapping segments, an
/// oversampled pulse, then 1.9 s of free ringing. The anchor keeps the error
/// from growing with time: the last 0.1 s is as accurate, relative to its
/// own level, as the forced part.
#[test]
fn tile_kernels_track_the_f64_reference() {
    let b = many_modes(40);
    let total = 96_000;
    let want = render_segments(&b, Kernel::Reference, total, total);
    let tail = total - 4800..total;
    for kernel in [Kernel::Auto, Kernel::Portable] {
        let got = render_segments(&b, kernel, total, total);
        let forced = max_diff(&got[..2400], &want[..2400]) / peak(&want[..2400]);
        let late = max_diff(&got[tail.clone()], &want[tail.clone()]) / peak(&want[tail.clone()]);
        eprintln!("{kernel:?}: forced part {forced:.2e}, last 0.1 s {late:.2e} of their peaks");
        assert!(forced < 2e-5 && late < 2e-5, "{kernel:?}: {forced:e} {late:e}");
        assert!(forced > 0.0, "{kernel:?} is not an f32 kernel");
    }
}

/// The f64 reference and the f32 tile kernels alike.
#[test]
fn no_kernel_changes_a_single_bit_with_the_block_size() {
    let b = many_modes(40);
    for kernel in [Kernel::Reference, Kernel::Auto, Kernel::Portable] {
        let whole = render_segments(&b, kernel, 6000, 6000);
        assert!(peak(&whole) > 0.0);
        for chunk in [1, 7, 100, 256, 1000] {
            assert!(render_segments(&b, kernel, 6000, chunk) == whole, "{kernel:?}: chunk {chunk} differs");
        }
    }
}

/// Without force the anchor moves by the exact `z ← P z`: the energy at
/// every anchor (multiple of BLOCK samples) never grows.
#[test]
fn tile_kernel_energy_never_grows_without_force() {
    let b = many_modes(40);
    let mut v = with_test_segments(&b, Kernel::Auto);
    // Forces end at sample 2001 (block 7).
    let (checked, last) = assert_energy_never_grows(&mut v, BLOCK, 40, 8);
    assert!(checked > 30 && last > 0.0);
}

/// The impulse limit of [`vanishing_force_pulse_equals_the_impulse_path`]
/// through the f32 kernel: within f32 precision of the impulse path.
#[test]
fn tile_kernel_force_pulse_equals_the_impulse_path() {
    let b = bank(&[220.0, 1250.0, 4400.0, 9100.0, 15_000.0], &[1.0, 8.0, 30.0, 90.0, 200.0]);
    let n = b.mode_count();
    let j = [0.002, -0.001, 0.004];
    let (fs, len, m) = (48_000.0, 4000, 4096u32);
    let k_peak = 100 * m as u64 + m as u64 / 3;
    let h = 1.0 / (m as f64 * fs);
    let mut dv = driven_on(&b, Kernel::Auto);
    dv.add_segment(ForceSegment {
        start: k_peak - 1,
        oversample: m,
        point: ImpactPoint::Position(AT),
        forces: vec![[0.0; 3], j.map(|x| x / h), [0.0; 3]],
    })
    .unwrap();
    let mut a = vec![0.0f32; len];
    dv.render(&mut a, 0);
    let mut iv = ModalVoice::new(&b, opts(OutputQuantity::Velocity, n)).unwrap();
    iv.add_impulse(k_peak as f64 / (m as f64 * fs), AT, j, 0.0).unwrap();
    let mut want = vec![0.0f32; len];
    iv.render(&mut want, 0);
    let err = max_diff(&a, &want) / peak(&want);
    eprintln!("f32 tile kernel vs impulse path: {err:.2e} of the peak");
    assert!(err < 1e-5, "{err}");
}
