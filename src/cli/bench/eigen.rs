//! `modal bench eigen` (work in progress).

use clap::Args;

/// Options of `modal bench eigen`.
#[derive(Debug, Args)]
pub struct EigenBenchArgs {}

/// Runs the benchmark.
pub fn run(_args: EigenBenchArgs) -> anyhow::Result<()> {
    anyhow::bail!("modal bench eigen is not implemented yet")
}
