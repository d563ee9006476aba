//! `modal bench accuracy`: error of the first modes against analytic / converged
//! references versus run time, TET4 and TET10 × mesh levels, for the free-free bar,
//! the free sphere and the cantilever (library: `modal_study`).
//!
//! Each case runs in its own child process (`modal bench accuracy --case bar:2:3`,
//! which prints one JSON line) so that its peak memory (`VmHWM`) is its own. The
//! parent collects the cases, fits convergence rates, writes the PNG plots and prints a
//! markdown report (or JSON with `--json`).

use crate::cli::output::warn;
use crate::cli::write_atomic;
use anyhow::{bail, Context, Result};
use clap::Args;
use modal_study::{order_name, CaseResult, CaseSpec, StudyReport, StudyShape};
use std::io::Write;
use std::path::PathBuf;
use std::process::Command;

/// Options of `modal bench accuracy`.
#[derive(Debug, Args)]
pub struct AccuracyBenchArgs {
    /// Shapes to study, comma separated: bar, sphere, cantilever.
    #[arg(long, value_delimiter = ',', default_value = "bar,sphere,cantilever")]
    shapes: Vec<String>,
    /// Element orders, comma separated: 1 (TET4), 2 (TET10).
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    orders: Vec<u8>,
    /// Mesh levels per shape and order (1-12); the element size halves every two levels.
    #[arg(long, default_value_t = 5)]
    levels: usize,
    /// Write the report to this file instead of stdout.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Report as JSON instead of markdown.
    #[arg(long)]
    json: bool,
    /// Directory for the PNG plots (created if missing).
    #[arg(long, default_value = "docs/accuracy")]
    plot_dir: PathBuf,
    /// Time budget of one case (s): a shape and order stops refining when its previous level
    /// took more than a quarter of it (each level has about 2.8 times the DOFs).
    #[arg(long, default_value_t = 120.0)]
    max_case_seconds: f64,
    /// Max relative error the mesh-size recommendation aims for.
    #[arg(long, default_value_t = 0.01)]
    target_error: f64,
    /// Redraw the PNG plots from a saved `--json` report instead of running the cases
    /// (for example after a change to the plotting); prints the plot paths.
    #[arg(long, value_name = "REPORT.json", conflicts_with_all = ["case", "shapes", "orders", "levels"])]
    replot: Option<PathBuf>,
    /// Run one case (shape:order:level or shape:order:h=<mm>) in this process and print it
    /// as one JSON line.
    #[arg(long, hide = true)]
    case: Option<String>,
}

/// Runs the benchmark.
pub fn run(args: AccuracyBenchArgs) -> Result<()> {
    if let Some(case) = &args.case {
        return run_child(case);
    }
    if let Some(saved) = &args.replot {
        return replot(saved, &args.plot_dir);
    }
    let specs = plan(&args)?;
    let cases = run_cases(&specs, args.max_case_seconds)?;
    let mut report = StudyReport::new(cases, args.target_error);
    std::fs::create_dir_all(&args.plot_dir)
        .with_context(|| format!("cannot create plot directory {}", args.plot_dir.display()))?;
    report.write_plots(&args.plot_dir)?;
    let text = if args.json { serde_json::to_string_pretty(&report)? + "\n" } else { report.to_markdown() };
    match &args.out {
        Some(path) => write_atomic(path, |tmp| Ok(std::fs::write(tmp, &text)?))
            .with_context(|| format!("cannot write {}", path.display())),
        None => Ok(std::io::stdout().lock().write_all(text.as_bytes())?),
    }
}

/// `--replot`: the plots of a saved report, drawn again without solving anything.
fn replot(saved: &std::path::Path, plot_dir: &std::path::Path) -> Result<()> {
    let text = std::fs::read_to_string(saved).with_context(|| format!("cannot read {}", saved.display()))?;
    let mut report: StudyReport = serde_json::from_str(&text)
        .with_context(|| format!("{} is not a `modal bench accuracy --json` report", saved.display()))?;
    if report.cases.is_empty() {
        bail!("{} has no cases to plot", saved.display());
    }
    report.plots.clear();
    std::fs::create_dir_all(plot_dir)
        .with_context(|| format!("cannot create plot directory {}", plot_dir.display()))?;
    report.write_plots(plot_dir)?;
    let mut out = std::io::stdout().lock();
    for path in &report.plots {
        writeln!(out, "{}", path.display())?;
    }
    Ok(())
}

