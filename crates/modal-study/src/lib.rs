//! `modal-study`: the measurements behind the accuracy claims in BENCHMARKS.md.
//!
//! Input: study settings (shapes, element orders, mesh levels). Output: rows of
//! measured error and run time, fitted convergence rates, and log-log PNG plots
//! drawn with `plotters` and a built-in bitmap font (no system font libraries).

pub mod plot;
