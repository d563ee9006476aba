//! End-to-end tests of `modal strike`: a real bank struck through the CLI,
//! and every bad input of issue 4 giving a clear error and no WAV.

mod common;
use common::*;

/// A steel bar bank (lightly damped) in `dir/bar.bank`.
fn bar_bank(dir: &std::path::Path) {
    let bar = example("bar_p1.msh");
    let mut args = vec!["precompute", bar.to_str().unwrap(), "-o", "bar.bank", "--modes", "12"];
    args.extend(STEEL);
    args.extend(["--alpha", "5", "--beta", "3e-8"]);
    modal(dir, &args).ok();
}

fn wav_samples(path: &std::path::Path) -> Vec<i16> {
    hound::WavReader::open(path).unwrap().into_samples::<i16>().map(Result::unwrap).collect()
}

#[test]
fn strike_writes_a_wav_that_is_linear_in_the_impulse() {
    let dir = temp_dir();
    bar_bank(dir.path());
    let strike = |impulse: &str, out: &str| {
        modal(
            dir.path(),
            &[
                "strike",
                "bar.bank",
                "--at",
                "0.05,0.01,0.01",
                "--impulse",
                impulse,
                "--duration",
                "0.5",
                "--rate",
                "44100",
                "-o",
                out,
                "--json",
            ],
        )
        .ok()
        .json()
    };
    let one = strike("0.002", "one.wav");
    let two = strike("0.004", "two.wav");
    assert_eq!(one["clipped_samples"], 0);
    assert!((two["peak"].as_f64().unwrap() / one["peak"].as_f64().unwrap() - 2.0).abs() < 1e-3);
    assert_eq!(one["sample_rate"], 44100);
    assert!((one["duration_s"].as_f64().unwrap() - 0.5).abs() < 1e-9);
    // The struck point lies on the bar's top face.
    assert!(one["strikes"][0]["distance_m"].as_f64().unwrap() < 1e-9);
    assert!(!one["top_modes"].as_array().unwrap().is_empty());
    let (a, b) = (wav_samples(&dir.path().join("one.wav")), wav_samples(&dir.path().join("two.wav")));
    assert_eq!(a.len(), 22050);
    assert!(a.iter().any(|&s| s.abs() > 100), "audible");
    // The bar still rings at 0.5 s; the fixed length ends with a 5 ms fade, not a click.
    let before_fade = &a[a.len() - 441..a.len() - 221];
    assert!(before_fade.iter().any(|&s| s.abs() > 10), "still ringing before the fade");
    assert_eq!(a[a.len() - 1], 0, "faded out");
    // 16-bit quantization allows ±1 LSB after doubling.
    assert!(
        a.iter().zip(&b).all(|(&x, &y)| (2 * x as i32 - y as i32).abs() <= 2),
        "doubling the impulse doubles the output"
    );
    // Default duration: until decayed by 60 dB.
    let auto =
        modal(dir.path(), &["strike", "bar.bank", "--at", "0.05,0.01,0.01", "-o", "auto.wav", "--json"])
            .ok()
            .json();
    assert!(auto["duration_s"].as_f64().unwrap() > 0.5);
    // Without --at, the 0.3 × 0.02 × 0.01 m bar is struck across a broad face near an end,
    // where its lowest modes move most along the normal, not at its farthest point (a
    // corner, whose tap along the axis played the axial modes to a listener on the
    // axis, the bending modes' null: 30× quieter).
    let run = modal(dir.path(), &["strike", "bar.bank", "-o", "default.wav", "--json"]).ok();
    assert!(run.stderr.contains("no --at, so struck at"), "{}", run.stderr);
    let default = run.json();
    let vec3 = |v: &serde_json::Value| -> Vec<f64> {
        v.as_array().unwrap().iter().map(|c| c.as_f64().unwrap()).collect()
    };
    let (at, impulse) =
        (vec3(&default["strikes"][0]["surface_point"]), vec3(&default["strikes"][0]["impulse_ns"]));
    assert!(at[2].abs() < 1e-9 || (at[2] - 0.01).abs() < 1e-9, "{at:?} is not on a broad face");
    assert!(at[0] < 0.03 || at[0] > 0.27, "{at:?} is not near an end");
    assert!(impulse[0].abs() < 1e-9 && impulse[1].abs() < 1e-9 && (impulse[2].abs() - 0.01).abs() < 1e-12);
    let axial = |name: &str| {
        modal(dir.path(), &["strike", "bar.bank", "--at", "0.3,0,0", "--dir", "-1,0,0", "-o", name, "--json"])
            .ok()
            .json()
    };
    let corner = axial("corner.wav");
    assert!(default["peak"].as_f64().unwrap() > 5.0 * corner["peak"].as_f64().unwrap(), "{default} {corner}");
    assert!(wav_samples(&dir.path().join("default.wav")).iter().any(|&s| s.abs() > 100), "audible");
}

