//! Log-log line plots as PNG, drawn with `plotters`' bitmap backend; text in
//! the DejaVu Sans font embedded by `modal-plot` (no system font libraries).
//!
//! Axes: a point `(x, y)` maps to `(log10 x, log10 y)`; each axis spans whole
//! decades from `floor(log10 min)` to `ceil(log10 max)` of the positive,
//! finite data. Major ticks and grid lines at the decades, minor ticks at
//! 2…9 × 10ᵏ. Non-positive or non-finite points are skipped (they have no
//! place on a log axis). The file is written to a temporary name in the same
//! directory and renamed, so a reader never sees a partial PNG.

use modal_plot::{draw_text, HPos, Text, VPos};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

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
    /// No series has a point with both coordinates positive and finite.
    #[error("plot '{title}' has no positive finite data point to draw on log axes")]
    NoData {
        /// The plot title.
        title: String,
    },
    /// Drawing or PNG encoding failed.
    #[error("cannot draw plot '{title}': {reason}")]
    Draw {
        /// The plot title.
        title: String,
        /// The backend's message.
        reason: String,
    },
    /// Renaming the finished temporary file failed.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The destination path.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

/// Image size in pixels.
const SIZE: (u32, u32) = (960, 640);
/// Plot frame in pixels: left, top, right, bottom.
const FRAME: (i32, i32, i32, i32) = (110, 60, 700, 560);
/// Text sizes [px]: title, axis labels, tick labels and legend.
const TITLE: f32 = 22.0;
const LABEL: f32 = 18.0;
const TICK: f32 = 16.0;
/// Legend line spacing [px].
const LINE: i32 = 26;
/// Line colours of successive series (the ten "tab10" colours: up to ten curves
/// stay distinguishable; the synthesis plot has eight).
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
];
const GRID: RGBColor = RGBColor(225, 225, 225);

/// Writes `plot` as a PNG file at `path` (atomically: temporary file + rename).
pub fn write_loglog_png(path: &Path, plot: &LogLogPlot) -> Result<(), PlotError> {
    let (xs, ys) = decade_ranges(plot).ok_or_else(|| PlotError::NoData { title: plot.title.into() })?;
    let tmp = temporary_path(path);
    let draw_err = |e: String| PlotError::Draw { title: plot.title.into(), reason: e };
    let result = render(&tmp, plot, xs, ys).map_err(draw_err);
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::rename(&tmp, path).map_err(|source| {
        let _ = std::fs::remove_file(&tmp);
        PlotError::Io { path: path.to_path_buf(), source }
    })
}

/// A sibling of `path` with a `.png` extension (the backend picks the encoder by extension).
fn temporary_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp.png", std::process::id()))
}

/// The positive finite points of one series.
fn positive(series: &Series) -> impl Iterator<Item = (f64, f64)> + '_ {
    series.points.iter().copied().filter(|&(x, y)| x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite())
}

