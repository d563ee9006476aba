//! Issue 14, item 4: the per-mode `error_estimate_pct` of `modal precompute` and
//! `modal info`, and `--accuracy PCT`.
//!
//! The estimate is checked against independent references: the free steel sphere
//! (Lamb, analytic) and the free-free steel bar (the 3D-converged table of
//! `shared/reference/analytic.md`), both given as surface meshes at coarse cells so
//! that the discretization error is large and known. The estimate must bracket it.

mod common;

use std::path::Path;

use common::{modal, temp_dir};
use modal_study::reference::{sphere_lamb_hz, BAR_FREE_HZ, BAR_SIZE, SPHERE_RADIUS};
use modal_tetra::{shapes, write_obj, TriSurface};

const STEEL: [&str; 6] = ["--youngs", "2e11", "--poisson", "0.3", "--density", "7850"];

fn write_surface(dir: &Path, name: &str, surface: &TriSurface) -> String {
    let path = dir.join(name);
    write_obj(surface, std::fs::File::create(&path).unwrap()).unwrap();
    path.display().to_string()
}

/// (frequency, estimate) of every mode of a `--json` report.
fn modes(report: &serde_json::Value) -> Vec<(f64, Option<f64>)> {
    report["modes"]
        .as_array()
        .expect("modes")
        .iter()
        .map(|m| (m["frequency_hz"].as_f64().unwrap(), m["error_estimate_pct"].as_f64()))
        .collect()
}

/// Runs precompute on `obj` with `extra` flags; returns the JSON report and stderr.
fn precompute(dir: &Path, obj: &str, extra: &[&str]) -> (serde_json::Value, String) {
    let mut args = vec!["precompute", obj, "-o", "out.bank", "--no-cache", "--json", "--max-freq", "1e6"];
    args.extend_from_slice(&STEEL);
    args.extend_from_slice(extra);
    let run = modal(dir, &args).ok();
    (run.json(), run.stderr)
}

/// Every estimate present, and ≥ the true error against `reference` (Hz, same order).
/// Returns (largest true error, largest estimate) in %.
fn assert_brackets(what: &str, got: &[(f64, Option<f64>)], reference: &[f64]) -> (f64, f64) {
    let (mut worst_true, mut worst_est) = (0.0_f64, 0.0_f64);
    for (k, (&(f, est), &want)) in got.iter().zip(reference).enumerate() {
        let est = est.unwrap_or_else(|| panic!("{what}: mode {} has no estimate: {got:?}", k + 1));
        let truth = 100.0 * (f / want - 1.0).abs();
        assert!(
            est >= truth,
            "{what}: mode {} at {f:.1} Hz (reference {want:.1}): estimate {est:.3} % < true {truth:.3} %",
            k + 1
        );
        worst_true = worst_true.max(truth);
        worst_est = worst_est.max(est);
    }
    (worst_true, worst_est)
}

#[test]
fn sphere_estimate_brackets_the_lamb_error_in_the_quintuplets() {
    let dir = temp_dir();
    let obj = write_surface(dir.path(), "sphere.obj", &shapes::icosphere(SPHERE_RADIUS, 4));
    let (report, stderr) = precompute(dir.path(), &obj, &["--cell", "0.02", "--modes", "20"]);
    let got = modes(&report);
    assert_eq!(got.len(), 20, "{stderr}");
    let lamb = sphere_lamb_hz(SPHERE_RADIUS);
    let (worst_true, worst_est) = assert_brackets("sphere, cell 2 cm", &got, &lamb);
    eprintln!("sphere: worst true {worst_true:.3} %, worst estimate {worst_est:.3} %");
    // Not vacuous: the discretization error is resolved, not drowned in a huge bound.
    assert!(worst_true > 0.2, "the test needs a visible error, got {worst_true:.3} %");
    assert!(worst_est < 8.0 * worst_true, "estimate {worst_est:.3} % is too loose for {worst_true:.3} %");
    let method = report["error_estimate_method"].as_str().expect("method named");
    assert!(method.contains("two-level"), "{method}");
}