#[test]
fn bad_strikes_fail_cleanly_without_output() {
    let dir = temp_dir();
    bar_bank(dir.path());
    let at = ["--at", "0.05,0.01,0.01"];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["strike", "missing.bank", at[0], at[1], "-o", "x.wav"], "missing.bank"),
        (vec!["strike", "bar.bank", "--at", "5,5,5", "-o", "x.wav"], "from the surface"),
        (vec!["strike", "bar.bank", "--mic", "5,5,5", "-o", "x.wav"], "--mic 5,5,5: point"),
        (vec!["strike", "bar.bank", at[0], at[1], "--impulse", "nan", "-o", "x.wav"], "impulse"),
        (vec!["strike", "bar.bank", at[0], at[1], "--rate", "0", "-o", "x.wav"], "sample rate"),
        (vec!["strike", "bar.bank", at[0], at[1], "--duration", "-1", "-o", "x.wav"], "duration"),
        (vec!["strike", "bar.bank", at[0], at[1], "--time", "1", "--time", "2", "-o", "x.wav"], "--time"),
        (vec!["strike", "bar.bank", at[0], at[1], "--duration", "0", "-o", "x.wav"], "above 0 s"),
        (
            vec!["strike", "bar.bank", at[0], at[1], "--duration", "1e-5", "-o", "x.wav"],
            "shorter than one sample",
        ),
        (
            vec!["strike", "bar.bank", at[0], at[1], "--contact-time", "-1", "-o", "x.wav"],
            "contact time -1 s",
        ),
        (
            vec!["strike", "bar.bank", at[0], at[1], "--contact-time", "1e300", "-o", "x.wav"],
            "contact time 1e300 s",
        ),
        (vec!["strike", "bar.bank", at[0], at[1], "--hertz", "1e300,1e-300", "-o", "x.wav"], "--hertz needs"),
        (vec!["strike", "bar.bank", at[0], at[1], "--impulse", "1e300", "-o", "x.wav"], "-1e300]"),
        // Not blamed on a weak impulse: no strike falls inside the file.
        (
            vec!["strike", "bar.bank", at[0], at[1], "--time", "2", "--duration", "1", "-o", "x.wav"],
            "every strike",
        ),
        // Refused before any work (a --solve-radiation would be wasted).
        (
            vec!["strike", "bar.bank", "--solve-radiation", "-o", "bar.bank/x.wav"],
            "cannot create directory bar.bank",
        ),
        (vec!["strike", "bar.bank", "--solve-radiation", "-o", "."], "is a directory"),
    ];
    for (args, needle) in cases {
        modal(dir.path(), &args).fails_with(needle);
        assert!(!dir.path().join("x.wav").exists(), "no partial WAV for {args:?}");
    }
    // The output may not be the input: a WAV written over the bank destroyed it.
    modal(dir.path(), &["strike", "bar.bank", "-o", "bar.bank"]).fails_with("input file itself");
    modal(dir.path(), &["export", "bar.bank", "--vtk", "./bar.bank"]).fails_with("input file itself");
    modal(dir.path(), &["info", "bar.bank"]).ok();
    // A bank with one flipped bit in its tensor data fails its checksum.
    let mut bytes = std::fs::read(dir.path().join("bar.bank")).unwrap();
    let last = bytes.len() - 7;
    bytes[last] ^= 0x10;
    std::fs::write(dir.path().join("bad.bank"), bytes).unwrap();
    modal(dir.path(), &["strike", "bad.bank", at[0], at[1], "-o", "x.wav"]).fails_with("checksum");
    assert!(!dir.path().join("x.wav").exists());
    assert!(files_in(dir.path()).iter().all(|f| !f.ends_with(".tmp")));
}

