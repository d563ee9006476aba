//! `modal catalogue merge`: join the catalogues of a batch's shards.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use serde::Serialize;

use super::output::{print_json, warn};

/// Missing shards named in a message; the rest are counted (a count of 10⁵
/// shards would print 10⁵ lines).
const MISSING_LISTED: usize = 10;

/// Work with batch catalogues.
#[derive(Debug, Subcommand)]
pub enum CatalogueCommand {
    /// Join shard catalogues (catalogue-shard-I-of-N.json in each DIR, or files) into one.
    Merge(MergeArgs),
}

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// Directories (all their catalogue-shard-I-of-N.json, else catalogue.json) or catalogue files.
    #[arg(required = true, value_name = "DIR")]
    pub inputs: Vec<PathBuf>,
    /// Merged catalogue to write (banks are made relative to its directory).
    #[arg(short, long, value_name = "FILE")]
    pub out: PathBuf,
    /// Write the merge even when shards are missing or unfinished (it is marked "complete": false).
    #[arg(long)]
    pub partial: bool,
    /// Print one JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct MergeJson {
    catalogue: String,
    inputs: Vec<String>,
    assets: usize,
    failed: usize,
    pending: usize,
    missing_shards: Vec<String>,
    /// Assets of the library that no input lists (a lost shard catalogue).
    missing_assets: usize,
    complete: bool,
}

/// "N of the library's M assets are in no catalogue".
fn missing_assets(report: &modal_batch::MergeReport, merged: &modal_batch::Catalogue) -> String {
    let total = merged.library.as_ref().map_or(0, |lib| lib.assets);
    format!("{} of the library's {total} assets are in no catalogue", report.missing_assets)
}

pub fn run(command: CatalogueCommand) -> Result<()> {
    match command {
        CatalogueCommand::Merge(args) => merge(args),
    }
}

fn merge(args: MergeArgs) -> Result<()> {
    let out_dir = super::directory_of(&args.out);
    super::prepare_output(&args.out).with_context(|| format!("cannot write -o {}", args.out.display()))?;
    let (merged, report) = modal_batch::merge(&args.inputs, out_dir)?;
    if !merged.complete && !args.partial {
        let mut why: Vec<String> = report.missing.iter().take(MISSING_LISTED).cloned().collect();
        if report.missing.len() > MISSING_LISTED {
            why.push(format!("and {} more missing shards", report.missing.len() - MISSING_LISTED));
        }
        if report.missing_assets > 0 {
            why.push(missing_assets(&report, &merged));
        }
        if !merged.pending.is_empty() {
            why.push(format!("{} assets unfinished (e.g. {})", merged.pending.len(), merged.pending[0]));
        }
        if why.is_empty() {
            why.push("an input catalogue is marked incomplete".into());
        }
        bail!(
            "the catalogues are incomplete ({}); re-run the missing shards, or pass --partial",
            why.join("; ")
        );
    }
    report.missing.iter().take(MISSING_LISTED).for_each(|m| warn(&format!("missing {m}")));
    if report.missing.len() > MISSING_LISTED {
        warn(&format!("and {} more missing shards", report.missing.len() - MISSING_LISTED));
    }
    if report.missing_assets > 0 {
        warn(&missing_assets(&report, &merged));
    }
    merged.save(&args.out)?;
    let summary = MergeJson {
        catalogue: args.out.display().to_string(),
        inputs: report.inputs.iter().map(|p| p.display().to_string()).collect(),
        assets: merged.assets.len(),
        failed: merged.failed(),
        pending: merged.pending.len(),
        missing_shards: report.missing,
        missing_assets: report.missing_assets,
        complete: merged.complete,
    };
    if args.json {
        print_json(&summary)
    } else {
        let n = summary.inputs.len();
        println!(
            "merged {n} catalogue{}: {} assets ({} failed{}) into {}",
            if n == 1 { "" } else { "s" },
            summary.assets,
            summary.failed,
            if summary.complete { "" } else { ", incomplete" },
            summary.catalogue
        );
        Ok(())
    }
}