#[test]
fn bar_estimate_brackets_the_converged_table() {
    let dir = temp_dir();
    let [x, y, z] = BAR_SIZE;
    let obj = write_surface(dir.path(), "bar.obj", &shapes::cuboid(x, y, z));
    let (report, stderr) = precompute(dir.path(), &obj, &["--cell", "0.005", "--modes", "12"]);
    let got = modes(&report);
    assert_eq!(got.len(), 12, "{stderr}");
    let (worst_true, worst_est) = assert_brackets("bar, cell 5 mm", &got, &BAR_FREE_HZ);
    // Measured: true ≤ 0.19 %, estimate up to 4.7 %: safe but loose here, because the
    // coarse level (7.5 mm) has only 1.3 cells across the 1 cm thickness and is far
    // from the asymptotic range (see BENCHMARKS.md, "Real assets").
    eprintln!("bar: worst true {worst_true:.3} %, worst estimate {worst_est:.3} %");
}

#[test]
fn tet_mesh_files_get_no_estimate_and_say_why() {
    let dir = temp_dir();
    let msh = dir.path().join("box.msh");
    let msh_s = msh.display().to_string();
    modal(dir.path(), &["mesh", "box", "--size", "0.1,0.05,0.04", "--h", "0.02", "-o", &msh_s]).ok();
    let (report, stderr) = precompute(dir.path(), &msh_s, &["--modes", "4"]);
    assert!(stderr.contains("no error estimate: a tet mesh file is solved as given"), "{stderr}");
    assert!(modes(&report).iter().all(|(_, e)| e.is_none()), "{report}");
    assert!(report["modes"][0].get("error_estimate_pct").is_some(), "the field is always present (null)");
    assert!(report["error_estimate_method"].is_null());
    // `modal info` shows the same, in text and JSON.
    let info = modal(dir.path(), &["info", "out.bank"]).ok();
    assert!(info.stdout.contains("error %: no estimate in this bank"), "{}", info.stdout);
    let info_json = modal(dir.path(), &["info", "out.bank", "--json"]).ok().json();
    assert!(info_json["modes"][0]["error_estimate_pct"].is_null());
}

#[test]
fn accuracy_off_skips_the_estimate_and_bad_values_are_one_error_line() {
    let dir = temp_dir();
    let obj = write_surface(dir.path(), "sphere.obj", &shapes::icosphere(SPHERE_RADIUS, 2));
    let (report, _) = precompute(dir.path(), &obj, &["--cell", "0.02", "--modes", "5", "--accuracy", "off"]);
    assert!(modes(&report).iter().all(|(_, e)| e.is_none()));
    for bad in ["0", "-1", "abc", "nan"] {
        let run = modal(dir.path(), &["precompute", &obj, "-o", "x.bank", "--accuracy", bad]);
        assert!(
            !run.success && run.stderr.contains("--accuracy") && !run.stderr.contains("panicked"),
            "{bad}: {}",
            run.stderr
        );
    }
    let mut args = vec!["precompute", obj.as_str(), "-o", "x.bank", "--accuracy-modes", "0"];
    args.extend_from_slice(&STEEL);
    modal(dir.path(), &args).fails_with("at least one mode");
}

#[test]
fn info_shows_the_estimate_of_each_mode() {
    let dir = temp_dir();
    let obj = write_surface(dir.path(), "sphere.obj", &shapes::icosphere(SPHERE_RADIUS, 2));
    let (report, _) = precompute(dir.path(), &obj, &["--cell", "0.02", "--modes", "6"]);
    let info = modal(dir.path(), &["info", "out.bank", "--json"]).ok().json();
    assert_eq!(modes(&info), modes(&report), "info reads back what precompute wrote");
    assert!(modes(&info).iter().all(|(_, e)| e.is_some()));
    let text = modal(dir.path(), &["info", "out.bank"]).ok().stdout;
    assert!(text.contains("error %") && text.contains("two-level Richardson"), "{text}");
}