/// A strike late in the file: the automatic length rings on after it (a
/// strike at 31 s wrote 30 s of silence, blamed on the strike's direction);
/// a time beyond the longest file, or negative, is refused before anything
/// is said or solved.
#[test]
fn a_late_strike_is_heard_and_an_impossible_time_is_refused_first() {
    let dir = temp_dir();
    bar_bank(dir.path());
    let late = modal(dir.path(), &["strike", "bar.bank", "--time", "31", "-o", "late.wav", "--json"]).ok();
    let report = late.json();
    assert!(report["duration_s"].as_f64().unwrap() > 31.0, "{report}");
    assert!(!late.stderr.contains("silent"), "{}", late.stderr);
    let samples = wav_samples(&dir.path().join("late.wav"));
    let start = (31.0 * report["sample_rate"].as_f64().unwrap()) as usize;
    assert!(samples[..start].iter().all(|&s| s == 0), "sound before the strike");
    assert!(samples[start..].iter().any(|&s| s.abs() > 100), "the strike is not heard");
    for time in ["-1", "1e9"] {
        let run =
            modal(dir.path(), &["strike", "bar.bank", "--time", time, "-o", "x.wav"]).fails_with("--time");
        assert!(!run.stderr.contains("strike: no --at"), "said before the refusal: {}", run.stderr);
    }
}

#[test]
fn a_strike_that_rounds_to_silence_says_so() {
    // A body heavy for its tap (a 35 kg beam, or a file read in the wrong unit)
    // rounds to zeros in 16-bit PCM: said, with the body's mass and what to change.
    let dir = temp_dir();
    bar_bank(dir.path());
    let faint = modal(dir.path(), &["strike", "bar.bank", "-o", "faint.wav", "--impulse", "1e-9"]).ok();
    assert!(wav_samples(&dir.path().join("faint.wav")).iter().all(|&s| s == 0));
    assert!(faint.stderr.contains("below half a step of 16-bit PCM"), "{}", faint.stderr);
    assert!(faint.stderr.contains("--impulse"), "{}", faint.stderr);
    let normalized = ["strike", "bar.bank", "-o", "n.wav", "--impulse", "1e-9", "--normalize"];
    assert!(!modal(dir.path(), &normalized).ok().stderr.contains("16-bit"));
    // True silence is said whatever the output format (--normalize has nothing to scale).
    let zero = ["strike", "bar.bank", "-o", "z.wav", "--impulse", "0", "--normalize", "--duration", "0.1"];
    let zero = modal(dir.path(), &zero).ok();
    assert!(zero.stderr.contains("is silent: the strikes excite none"), "{}", zero.stderr);
    let heard = modal(dir.path(), &["strike", "bar.bank", "-o", "heard.wav"]).ok();
    assert!(!heard.stderr.contains("16-bit"), "{}", heard.stderr);
}

#[test]
fn a_body_ringing_high_is_struck_with_a_contact_short_enough_to_excite_it() {
    // The bar made 20 times smaller rings 20 times higher; a fixed 0.1 ms
    // contact would sit near the half-sine's nulls there.
    let dir = temp_dir();
    bar_bank(dir.path());
    modal(dir.path(), &["retune", "bar.bank", "--scale", "0.05", "-o", "small.bank"]).ok();
    let low = modal(dir.path(), &["info", "small.bank", "--json"]).ok().json();
    let f0 = low["modes"][0]["frequency_hz"].as_f64().unwrap();
    assert!(f0 > 5000.0, "{f0}");
    let strike = |bank: &str| {
        let args = ["strike", bank, "-o", "s.wav", "--duration", "0.05", "--json"];
        modal(dir.path(), &args).ok().json()["contact_time_s"].as_f64().unwrap()
    };
    assert!((strike("small.bank") - 0.5 / f0).abs() < 1e-12 * f0.recip());
    assert_eq!(strike("bar.bank"), 1e-4, "a bar ringing below 5 kHz keeps the 0.1 ms mallet");
}

