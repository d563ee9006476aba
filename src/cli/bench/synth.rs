//! `modal bench synth`: synthesis error versus cost (issue 7).
//!
//! For each material (steel, glass: Rayleigh α, β of the presets) a
//! realistic synthetic bank (`modal_synth::study::Scenario::realistic`:
//! `--modes` modes log-spaced 50 Hz – 20 kHz, seeded random shapes and
//! gains, four strikes incl. overlapping contacts) is rendered by every
//! variant of `modal_synth::study::standard_variants` (f64 scalar path, f32
//! SIMD and portable kernels, culling −60/−80/−100 dB and off, budgets) on
//! one thread and compared with the f64 closed form. Prints a table (or
//! JSON), optionally writes the JSON to `--out` and a log-log plot of error
//! vs cost to `--plot`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use modal_study::plot::{write_loglog_png, LogLogPlot, Series};
use modal_synth::kernel::SimdPath;
use modal_synth::study::{measure, standard_variants, Measurement, Scenario};
use modal_synth::Kernel;
use serde::Serialize;

use crate::cli::{output, write_atomic};

/// Largest accepted `--modes` (bounds memory and run time).
const MAX_MODES: usize = 100_000;
/// Longest accepted `--seconds`.
const MAX_SECONDS: f64 = 600.0;
/// Materials measured (presets of `modal_fem::Material`).
const MATERIALS: [&str; 2] = ["steel", "glass"];

/// Options of `modal bench synth`.
#[derive(Debug, Args)]
pub struct SynthBenchArgs {
    /// Rendered audio per variant [s].
    #[arg(long, default_value_t = 2.0)]
    pub seconds: f64,
    /// Modes in the synthetic bank.
    #[arg(long, default_value_t = 1000)]
    pub modes: usize,
    /// Timed repeats per variant (the fastest counts).
    #[arg(long, default_value_t = 3)]
    pub repeats: usize,
    /// Seed of the random shapes and gains.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Also write the JSON results to this file.
    #[arg(long, value_name = "PATH")]
    pub out: Option<PathBuf>,
    /// Write a log-log PNG of error vs cost to this file.
    #[arg(long, value_name = "PATH")]
    pub plot: Option<PathBuf>,
}

/// One measured variant, as reported.
#[derive(Debug, Serialize)]
struct Row {
    label: String,
    kernel: &'static str,
    cull_db: Option<f64>,
    budget: Option<usize>,
    rel_rms_error: f64,
    rel_rms_error_db: f64,
    max_error_rel_peak: f64,
    max_error_rel_peak_db: f64,
    wall_s: f64,
    mode_samples: u64,
    mode_samples_per_s: f64,
    realtime_factor: f64,
    modes_culled: u64,
}

/// All variants of one material.
#[derive(Debug, Serialize)]
struct MaterialReport {
    material: &'static str,
    reference_terms: usize,
    reference_wall_s: f64,
    peak: f64,
    rows: Vec<Row>,
}

/// The whole benchmark, as printed with `--json`.
#[derive(Debug, Serialize)]
struct Report {
    modes: usize,
    seconds: f64,
    sample_rate_hz: f64,
    seed: u64,
    repeats: usize,
    threads: usize,
    simd_path: String,
    materials: Vec<MaterialReport>,
    plot: Option<String>,
    plot_error: Option<String>,
}

fn kernel_name(k: Kernel) -> &'static str {
    match k {
        Kernel::Reference => "f64_scalar",
        Kernel::Portable => "f32_portable",
        Kernel::Auto => "f32_simd",
    }
}

fn row(m: &Measurement) -> Row {
    Row {
        label: m.variant.label.clone(),
        kernel: kernel_name(m.variant.kernel),
        cull_db: m.variant.cull_db,
        budget: m.variant.budget,
        rel_rms_error: m.error.rel_rms,
        rel_rms_error_db: m.error.rel_rms_db(),
        max_error_rel_peak: m.error.max_rel,
        max_error_rel_peak_db: m.error.max_rel_db(),
        wall_s: m.wall_s,
        mode_samples: m.mode_samples,
        mode_samples_per_s: m.mode_samples_per_s(),
        realtime_factor: m.realtime_factor(),
        modes_culled: m.modes_culled,
    }
}

fn check_args(args: &SynthBenchArgs) -> anyhow::Result<()> {
    if !(args.seconds.is_finite() && args.seconds > 0.0 && args.seconds <= MAX_SECONDS) {
        anyhow::bail!("--seconds {} must be within (0, {MAX_SECONDS}]", args.seconds);
    }
    if args.modes == 0 || args.modes > MAX_MODES {
        anyhow::bail!("--modes {} must be within 1..={MAX_MODES}", args.modes);
    }
    if args.repeats == 0 || args.repeats > 100 {
        anyhow::bail!("--repeats {} must be within 1..=100", args.repeats);
    }
    Ok(())
}

