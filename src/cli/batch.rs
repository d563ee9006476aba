//! `modal precompute-batch`: a manifest of assets → one bank each and a catalogue.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use modal_batch::{BatchOptions, Catalogue, Event, Manifest, Shard, ShardEnv};
use serde::Serialize;

use super::output::{print_json, warn};
use super::precompute::{memory_limit_from_env, open_cache};

/// Precompute the mode banks of every asset in a manifest (one shard of it).
#[derive(Debug, Args)]
pub struct PrecomputeBatchArgs {
    /// Manifest (TOML: [defaults], [[assets]], [[globs]]; see docs/asset-libraries.md).
    pub manifest: PathBuf,
    /// Output directory: one bank per asset and the catalogue.
    #[arg(short, long, value_name = "DIR")]
    pub out: PathBuf,
    /// Run shard I of N (0-based, e.g. 0/3); default: from SLURM_ARRAY_TASK_ID or
    /// JOB_COMPLETION_INDEX, else the whole manifest.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// Number of shards for JOB_COMPLETION_INDEX (or MODAL_SHARD_COUNT); overrides SLURM_ARRAY_TASK_COUNT.
    #[arg(long, value_name = "N")]
    pub shard_count: Option<usize>,
    /// Assets solved at the same time.
    #[arg(long, short = 'j', value_name = "J", default_value_t = 1)]
    pub jobs: usize,
    /// Solver threads per asset (default: the pipeline's).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Cache directory (default $MODAL_CACHE_DIR, $XDG_CACHE_HOME/modal or ~/.cache/modal);
    /// shards on several machines should share one.
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    /// Do not read or write the cache (finished banks in --out are still reused).
    #[arg(long)]
    pub no_cache: bool,
    /// Recompute everything, even what is cached or finished.
    #[arg(long)]
    pub force: bool,
    /// Print one JSON object on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// What `--json` prints: counts, then the catalogue's entries.
#[derive(Serialize)]
struct BatchJson<'a> {
    catalogue: String,
    shard: Option<modal_batch::ShardInfo>,
    total: usize,
    ok: usize,
    failed: usize,
    /// Assets reused from the cache or from finished banks (not solved in this run).
    cached: usize,
    /// Assets solved in this run.
    computed: usize,
    seconds: f64,
    assets: &'a [modal_batch::CatalogueEntry],
}

pub fn run(args: PrecomputeBatchArgs) -> Result<()> {
    if args.jobs == 0 {
        bail!("--jobs must be at least 1");
    }
    let (shard, from) =
        Shard::select(args.shard.as_deref(), args.shard_count, |name| std::env::var(name).ok())?;
    // The memory guard of `modal precompute` (in a pod or a Slurm job the
    // machine's free memory is not the job's limit), shared by the --jobs
    // solves that run at once: each alone within the whole would not keep
    // them together within it.
    let jobs = args.jobs as u64;
    let memory_limit = match memory_limit_from_env()? {
        Some(bytes) => Some(bytes / jobs),
        // One job: the solver's own default, judged at each solve.
        None if jobs == 1 => None,
        None => modal_eigen::default_memory_limit().map(|bytes| bytes / jobs),
    };
    let manifest = Manifest::load(&args.manifest)?;
    let (all, warnings) = manifest.resolve()?;
    warnings.iter().for_each(|w| warn(w));
    // A library that resolves to nothing (a mount missing on this node) must not
    // pass as a complete, empty batch on every shard.
    if all.is_empty() {
        bail!("{}: the manifest resolves to no asset", args.manifest.display());
    }
    let library = modal_batch::Library::of(&all);
    let mut assets: Vec<_> = all.into_iter().filter(|a| shard.owns(&a.bank)).collect();
    if memory_limit.is_some() {
        assets.iter_mut().for_each(|a| a.request.memory_limit_bytes = memory_limit);
    }
    let selection = match from {
        ShardEnv::Whole => String::new(),
        ShardEnv::Flag => format!("shard {shard} (--shard): "),
        ShardEnv::Slurm => format!("shard {shard} (Slurm array): "),
        ShardEnv::Kubernetes => format!("shard {shard} (JOB_COMPLETION_INDEX): "),
    };
    let cache = open_cache(args.cache_dir.as_deref(), args.no_cache)?;
    anyhow::ensure!(
        !args.out.exists() || args.out.is_dir(),
        "--out {} is a file: give the directory the banks and the catalogue go to",
        args.out.display()
    );
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let options = BatchOptions {
        out_dir: args.out.clone(),
        cache,
        library: Some(library),
        jobs: args.jobs,
        force: args.force,
        threads: args.threads,
        shard,
    };
    let bar = progress_bar(assets.len() as u64, &selection);
    // Without a terminal (a Slurm or Kubernetes log) the bar is hidden: one line per asset instead.
    let log_lines = !std::io::stderr().is_terminal();
    let start = Instant::now();
    let on_event = |event: Event<'_>| match event {
        Event::Started { asset } => bar.set_message(asset.path.clone()),
        Event::Finished { entry, .. } => {
            bar.inc(1);
            // Read before `suspend`, which holds the bar's lock while its closure runs.
            let (done, total, eta) = (bar.position(), bar.length().unwrap_or(0), bar.eta().as_secs());
            bar.suspend(|| {
                entry.warnings.iter().for_each(|w| warn(w));
                if !entry.is_ok() {
                    warn(&format!("{} failed: {}", entry.path, entry.status));
                }
                if log_lines {
                    let how = if !entry.is_ok() {
                        "failed"
                    } else if entry.cached {
                        "reused"
                    } else {
                        "solved"
                    };
                    eprintln!(
                        "{selection}[{done}/{total}] {} {how} in {:.1} s; ETA {}:{:02}",
                        entry.path,
                        entry.seconds,
                        eta / 60,
                        eta % 60
                    );
                }
            });
        }
    };
    let catalogue = modal_batch::run_batch(&assets, &options, &on_event)?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    let path = args.out.join(Catalogue::file_name(shard));
    let cached = catalogue.assets.iter().filter(|e| e.cached).count();
    let failed = catalogue.failed();
    if args.json {
        print_json(&BatchJson {
            catalogue: path.display().to_string(),
            shard: catalogue.shard,
            total: catalogue.assets.len(),
            ok: catalogue.assets.len() - failed,
            failed,
            cached,
            computed: catalogue.assets.iter().filter(|e| e.is_ok() && !e.cached).count(),
            seconds,
            assets: &catalogue.assets,
        })?;
    } else {
        write_table(&catalogue, &mut std::io::stdout().lock())?;
        println!(
            "{selection}{} assets: {} ok ({cached} reused), {failed} failed in {seconds:.1} s; wrote {}",
            catalogue.assets.len(),
            catalogue.assets.len() - failed,
            path.display()
        );
    }
    if failed > 0 {
        bail!(
            "{failed} of {} assets failed (their errors are in {})",
            catalogue.assets.len(),
            path.display()
        );
    }
    Ok(())
}

