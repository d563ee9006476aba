//! Error against cost of the radiation solve (BENCHMARKS.md "Acoustic
//! radiation", docs/radiation-pareto.png), from `modal radiation --json`
//! runs of one bank: a reference with one unknown per panel
//! (`--full-resolution`) and runs at several cluster sizes `--cluster-kh κ`,
//! same modes and points (crates/modal-radiation/bench/sweep.sh makes them).
//!
//! Per run: seconds per mode (solve + projection, from the progress lines
//! of the run's stderr), mean unknowns, and the level error [dB] of every
//! (mode, point) whose reference level is within 20 dB of the mode's
//! loudest point: median and max. Prints a Markdown table and draws the
//! Pareto plot (log-log, seconds per mode against max and median error).
//!
//! `cargo run -p modal-radiation --example pareto -- OUT.png REF.json REF.err RUN.json RUN.err LABEL [RUN.json RUN.err LABEL …]`
use modal_study::plot::{write_loglog_png, LogLogPlot, Series};
use serde_json::Value;

fn load(json: &str, err: &str) -> (Value, f64, f64) {
    let v: Value = serde_json::from_str(&std::fs::read_to_string(json).expect("json file")).expect("json");
    let text = std::fs::read_to_string(err).expect("stderr file");
    let (mut seconds, mut unknowns, mut groups) = (0.0, 0.0, 0.0);
    for line in text.lines().filter(|l| l.contains(" unknowns on ")) {
        let num = |key: &str| -> f64 {
            let at = line.find(key).expect("key");
            line[at + key.len()..].split_whitespace().next().unwrap().trim_end_matches(',').parse().unwrap()
        };
        seconds += num("solve ") + num("fit ");
        unknowns += line.split(", ").nth(1).unwrap().split(' ').next().unwrap().parse::<f64>().unwrap();
        groups += 1.0;
    }
    let modes = v["modes"].as_array().unwrap().len() as f64;
    (v, seconds / modes, unknowns / groups)
}

fn pressures(m: &Value) -> Vec<f64> {
    m["pressure_pa"]
        .as_array()
        .unwrap()
        .iter()
        .map(|z| z[0].as_f64().unwrap().hypot(z[1].as_f64().unwrap()))
        .collect()
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() < 6 || !(a.len() - 3).is_multiple_of(3) {
        eprintln!("usage: pareto OUT.png REF.json REF.err RUN.json RUN.err LABEL [RUN.json RUN.err LABEL …]");
        std::process::exit(2);
    }
    let (reference, ref_s, ref_n) = load(&a[1], &a[2]);
    println!("| run | s per mode | unknowns (mean) | median dB | max dB |");
    println!("|---|---|---|---|---|");
    println!("| full resolution | {ref_s:.2} | {ref_n:.0} | 0 | 0 |");
    let (mut max_curve, mut median_curve) = (vec![], vec![]);
    for run in a[3..].chunks(3) {
        let (v, s, n) = load(&run[0], &run[1]);
        let mut errs = Vec::new();
        for (m, r) in v["modes"].as_array().unwrap().iter().zip(reference["modes"].as_array().unwrap()) {
            assert_eq!(m["index"], r["index"], "same modes in the same order");
            let (p, q) = (pressures(m), pressures(r));
            let loudest = q.iter().copied().fold(0.0, f64::max);
            for (x, y) in p.iter().zip(&q) {
                if *y > 0.1 * loudest {
                    errs.push((20.0 * (x / y).log10()).abs());
                }
            }
        }
        errs.sort_by(f64::total_cmp);
        let (median, max) = (errs[errs.len() / 2], errs[errs.len() - 1]);
        println!("| {} | {s:.2} | {n:.0} | {median:.3} | {max:.3} |", run[2]);
        max_curve.push((s, max));
        median_curve.push((s, median));
    }
    let series = [
        Series { label: "max error".into(), points: max_curve },
        Series { label: "median error".into(), points: median_curve },
    ];
    let plot = LogLogPlot {
        title: "Radiation of the steel bar's modes: error against cost",
        x_label: "seconds per mode (solve + projection)",
        y_label: "level error at 2 bounding radii [dB]",
        series: &series,
    };
    write_loglog_png(std::path::Path::new(&a[0]), &plot).expect("plot written");
}