/// The hidden `--case` mode: one case, one JSON line with this process's peak memory.
fn run_child(case: &str) -> Result<()> {
    let spec = CaseSpec::parse(case)?;
    let mut result = modal_study::run_case(spec).with_context(|| format!("case {case}"))?;
    result.peak_rss_bytes = modal_study::peak_rss_bytes();
    let mut out = std::io::stdout().lock();
    serde_json::to_writer(&mut out, &result)?;
    writeln!(out)?;
    Ok(())
}

/// Validated case list: shapes × orders × levels.
fn plan(args: &AccuracyBenchArgs) -> Result<Vec<CaseSpec>> {
    if !(1..=12).contains(&args.levels) {
        bail!("--levels must be between 1 and 12, got {}", args.levels);
    }
    if !(args.target_error > 0.0 && args.target_error < 1.0) {
        bail!("--target-error must be in (0, 1), got {}", args.target_error);
    }
    if let Some(bad) = args.orders.iter().find(|o| !(1..=2).contains(*o)) {
        bail!("--orders accepts 1 and 2, got {bad}");
    }
    let shapes =
        args.shapes.iter().map(|s| StudyShape::from_name(s.trim())).collect::<Result<Vec<_>, _>>()?;
    let mut specs = Vec::new();
    for &shape in &shapes {
        for &order in &args.orders {
            specs.extend((0..args.levels).map(|level| CaseSpec::new(shape, order, level)));
        }
    }
    Ok(specs)
}

/// Growth of a case's run time from one level to the next, assumed by the skip rule.
const LEVEL_TIME_GROWTH: f64 = 4.0;

/// Runs every case in a child process. A shape/order ladder stops refining when the
/// previous level predicts more than `max_case_seconds`, or after a failed case (reported
/// as a warning: the other ladders still run).
fn run_cases(specs: &[CaseSpec], max_case_seconds: f64) -> Result<Vec<CaseResult>> {
    let exe = std::env::current_exe().context("cannot locate the modal executable")?;
    let mut results: Vec<CaseResult> = Vec::new();
    let mut stopped: Vec<(StudyShape, u8)> = Vec::new();
    for spec in specs {
        if stopped.contains(&(spec.shape, spec.order)) {
            continue;
        }
        let too_slow = results.iter().any(|r| {
            r.spec.shape == spec.shape
                && r.spec.order == spec.order
                && r.total_s * LEVEL_TIME_GROWTH > max_case_seconds
        });
        if too_slow {
            warn(&format!(
                "skipping {} and finer: the previous level predicts more than {max_case_seconds} s",
                spec.label()
            ));
            stopped.push((spec.shape, spec.order));
            continue;
        }
        let result = match run_child_case(&exe, spec) {
            Ok(r) => r,
            Err(e) => {
                warn(&format!("{e:#}; finer levels of this shape and order are skipped"));
                stopped.push((spec.shape, spec.order));
                continue;
            }
        };
        eprintln!(
            "{:<10} {:<5} level {}: {:>7} DOF, {:>7.2} s, max rel. error {:.2e}",
            spec.shape.name(),
            order_name(spec.order),
            spec.level,
            result.dofs,
            result.total_s,
            result.comparison.max_relative_error
        );
        results.push(result);
    }
    if results.is_empty() {
        bail!("no study case finished");
    }
    Ok(results)
}

/// Runs `spec` in a child process and parses its JSON line.
fn run_child_case(exe: &std::path::Path, spec: &CaseSpec) -> Result<CaseResult> {
    let out = Command::new(exe)
        .args(["bench", "accuracy", "--case", &spec.label()])
        .output()
        .with_context(|| format!("cannot start {} for case {}", exe.display(), spec.label()))?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        bail!("case {} failed: {}", spec.label(), stderr.trim());
    }
    serde_json::from_slice(&out.stdout)
        .with_context(|| format!("case {} printed no valid result", spec.label()))
}
