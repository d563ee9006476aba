//! The f64 closed form (`modal_synth::reference`) and the error-vs-cost study
//! (`modal_synth::study`) that `modal bench synth` runs.

mod common;
use common::*;
use modal_synth::study::{measure, standard_variants, Scenario, Variant};
use modal_synth::*;

const AT: [f64; 3] = [0.3, 0.02, 0.004];
const J: [f64; 3] = [0.0, -0.004, 0.01];

#[test]
fn closed_form_matches_the_independent_test_formula() {
    // tests/common::closed_form writes the contact-mic velocity out as
    // g a e^{−dτ}(cos ω_d τ − d/ω_d sin ω_d τ); the library evaluates Im(K e^{sτ}).
    let b = bank(&[440.0, 1000.0, 7300.0], &[3.0, 8.0, 60.0]);
    let rate = 48_000.0;
    let t0 = 0.012_345_678_9;
    let strike = Strike { time_s: t0, at: AT, impulse_ns: J, contact_time_s: 0.0 };
    let opts = SynthOptions { sample_rate: rate, ..SynthOptions::default() };
    let cf = ClosedForm::new(&b, &[strike], &opts).unwrap();
    assert_eq!(cf.term_count(), 3);
    let p = cf.points()[0];
    let mut y = vec![0.0; 4800];
    cf.render(0, &mut y);
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for (n, &v) in y.iter().enumerate() {
        let want = closed_form(&b, p.triangle, p.bary, p.normal, J, t0, n as f64 / rate);
        worst = worst.max((v - want).abs());
        scale = scale.max(want.abs());
        assert_eq!(v, cf.sample(n as u64), "render and sample agree");
    }
    assert!(scale > 0.0 && worst <= 1e-12 * scale, "{worst} vs {scale}");
    assert_eq!(y[592], 0.0, "nothing before ⌈t0·fs⌉ = 593");
    assert!(y[593] != 0.0);
}

#[test]
fn voice_matches_closed_form_for_every_quantity_and_gain() {
    let b = bank(&[440.0, 1000.0, 2500.0, 4100.0], &[3.0, 8.0, 20.0, 35.0]);
    let strikes = [
        Strike { time_s: 0.001, at: AT, impulse_ns: J, contact_time_s: 1e-4 },
        Strike { time_s: 0.0011, at: [0.1, 0.0, 0.01], impulse_ns: [0.0, 0.02, 0.0], contact_time_s: 3e-4 },
    ];
    let gains = [
        OutputGain::ContactMic { at: None },
        OutputGain::ContactMic { at: Some([0.2, 0.02, 0.005]) },
        OutputGain::RadiationProxy,
        OutputGain::PerMode(vec![1.0, -0.5, 0.25, 2.0]),
    ];
    for quantity in [OutputQuantity::Velocity, OutputQuantity::Displacement] {
        for gain in &gains {
            for kernel in [Kernel::Reference, Kernel::Auto] {
                let o = SynthOptions {
                    gain: gain.clone(),
                    quantity,
                    kernel,
                    cull_db: None,
                    ..Default::default()
                };
                let cf = ClosedForm::new(&b, &strikes, &o).unwrap();
                let mut want = vec![0.0; 9600];
                cf.render(0, &mut want);
                let r = render_strikes(&b, &strikes, &o, RenderLength::Fixed(0.2)).unwrap();
                let e = SignalError::between(&r.samples, &want);
                // f64 path: only the f32 output rounding; f32 path: ≤ one block of f32 rounding.
                let bound = if kernel == Kernel::Reference { 1e-7 } else { 1e-5 };
                assert!(e.max_rel < bound, "{quantity:?} {gain:?} {kernel:?}: {e:?}");
            }
        }
    }
}

