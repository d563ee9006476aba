//! `modal bench synth` (work in progress).

use clap::Args;

/// Options of `modal bench synth`.
#[derive(Debug, Args)]
pub struct SynthBenchArgs {}

/// Runs the benchmark.
pub fn run(_args: SynthBenchArgs) -> anyhow::Result<()> {
    anyhow::bail!("modal bench synth is not implemented yet")
}
