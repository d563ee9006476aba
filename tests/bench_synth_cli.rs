//! `modal bench synth` stays runnable: a tiny run prints its table, its JSON
//! has one row per variant with sane errors, and bad options fail cleanly.

mod common;
use common::*;

#[test]
fn bench_synth_small_run_reports_error_and_cost() {
    let dir = temp_dir();
    let run = modal(
        dir.path(),
        &[
            "bench",
            "synth",
            "--seconds",
            "0.2",
            "--modes",
            "50",
            "--repeats",
            "1",
            "--json",
            "--out",
            "r.json",
        ],
    )
    .ok();
    let json = run.json();
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    assert_eq!(json, file, "--out holds the printed JSON");
    assert_eq!(json["modes"], 50);
    let materials = json["materials"].as_array().unwrap();
    assert_eq!(materials.len(), 2);
    for m in materials {
        let rows = m["rows"].as_array().unwrap();
        // f64 ×2, f32 SIMD + portable, culling ×3, budgets 25/12/5.
        assert_eq!(rows.len(), 10, "{m}");
        for r in rows {
            let err = r["rel_rms_error"].as_f64().unwrap();
            // Without a budget every path is within -60 dB of the closed form;
            // a budget of 5 of 50 modes may lose most of the signal, never more.
            let bound = if r["budget"].is_null() { 1e-3 } else { 1.0 };
            assert!(err.is_finite() && err >= 0.0 && err < bound, "{r}");
            assert!(r["realtime_factor"].as_f64().unwrap() > 0.0, "{r}");
        }
        let f64_off = &rows[0];
        assert_eq!(f64_off["kernel"], "f64_scalar");
        assert!(f64_off["max_error_rel_peak"].as_f64().unwrap() < 1e-6, "{f64_off}");
    }
    let table =
        modal(dir.path(), &["bench", "synth", "--seconds", "0.2", "--modes", "50", "--repeats", "1"]).ok();
    assert!(table.stdout.contains("| f32 SIMD, cull -100 dB |"), "{}", table.stdout);
}

#[test]
fn bench_synth_rejects_bad_options() {
    let dir = temp_dir();
    modal(dir.path(), &["bench", "synth", "--seconds", "0"]).fails_with("--seconds");
    modal(dir.path(), &["bench", "synth", "--seconds", "NaN"]).fails_with("--seconds");
    modal(dir.path(), &["bench", "synth", "--modes", "0"]).fails_with("--modes");
    assert!(files_in(dir.path()).iter().all(|f| f == "cache"), "{:?}", files_in(dir.path()));
}
