//! `modal bench …`: the measured claims in BENCHMARKS.md, reproducible with
//! one command each. Benchmarks report numbers; they never assert timings.

mod accuracy;
mod eigen;
mod synth;

use clap::Subcommand;

pub use accuracy::AccuracyBenchArgs;
pub use eigen::EigenBenchArgs;
pub use synth::SynthBenchArgs;

/// The benchmark to run.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Whole `modal precompute` vs scipy `eigsh` on the same matrices, side by side.
    Eigen(EigenBenchArgs),
    /// Error of the first modes vs run time, TET4/TET10 × mesh sizes (bar, sphere, cantilever).
    Accuracy(AccuracyBenchArgs),
    /// Synthesis error vs the f64 closed form against speed (f32 kernel, culling, budgets).
    Synth(SynthBenchArgs),
}

/// Runs one benchmark.
pub fn run(command: BenchCommand) -> anyhow::Result<()> {
    match command {
        BenchCommand::Eigen(args) => eigen::run(args),
        BenchCommand::Accuracy(args) => accuracy::run(args),
        BenchCommand::Synth(args) => synth::run(args),
    }
}