/// Whole-decade exponent ranges `(lo, hi)`, `lo < hi`, of x and y; `None` without data.
fn decade_ranges(plot: &LogLogPlot) -> Option<((i32, i32), (i32, i32))> {
    let mut it = plot.series.iter().flat_map(positive).peekable();
    it.peek()?;
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in it {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    Some((decades(x0, x1), decades(y0, y1)))
}

fn decades(lo: f64, hi: f64) -> (i32, i32) {
    // Exponents of finite positive f64 lie within ±324.
    let a = lo.log10().floor() as i32;
    let b = hi.log10().ceil() as i32;
    if b > a {
        (a, b)
    } else {
        (a, a + 1)
    }
}

/// Maps data to pixels inside [`FRAME`].
struct Axes {
    xs: (i32, i32),
    ys: (i32, i32),
}

impl Axes {
    fn px(&self, x: f64, y: f64) -> (i32, i32) {
        let (l, t, r, b) = FRAME;
        let fx = (x.log10() - self.xs.0 as f64) / (self.xs.1 - self.xs.0) as f64;
        let fy = (y.log10() - self.ys.0 as f64) / (self.ys.1 - self.ys.0) as f64;
        (l + (fx * (r - l) as f64).round() as i32, b - (fy * (b - t) as f64).round() as i32)
    }
}

/// Tick label of 10^k: plain decimals for |k| ≤ 3, else `1e{k}`.
fn decade_label(k: i32) -> String {
    match k {
        0..=3 => format!("{}", 10_i64.pow(k as u32)),
        -3..=-1 => format!("{}", 10f64.powi(k)),
        _ => format!("1e{k}"),
    }
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

fn render(tmp: &Path, plot: &LogLogPlot, xs: (i32, i32), ys: (i32, i32)) -> Result<(), String> {
    let area = BitMapBackend::new(tmp, SIZE).into_drawing_area();
    fn e<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> String {
        e.to_string()
    }
    area.fill(&WHITE).map_err(e)?;
    let axes = Axes { xs, ys };
    draw_grid(&area, &axes).map_err(e)?;
    draw_labels(&area, plot, &axes).map_err(e)?;
    for (i, s) in plot.series.iter().enumerate() {
        draw_series(&area, &axes, s, &PALETTE[i % PALETTE.len()]).map_err(e)?;
    }
    draw_legend(&area, plot.series).map_err(e)?;
    area.present().map_err(e)
}

type DrawResult = Result<(), DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>>;

fn draw_grid(area: &Area, axes: &Axes) -> DrawResult {
    let (l, t, r, b) = FRAME;
    for k in axes.xs.0..=axes.xs.1 {
        let (x, _) = axes.px(10f64.powi(k), 1.0);
        area.draw(&PathElement::new(vec![(x, t), (x, b)], GRID))?;
        area.draw(&PathElement::new(vec![(x, b), (x, b + 8)], BLACK))?;
        draw_text(area, &decade_label(k), (x, b + 12), &Text::new(TICK).at(HPos::Center, VPos::Top))?;
        for m in 2..10 {
            let (xm, _) = axes.px(m as f64 * 10f64.powi(k), 1.0);
            if k < axes.xs.1 {
                area.draw(&PathElement::new(vec![(xm, b), (xm, b + 4)], BLACK))?;
            }
        }
    }
    for k in axes.ys.0..=axes.ys.1 {
        let (_, y) = axes.px(1.0, 10f64.powi(k));
        area.draw(&PathElement::new(vec![(l, y), (r, y)], GRID))?;
        area.draw(&PathElement::new(vec![(l - 8, y), (l, y)], BLACK))?;
        draw_text(area, &decade_label(k), (l - 12, y), &Text::new(TICK).at(HPos::Right, VPos::Center))?;
        for m in 2..10 {
            let (_, ym) = axes.px(1.0, m as f64 * 10f64.powi(k));
            if k < axes.ys.1 {
                area.draw(&PathElement::new(vec![(l - 4, ym), (l, ym)], BLACK))?;
            }
        }
    }
    area.draw(&Rectangle::new([(l, t), (r, b)], BLACK.stroke_width(1)))
}

fn draw_labels(area: &Area, plot: &LogLogPlot, _axes: &Axes) -> DrawResult {
    let (l, t, r, b) = FRAME;
    draw_text(area, plot.title, ((l + r) / 2, t - 18), &Text::new(TITLE).at(HPos::Center, VPos::Bottom))?;
    draw_text(area, plot.x_label, ((l + r) / 2, b + 42), &Text::new(LABEL).at(HPos::Center, VPos::Top))?;
    draw_text(area, plot.y_label, (14, (t + b) / 2), &Text::new(LABEL).at(HPos::Center, VPos::Top).upwards())
}

fn draw_series(area: &Area, axes: &Axes, series: &Series, color: &RGBColor) -> DrawResult {
    let mut pts: Vec<(f64, f64)> = positive(series).collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let px: Vec<(i32, i32)> = pts.iter().map(|&(x, y)| axes.px(x, y)).collect();
    area.draw(&PathElement::new(px.clone(), color.stroke_width(2)))?;
    for p in px {
        area.draw(&Circle::new(p, 4, color.filled()))?;
    }
    Ok(())
}

fn draw_legend(area: &Area, series: &[Series]) -> DrawResult {
    let (_, t, r, _) = FRAME;
    for (i, s) in series.iter().enumerate() {
        let mid = t + 20 + i as i32 * LINE;
        let color = PALETTE[i % PALETTE.len()];
        area.draw(&PathElement::new(vec![(r + 16, mid), (r + 46, mid)], color.stroke_width(2)))?;
        area.draw(&Circle::new((r + 31, mid), 4, color.filled()))?;
        draw_text(area, &s.label, (r + 54, mid), &Text::new(TICK).at(HPos::Left, VPos::Center))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decades_cover_the_data_with_whole_exponents() {
        assert_eq!(decades(0.002, 0.5), (-3, 0));
        assert_eq!(decades(10.0, 10.0), (1, 2));
        assert_eq!(decade_label(-2), "0.01");
        assert_eq!(decade_label(3), "1000");
        assert_eq!(decade_label(-5), "1e-5");
    }
}
