//! Bad input gives typed one-line errors; WAV output is atomic and exact.

mod common;
use common::*;
use modal_synth::*;

const AT: [f64; 3] = [0.3, 0.02, 0.004];

#[test]
fn bad_input_is_a_typed_error() {
    let b = bank(&[440.0], &[3.0]);
    let mut v = ModalVoice::new(&b, SynthOptions::default()).unwrap();
    let e = v.add_impulse(0.0, AT, [f64::NAN, 0.0, 0.0], 0.0).unwrap_err();
    assert!(matches!(e, SynthError::InvalidImpulse(_)), "{e}");
    assert!(matches!(v.add_impulse(-1.0, AT, [0.0; 3], 0.0), Err(SynthError::InvalidTime(..))));
    assert!(matches!(v.add_impulse(f64::INFINITY, AT, [0.0; 3], 0.0), Err(SynthError::InvalidTime(..))));
    assert!(matches!(v.add_impulse(0.0, AT, [0.0; 3], -1e-4), Err(SynthError::InvalidContactTime(_))));
    assert!(matches!(
        v.add_impulse(0.0, [f64::NAN, 0.0, 0.0], [0.0; 3], 0.0),
        Err(SynthError::InvalidPoint(_))
    ));
    // Bounding-box diagonal ≈ 0.3008 m: 0.02 m away is fine, 0.05 m is not.
    assert!(v.add_impulse(0.0, [0.32, 0.01, 0.005], [0.0; 3], 0.0).is_ok());
    let e = v.add_impulse(0.0, [0.35, 0.01, 0.005], [0.0; 3], 0.0).unwrap_err();
    match e {
        SynthError::PointFarFromSurface { distance, limit, .. } => {
            assert!((distance - 0.05).abs() < 1e-12 && (limit - 0.030_08).abs() < 1e-4)
        }
        other => panic!("{other}"),
    }
    assert!(!e.to_string().contains('\n'));
    for rate in [0.0, 7_999.0, 192_001.0, f64::NAN] {
        let o = SynthOptions { sample_rate: rate, ..SynthOptions::default() };
        assert!(matches!(ModalVoice::new(&b, o), Err(SynthError::SampleRate(_))), "{rate}");
    }
    let o = SynthOptions { gain: OutputGain::PerMode(vec![1.0, 2.0]), ..SynthOptions::default() };
    assert!(matches!(ModalVoice::new(&b, o), Err(SynthError::GainCount { got: 2, expected: 1 })));
    let o = SynthOptions { cull_db: Some(f64::NAN), ..SynthOptions::default() };
    assert!(ModalVoice::new(&b, o).is_err());
    let mut broken = b.clone();
    broken.shapes.pop();
    assert!(matches!(
        ModalVoice::new(&broken, SynthOptions::default()),
        Err(SynthError::InconsistentBank(_))
    ));
    let err = render_strikes(
        &b,
        &[Strike::new(AT, [0.0, 0.0, 1.0])],
        &SynthOptions::default(),
        RenderLength::Fixed(1e12),
    );
    assert!(err.is_err(), "giant durations are refused");
}

#[test]
fn zero_mode_bank_is_silence() {
    let b = bank(&[], &[]);
    let r = render_strikes(
        &b,
        &[Strike::new(AT, [0.0, 0.0, 1.0])],
        &SynthOptions::default(),
        RenderLength::Auto { cap_s: 5.0 },
    )
    .unwrap();
    assert!(!r.samples.is_empty() && r.samples.iter().all(|&x| x == 0.0));
}

#[test]
fn wav_roundtrip_pcm_and_float() {
    let dir = tempfile::tempdir().unwrap();
    let x: Vec<f32> = vec![0.0, 0.5, -0.25, 1.5, -2.0];
    let y: Vec<f32> = vec![0.1, 0.2, 0.3, 0.4, 0.5];
    let p = dir.path().join("a.wav");
    let r = write_wav(&p, &[&x, &y], 44_100, WavFormat::Pcm16, WavGain::default()).unwrap();
    assert_eq!((r.channels, r.frames, r.clipped), (2, 5, 2));
    let mut rd = hound::WavReader::open(&p).unwrap();
    assert_eq!(rd.spec().sample_rate, 44_100);
    let s: Vec<i16> = rd.samples::<i16>().map(|s| s.unwrap()).collect();
    assert_eq!(s[..4], [0, 3277, 16384, 6553]);
    assert_eq!(s[6], 32767);
    assert_eq!(s[8], -32767);

    let q = dir.path().join("b.wav");
    let r = write_wav(&q, &[&x], 96_000, WavFormat::Float32, WavGain::Fixed(2.0)).unwrap();
    assert_eq!(r.clipped, 0);
    let f: Vec<f32> = hound::WavReader::open(&q).unwrap().samples::<f32>().map(|s| s.unwrap()).collect();
    assert_eq!(f, vec![0.0, 1.0, -0.5, 3.0, -4.0], "float output is unclipped");

    let r = write_wav(&q, &[&x], 8_000, WavFormat::Float32, WavGain::Normalize { peak: 0.5 }).unwrap();
    assert!((r.peak - 0.5).abs() < 1e-12 && (r.gain - 0.25).abs() < 1e-12);
}

#[test]
fn wav_errors_leave_no_file_behind() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.wav");
    let x = vec![0.0f32; 10];
    assert!(matches!(
        write_wav(&p, &[&x], 0, WavFormat::Pcm16, WavGain::default()),
        Err(SynthError::SampleRate(_))
    ));
    assert!(write_wav(&p, &[&x, &x[..5]], 48_000, WavFormat::Pcm16, WavGain::default()).is_err());
    assert!(write_wav(&p, &[], 48_000, WavFormat::Pcm16, WavGain::default()).is_err());
    let nan = vec![f32::NAN; 4];
    assert!(write_wav(&p, &[&nan], 48_000, WavFormat::Float32, WavGain::default()).is_err());
    let missing = dir.path().join("no/such/dir/x.wav");
    assert!(matches!(
        write_wav(&missing, &[&x], 48_000, WavFormat::Pcm16, WavGain::default()),
        Err(SynthError::WavWrite { .. })
    ));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "nothing written, no temp file left");
}

#[test]
fn struck_bank_to_wav_end_to_end() {
    let b = bank(&[440.0, 1000.0], &[3.0, 8.0]);
    let r = render_strikes(
        &b,
        &[Strike::new(AT, [0.0, 0.0, 0.01])],
        &SynthOptions::default(),
        RenderLength::Fixed(0.2),
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.wav");
    let rep = write_wav(&p, &[&r.samples], 48_000, WavFormat::Pcm16, WavGain::default()).unwrap();
    assert_eq!(rep.frames, 9600);
    assert!(rep.peak > 0.0);
}