#[test]
fn tables_number_modes_as_json_and_radiation_mode_do() {
    // One numbering everywhere: from 0, as `--json`, `radiation --mode` and
    // every error message count (info and strike's tables counted from 1).
    let dir = temp_dir();
    bar_bank(dir.path());
    let info = modal(dir.path(), &["info", "bar.bank"]).ok().stdout;
    let header = info.lines().position(|l| l.trim_start().starts_with("mode ")).unwrap();
    let first_row = info.lines().nth(header + 1).unwrap();
    let f0 = modal(dir.path(), &["info", "bar.bank", "--json"]).ok().json()["modes"][0]["frequency_hz"]
        .as_f64()
        .unwrap();
    let cells: Vec<&str> = first_row.split_whitespace().collect();
    assert_eq!(cells[0], "0", "{first_row}");
    assert!((cells[1].parse::<f64>().unwrap() - f0).abs() < 1e-3, "{first_row} vs {f0}");
    let args = ["strike", "bar.bank", "--at", "0.05,0.01,0.01", "--duration", "0.1", "-o", "s.wav"];
    let human = modal(dir.path(), &args).ok().stdout;
    let json = modal(dir.path(), &[&args[..], &["--json"]].concat()).ok().json();
    let listed: Vec<u64> = human
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix("mode "))
        .map(|rest| rest.split_whitespace().next().unwrap().parse().unwrap())
        .collect();
    let want: Vec<u64> =
        json["top_modes"].as_array().unwrap().iter().map(|m| m["mode"].as_u64().unwrap()).collect();
    assert!(!want.is_empty());
    assert_eq!(listed, want);
    // Pressure at the listener is printed in Pa, not the contact microphone's m/s.
    assert!(human.contains(" Pa (0.0") && human.contains(" of full scale)  T60"), "{human}");
}

/// The level of a float WAV's component at `f_hz` (one DFT bin over the whole file).
fn level_at(path: &std::path::Path, f_hz: f64) -> f64 {
    let mut reader = hound::WavReader::open(path).unwrap();
    let fs = reader.spec().sample_rate as f64;
    let samples: Vec<f32> = reader.samples().map(Result::unwrap).collect();
    let w = 2.0 * std::f64::consts::PI * f_hz / fs;
    let (re, im) = samples.iter().enumerate().fold((0.0, 0.0), |(re, im), (n, &x)| {
        let (s, c) = (w * n as f64).sin_cos();
        (re + x as f64 * c, im - x as f64 * s)
    });
    20.0 * (re.hypot(im) / samples.len() as f64).log10()
}

#[test]
fn a_degenerate_pair_heard_through_the_estimate_does_not_cancel() {
    // A glass bowl's 2 967 Hz pair (0.004 Hz apart), struck radially on the rim,
    // heard without radiation data (the direction-free estimate). Real levels
    // summed the pair coherently, at a level set by how the eigensolver turned
    // it: −33.7 dB at 0°, −95 dB (cancelled) at 30° and −88 dB at 90° before
    // degenerate_phases put the pair in quadrature.
    let dir = temp_dir();
    let d = dir.path();
    let bowl = ["mesh", "bowl", "--radius", "0.06", "--thickness", "0.004", "--h", "0.008", "-o", "bowl.msh"];
    modal(d, &bowl).ok();
    modal(
        d,
        &["precompute", "bowl.msh", "--material", "glass", "--modes", "6", "-o", "bowl.bank", "--no-cache"],
    )
    .ok();
    let info = modal(d, &["info", "bowl.bank", "--json"]).ok().json();
    let f: Vec<f64> =
        info["modes"].as_array().unwrap().iter().map(|m| m["frequency_hz"].as_f64().unwrap()).collect();
    let pair = (0..f.len() - 1)
        .find(|&i| (f[i + 1] - f[i]) < 1e-5 * f[i])
        .expect("the bowl has an (almost) exactly degenerate pair");
    let levels: Vec<f64> = [0.0f64, 30.0, 90.0]
        .iter()
        .map(|deg| {
            let (s, c) = deg.to_radians().sin_cos();
            let v = |r: f64| format!("{},{},0", r * c, r * s);
            let out = format!("a{deg}.wav");
            let args = [
                "strike",
                "bowl.bank",
                "--at",
                &v(0.06),
                "--dir",
                &v(-1.0),
                "--listener",
                &v(0.46),
                "--duration",
                "0.5",
                "--float",
                "-o",
                &out,
            ];
            let run = modal(d, &args).ok();
            assert!(run.stderr.contains("no radiation data"), "{}", run.stderr);
            level_at(&d.join(out), f[pair])
        })
        .collect();
    let (lo, hi) = levels.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
    assert!(hi - lo < 0.5, "the pair's level depends on where the rim is struck: {levels:?} dB");
}
