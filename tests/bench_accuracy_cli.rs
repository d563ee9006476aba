//! `modal bench accuracy`: a one-level run writes its JSON report and plots, and
//! `--replot` redraws exactly those plots from the saved report without solving.

mod common;
use common::*;

#[test]
fn replot_from_saved_report_redraws_the_same_pngs() {
    let dir = temp_dir();
    let args = ["bench", "accuracy", "--shapes", "sphere", "--orders", "2", "--levels", "1"];
    modal(dir.path(), &[&args[..], &["--json", "--out", "r.json", "--plot-dir", "first"]].concat()).ok();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    let cases = report["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 1);
    assert!(cases[0]["comparison"]["max_relative_error"].as_f64().unwrap() < 0.1, "{report}");

    let run = modal(dir.path(), &["bench", "accuracy", "--replot", "r.json", "--plot-dir", "again"]).ok();
    let printed = run.stdout;
    assert_eq!(files_in(&dir.path().join("first")), files_in(&dir.path().join("again")));
    for name in files_in(&dir.path().join("first")) {
        assert!(printed.contains(&name), "{name} listed in {printed}");
        let a = std::fs::read(dir.path().join("first").join(&name)).unwrap();
        let b = std::fs::read(dir.path().join("again").join(&name)).unwrap();
        assert!(a.len() > 1000 && a == b, "{name}: replot differs from the original plot");
    }
}

#[test]
fn replot_rejects_what_is_not_a_report() {
    let dir = temp_dir();
    std::fs::write(dir.path().join("bad.json"), "{\"cases\": 3}").unwrap();
    modal(dir.path(), &["bench", "accuracy", "--replot", "bad.json"])
        .fails_with("is not a `modal bench accuracy --json` report");
    modal(dir.path(), &["bench", "accuracy", "--replot", "missing.json"])
        .fails_with("cannot read missing.json");
    std::fs::write(
        dir.path().join("empty.json"),
        r#"{"cases":[],"rates":[],"target_error":0.01,"cheapest":[],"plots":[]}"#,
    )
    .unwrap();
    modal(dir.path(), &["bench", "accuracy", "--replot", "empty.json"]).fails_with("has no cases to plot");
}