#[test]
fn signal_error_definitions() {
    let reference = [0.0, 1.0, -2.0, 0.5];
    let scaled: Vec<f32> = reference.iter().map(|&x| (1.01 * x) as f32).collect();
    let e = SignalError::between(&scaled, &reference);
    assert!((e.rel_rms - 0.01).abs() < 1e-7 && (e.max_rel - 0.01).abs() < 1e-7 && e.peak == 2.0, "{e:?}");
    assert!((e.max_rel_db() + 40.0).abs() < 1e-4);
    let exact: Vec<f32> = reference.iter().map(|&x| x as f32).collect();
    let e = SignalError::between(&exact, &reference);
    assert_eq!((e.rel_rms, e.max_rel), (0.0, 0.0));
    assert_eq!(e.rel_rms_db(), f64::NEG_INFINITY);
    let e = SignalError::between(&[1.0], &[0.0]);
    assert_eq!(e.rel_rms, f64::INFINITY);
    assert_eq!(SignalError::between(&[0.0], &[0.0]).max_rel, 0.0);
}

#[test]
fn closed_form_rejects_what_the_voice_rejects() {
    let b = bank(&[440.0], &[3.0]);
    let o = SynthOptions::default();
    let s = |time_s, impulse_ns, contact_time_s| Strike { time_s, at: AT, impulse_ns, contact_time_s };
    let bad = [
        s(f64::NAN, J, 0.0),
        s(-1.0, J, 0.0),
        s(0.0, [f64::INFINITY, 0.0, 0.0], 0.0),
        s(0.0, J, f64::NAN),
        Strike { at: [0.0, f64::NAN, 0.0], ..s(0.0, J, 0.0) },
        Strike { at: [5.0, 0.0, 0.0], ..s(0.0, J, 0.0) },
    ];
    for strike in bad {
        assert!(ClosedForm::new(&b, &[strike], &o).is_err(), "{strike:?}");
    }
    let o = SynthOptions { sample_rate: 0.0, ..SynthOptions::default() };
    assert!(matches!(ClosedForm::new(&b, &[], &o), Err(SynthError::SampleRate(_))));
}

#[test]
fn study_orders_the_paths_by_error_and_cost() {
    let sc = Scenario::realistic("steel", 200, 0.25, 7);
    let reference = sc.reference().unwrap();
    assert_eq!(reference.len(), 12_000);
    let run = |v: &Variant| measure(&sc, &reference, v, 1).unwrap();
    let f64_off = run(&Variant::new(Kernel::Reference, None, None));
    let f32_off = run(&Variant::new(Kernel::Auto, None, None));
    // The scalar f64 path differs from the closed form only by the f32 output rounding.
    assert!(f64_off.error.max_rel < 1e-6, "{:?}", f64_off.error);
    assert!(f32_off.error.max_rel < 1e-5, "{:?}", f32_off.error);
    assert!(f32_off.error.rel_rms < 1e-5, "{:?}", f32_off.error);
    // More culling: less work, more error, both bounded by the threshold.
    let c60 = run(&Variant::new(Kernel::Auto, Some(-60.0), None));
    let c100 = run(&Variant::new(Kernel::Auto, Some(-100.0), None));
    assert!(c60.mode_samples < c100.mode_samples && c100.mode_samples <= f32_off.mode_samples);
    assert!(c60.modes_culled > 0);
    assert!(c60.error.rel_rms < 1e-2, "{:?}", c60.error);
    assert!(c100.error.rel_rms < 1e-4, "{:?}", c100.error);
    // A budget of 20 of 200 modes does a tenth of the work (or less).
    let b20 = run(&Variant::new(Kernel::Auto, Some(-100.0), Some(20)));
    assert!(b20.mode_samples * 10 <= f32_off.mode_samples + 20 * 12_000);
    assert!(b20.error.rel_rms > c100.error.rel_rms);
    assert!(f32_off.realtime_factor() > 0.0 && f32_off.mode_samples_per_s() > 0.0);
    let labels: Vec<String> = standard_variants(1000).into_iter().map(|v| v.label).collect();
    assert!(labels.contains(&"f32 SIMD, cull -100 dB, budget 100".to_string()), "{labels:?}");
}
