//! `modal bench accuracy` (work in progress).

use clap::Args;

/// Options of `modal bench accuracy`.
#[derive(Debug, Args)]
pub struct AccuracyBenchArgs {}

/// Runs the benchmark.
pub fn run(_args: AccuracyBenchArgs) -> anyhow::Result<()> {
    anyhow::bail!("modal bench accuracy is not implemented yet")
}
