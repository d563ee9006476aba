//! `modal render` hears each mode through its acoustic transfer by default:
//! the transfer of a mesh asset is solved once (boundary elements), cached
//! beside its bank and read back bit-exactly; `--radiation estimate` skips
//! it. Issue 15, "the demo renders with radiation".

mod common;
use common::*;

/// A 12 cm steel bar (1 × 1 cm) dropped onto the floor, mono, band up to
/// 7.2 kHz: its first bending pair (≈ 3.6 kHz) is heard, little else.
const BAR: &str = r#"
duration = 0.5
sample_rate = 16000
[listener]
position = [0.0, 0.2, 0.5]
channels = "mono"
[ground]
material = "wood"
[[objects]]
name = "bar"
mesh = { generate = "box", size = [0.12, 0.01, 0.01], element_size = 0.005 }
material = "steel"
position = [0.0, 0.05, 0.0]
rotation = { euler = [0.0, 0.0, 10.0] }
"#;

#[test]
fn render_solves_the_transfer_by_default_caches_it_and_can_skip_it() {
    let dir = temp_dir();
    std::fs::write(dir.path().join("s.toml"), BAR).unwrap();
    let args = ["render", "s.toml", "-o", "t.wav", "--json"];

    // First run: bank and transfer solved; progress on stderr.
    let first = modal(dir.path(), &args).ok();
    assert!(first.stderr.contains("acoustic transfer of generated box: solving"), "{}", first.stderr);
    let report = first.json();
    let solved = report["radiation_solved"].as_array().unwrap();
    assert_eq!(solved.len(), 1, "{report}");
    let modes = solved[0]["modes"].as_u64().unwrap();
    assert!(modes >= 1, "{report}");
    let bar = &report["objects"][0];
    assert_eq!(bar["modes_with_transfer"].as_u64().unwrap(), modes, "{bar}");
    assert!(bar["impacts"].as_u64().unwrap() >= 1);
    let levels = bar["mode_levels"].as_array().unwrap();
    assert_eq!(levels.len() as u64, modes);
    for l in levels {
        let t = l["transfer_pa_m"].as_f64().unwrap();
        assert!(t.is_finite() && t > 0.0, "{l}");
    }
    let transfer_wav = std::fs::read(dir.path().join("t.wav")).unwrap();

    // Second run: everything from the cache, nothing solved, same samples.
    let second = modal(dir.path(), &args).ok().json();
    assert_eq!(second["radiation_solved"].as_array().unwrap().len(), 0, "{second}");
    assert_eq!(second["objects"][0]["modes_with_transfer"].as_u64().unwrap(), modes);
    assert_eq!(std::fs::read(dir.path().join("t.wav")).unwrap(), transfer_wav);

    // Opt out: the estimate, nothing solved, a different sound.
    let est = modal(dir.path(), &["render", "s.toml", "-o", "e.wav", "--json", "--radiation", "estimate"])
        .ok()
        .json();
    assert_eq!(est["objects"][0]["modes_with_transfer"].as_u64().unwrap(), 0, "{est}");
    assert_eq!(est["radiation_solved"].as_array().unwrap().len(), 0);
    assert_ne!(std::fs::read(dir.path().join("e.wav")).unwrap(), transfer_wav);
}

#[test]
fn bad_radiation_choice_is_one_clear_error() {
    let dir = temp_dir();
    let run = modal(dir.path(), &["render", "--radiation", "loud"]);
    assert!(!run.success && !run.stderr.contains("panicked"), "{}", run.stderr);
    assert!(run.stderr.contains("transfer") && run.stderr.contains("estimate"), "{}", run.stderr);
    std::fs::write(dir.path().join("s.toml"), BAR).unwrap();
    modal(dir.path(), &["render", "s.toml", "--transfer-max-freq", "0"]).fails_with("--transfer-max-freq");
    // A negative value gets the same check's words, as in `strike`, not
    // clap's "unexpected argument".
    modal(dir.path(), &["render", "s.toml", "--transfer-max-freq", "-5"])
        .fails_with("--transfer-max-freq must be a positive frequency");
}