fn run_material(material: &'static str, args: &SynthBenchArgs) -> anyhow::Result<MaterialReport> {
    let scenario = Scenario::realistic(material, args.modes, args.seconds, args.seed);
    let start = Instant::now();
    let reference = scenario.reference().with_context(|| format!("{material}: closed-form reference"))?;
    let reference_wall_s = start.elapsed().as_secs_f64();
    let reference_terms =
        modal_synth::ClosedForm::new(&scenario.bank, &scenario.strikes, &scenario.options)?.term_count();
    let mut rows = Vec::new();
    let mut peak = 0.0;
    for variant in standard_variants(args.modes) {
        let m = measure(&scenario, &reference, &variant, args.repeats)
            .with_context(|| format!("{material}: {}", variant.label))?;
        peak = m.error.peak;
        rows.push(row(&m));
    }
    Ok(MaterialReport { material, reference_terms, reference_wall_s, peak, rows })
}

/// Selects the rows of one plotted curve.
type RowFilter = fn(&Row) -> bool;

/// Cost (wall seconds per audio second) vs relative RMS error, one curve per
/// material and family of variants: f32 SIMD culling sweep (off, −100, −80,
/// −60 dB), f32 SIMD budgets (at −100 dB, with the unlimited point), the f64
/// scalar path (off, −100 dB) and the portable ("plain", no run-time SIMD
/// dispatch) f32 kernel (culling off).
/// Labels stay short: the legend has room for about 20 characters.
fn plot_series(materials: &[MaterialReport]) -> Vec<Series> {
    let families: [(&str, RowFilter); 4] = [
        ("f32 cull", |r| r.kernel == "f32_simd" && r.budget.is_none()),
        ("f32 budget", |r| r.kernel == "f32_simd" && (r.budget.is_some() || r.cull_db == Some(-100.0))),
        ("f64 scalar", |r| r.kernel == "f64_scalar"),
        ("f32 plain", |r| r.kernel == "f32_portable"),
    ];
    let mut series = Vec::new();
    for m in materials {
        for (name, keep) in &families {
            let mut points: Vec<(f64, f64)> = m
                .rows
                .iter()
                .filter(|r| keep(r))
                .map(|r| (1.0 / r.realtime_factor, r.rel_rms_error))
                .collect();
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            series.push(Series { label: format!("{} {name}", m.material), points });
        }
    }
    series
}

fn print_table(report: &Report) {
    println!(
        "Synthesis error vs cost: {} modes (50 Hz-20 kHz, log-spaced), {} s at {} Hz, 4 strikes, seed {}, \
         one thread, {} path, fastest of {}",
        report.modes, report.seconds, report.sample_rate_hz, report.seed, report.simd_path, report.repeats
    );
    for m in &report.materials {
        println!();
        println!(
            "{}: reference = f64 closed form, {} damped sinusoids, peak {:.4e}, computed in {:.2} s",
            m.material, m.reference_terms, m.peak, m.reference_wall_s
        );
        println!(
            "| variant | rel. RMS error | max error / peak | mode-samples/s | real-time factor | mode-samples | culled |"
        );
        println!("|---|---|---|---|---|---|---|");
        for r in &m.rows {
            println!(
                "| {} | {:.2e} ({:.1} dB) | {:.2e} ({:.1} dB) | {:.3e} | {:.0}x | {:.3e} | {} |",
                r.label,
                r.rel_rms_error,
                r.rel_rms_error_db,
                r.max_error_rel_peak,
                r.max_error_rel_peak_db,
                r.mode_samples_per_s,
                r.realtime_factor,
                r.mode_samples as f64,
                r.modes_culled
            );
        }
    }
    match (&report.plot, &report.plot_error) {
        (Some(p), _) => println!("\nplot: {p}"),
        (None, Some(e)) => println!("\nplot missing: {e}"),
        _ => {}
    }
}

/// Runs the benchmark.
pub fn run(args: SynthBenchArgs) -> anyhow::Result<()> {
    check_args(&args)?;
    let mut materials = Vec::new();
    for material in MATERIALS {
        materials.push(run_material(material, &args)?);
    }
    let (mut plot, mut plot_error) = (None, None);
    if let Some(path) = &args.plot {
        let series = plot_series(&materials);
        let title = format!("Synthesis error vs cost, {} modes, {} s at 48 kHz", args.modes, args.seconds);
        let spec = LogLogPlot {
            title: &title,
            x_label: "wall seconds per audio second (1 thread)",
            y_label: "relative RMS error vs f64 closed form",
            series: &series,
        };
        match write_loglog_png(path, &spec) {
            Ok(()) => plot = Some(path.display().to_string()),
            Err(e) => {
                output::warn(&format!("no plot written to {}: {e}", path.display()));
                plot_error = Some(e.to_string());
            }
        }
    }
    let report = Report {
        modes: args.modes,
        seconds: args.seconds,
        sample_rate_hz: 48_000.0,
        seed: args.seed,
        repeats: args.repeats,
        threads: 1,
        simd_path: format!("{:?}", SimdPath::detect()),
        materials,
        plot,
        plot_error,
    };
    if let Some(path) = &args.out {
        write_atomic(path, |tmp| {
            std::fs::write(tmp, serde_json::to_string_pretty(&report)? + "\n")?;
            Ok(())
        })
        .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if args.json {
        output::print_json(&report)
    } else {
        print_table(&report);
        Ok(())
    }
}
