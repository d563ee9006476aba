//! `modal bench eigen` on a tiny box so the benchmark command cannot rot: the JSON
//! report, the child-process measurements, the temporary directory clean-up and the
//! clear error when Python/scipy is missing. Timings are never asserted.

mod common;
use common::*;
use std::path::Path;

/// Runs `modal bench eigen ARGS` with TMPDIR inside `dir`.
fn bench(dir: &Path, args: &[&str]) -> Run {
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    let args: Vec<&str> = ["bench", "eigen"].into_iter().chain(args.iter().copied()).collect();
    modal_with_env(dir, &args, &[("TMPDIR", &tmp)])
}

#[test]
fn skip_scipy_reports_our_side_and_cleans_up() {
    let dir = temp_dir();
    let json = bench(dir.path(), &["--skip-scipy", "--dofs", "3000", "--modes", "6", "--json"]).ok().json();
    let rows = json.as_array().expect("an array of sizes");
    assert_eq!(rows.len(), 1);
    let r = &rows[0];
    let dofs = r["dofs"].as_u64().unwrap();
    // Closest TET10 box to 3000 DOF: 5 × 3 × 2 cells → 11 · 7 · 5 nodes · 3 = 1155 is farther
    // than 6 × 4 × 3 → 13 · 9 · 7 · 3 = 2457, and 7 × 5 × 4 → 15 · 11 · 9 · 3 = 4455.
    assert!((2000..=4500).contains(&dofs), "dofs {dofs}");
    assert_eq!(dofs % 3, 0);
    assert_eq!(r["modes"], 6);
    assert_eq!(r["inertia_check"]["expected"], r["inertia_check"]["found"]);
    assert!(r["max_residual"].as_f64().unwrap() <= 1e-8);
    assert!(r["precompute_wall_s"].as_f64().unwrap() > 0.0);
    assert!(r["precompute_peak_rss_mb"].as_f64().unwrap() > 1.0);
    for key in ["assemble", "factor", "solve"] {
        assert!(r["timings_s"][key].as_f64().is_some(), "timing {key}");
    }
    assert!(r.get("scipy").is_none() && r.get("ratio").is_none());
    let left: Vec<_> = std::fs::read_dir(dir.path().join("tmp")).unwrap().collect();
    assert!(left.is_empty(), "temporary files left behind: {left:?}");
}

#[test]
fn markdown_table_has_a_row_per_size() {
    let dir = temp_dir();
    let run = bench(dir.path(), &["--skip-scipy", "--dofs", "1500,3000", "--modes", "4"]).ok();
    let rows: Vec<&str> =
        run.stdout.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| DOF")).collect();
    assert_eq!(rows.len(), 2, "{}", run.stdout);
    assert!(rows.iter().all(|r| r.split('|').nth(2).unwrap().trim() == "4"), "{}", run.stdout);
}

#[test]
fn missing_python_is_a_clear_error() {
    let dir = temp_dir();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
    bench(
        dir.path(),
        &["--dofs", "3000", "--python", "/nonexistent/python3", "--scipy-script", script.to_str().unwrap()],
    )
    .fails_with("--skip-scipy");
    bench(dir.path(), &["--dofs", "3000", "--scipy-script", "/nonexistent/scipy_eigs.py"])
        .fails_with("does not exist");
}

#[test]
fn bad_sizes_are_rejected() {
    let dir = temp_dir();
    bench(dir.path(), &["--skip-scipy", "--dofs", "10"]).fails_with("--dofs");
    bench(dir.path(), &["--skip-scipy", "--modes", "0"]).fails_with("--modes");
}
