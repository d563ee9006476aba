//! `modal-study`: the measurements behind the accuracy claims in BENCHMARKS.md.
//!
//! Input: study settings (shapes, element orders, mesh levels). Output: rows of
//! measured error and run time ([`CaseResult`], from [`run_case`]), fitted
//! convergence rates and the cheapest mesh meeting an error target
//! ([`StudyReport`]), and log-log PNG plots ([`plot::write_loglog_png`]) drawn with
//! `plotters` and the DejaVu Sans font embedded by `modal-plot` (no system font libraries).
//!
//! Shapes and references (module [`reference`]): the free-free steel bar and the
//! free steel sphere of `shared/reference/analytic.md`, and the bar as a cantilever.
//! The library never prints; peak memory is per process ([`peak_rss_bytes`]), so a
//! caller that wants it per case runs each case in its own process.

mod case;
mod compare;
mod error;
mod fit;
mod memory;
pub mod plot;
pub mod reference;
mod report;

pub use case::{run_case, study_material, CaseResult, CaseSpec, StudyShape};
pub use compare::{compare_sorted, median, Comparison};
pub use error::StudyError;
pub use fit::{fit_power_law, PowerFit};
pub use memory::peak_rss_bytes;
pub use report::{order_name, Cheapest, Rate, StudyReport};
