//! Log-log line plots as PNG (work in progress).

use std::path::Path;

/// One curve: a label for the legend and its (x, y) points, both > 0.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points in data units; non-positive values are skipped on log axes.
    pub points: Vec<(f64, f64)>,
}

/// A log-log plot with a title, axis labels and curves.
#[derive(Debug, Clone)]
pub struct LogLogPlot<'a> {
    /// Text above the plot.
    pub title: &'a str,
    /// Horizontal axis label (with unit).
    pub x_label: &'a str,
    /// Vertical axis label (with unit).
    pub y_label: &'a str,
    /// The curves.
    pub series: &'a [Series],
}

/// Why a plot could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Not implemented yet.
    #[error("plotting is not implemented yet")]
    Unimplemented,
}

/// Writes `plot` as a PNG file at `path`.
pub fn write_loglog_png(_path: &Path, _plot: &LogLogPlot) -> Result<(), PlotError> {
    Err(PlotError::Unimplemented)
}