fn progress_bar(len: u64, prefix: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    let template =
        format!("{prefix}{{bar:30}} {{pos}}/{{len}} [{{elapsed_precise}}, ETA {{eta_precise}}] {{wide_msg}}");
    bar.set_style(ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar()));
    bar.enable_steady_tick(Duration::from_millis(250));
    bar
}

/// The summary table: one line per asset, failures with their message. A
/// file listed more than once (two materials) is told apart by its bank.
fn write_table(catalogue: &Catalogue, out: &mut impl Write) -> std::io::Result<()> {
    let listed = |path: &str| catalogue.assets.iter().filter(|e| e.path == path).count();
    let labels: Vec<String> = catalogue
        .assets
        .iter()
        .map(|e| if listed(&e.path) > 1 { format!("{} ({})", e.path, e.id) } else { e.path.clone() })
        .collect();
    let width = labels.iter().map(|l| l.chars().count()).max().unwrap_or(4).max(4);
    writeln!(
        out,
        "{:<width$}  {:>5}  {:>10}  {:>8}  {:>8}  {:<6}  status",
        "path", "modes", "f1 [Hz]", "transfer", "seconds", "reused"
    )?;
    for (e, label) in catalogue.assets.iter().zip(&labels) {
        let f1 = e.first_frequency_hz.map_or("-".to_string(), |f| format!("{f:.1}"));
        let reused = if e.cached { "yes" } else { "no" };
        writeln!(
            out,
            "{label:<width$}  {:>5}  {f1:>10}  {:>8}  {:>8.2}  {reused:<6}  {}",
            e.modes, e.transfer_modes, e.seconds, e.status
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file listed twice (two materials) shows its bank; a file listed once does not.
    #[test]
    fn the_table_tells_two_banks_of_one_file_apart() {
        let entry = |path: &str, id: &str| modal_batch::CatalogueEntry {
            path: path.into(),
            bank: Some(id.into()),
            id: id.into(),
            hash: None,
            modes: 4,
            first_frequency_hz: Some(100.0),
            transfer_modes: 0,
            seconds: 1.0,
            status: "ok".into(),
            cached: false,
            mass_kg: None,
            size_m: None,
            warnings: Vec::new(),
        };
        let assets = vec![
            entry("cup.obj", "cup.bank"),
            entry("cup.obj", "cup_glass.bank"),
            entry("rod.obj", "rod.bank"),
        ];
        let catalogue = Catalogue::new(assets, Vec::new(), modal_batch::Shard::WHOLE);
        let mut out = Vec::new();
        write_table(&catalogue, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(text.contains("cup.obj (cup.bank) ") && text.contains("cup.obj (cup_glass.bank) "), "{text}");
        assert!(text.contains("\nrod.obj ") && !text.contains("rod.obj (rod.bank)"), "{text}");
    }
}
