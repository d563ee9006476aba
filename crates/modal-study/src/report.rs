//! The study's summary: convergence rates, the mesh-size recommendation, the plots
//! and a markdown report, all computed from measured [`CaseResult`]s.
//!
//! Error measure throughout: the largest relative error of the compared modes
//! (see [`crate::compare`]). Rates: [`crate::fit`] of that error against the mean cell
//! size and against the DOF count, per shape and element order.

use crate::case::{CaseResult, StudyShape};
use crate::fit::{fit_power_law, PowerFit};
use crate::plot::{write_loglog_png, LogLogPlot, Series};
use crate::StudyError;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Fitted convergence rates of one shape and element order.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Rate {
    /// The shape.
    pub shape: StudyShape,
    /// Element order.
    pub order: u8,
    /// Fit of max relative error against the mean cell size (m).
    pub vs_h: Option<PowerFit>,
    /// Fit of max relative error against the DOF count.
    pub vs_dofs: Option<PowerFit>,
}

/// The cheapest measured level of one shape and order meeting the error target.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Cheapest {
    /// The shape.
    pub shape: StudyShape,
    /// Element order.
    pub order: u8,
    /// Nominal element size of that level (m), `None` if no level met the target.
    pub h_m: Option<f64>,
    /// Smallest dimension over h (the `N` of the rule `h = D / N`).
    pub d_over_h: Option<f64>,
    /// Its total wall time (s).
    pub total_s: Option<f64>,
    /// Its max relative error.
    pub max_relative_error: Option<f64>,
}

/// Everything the study reports.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StudyReport {
    /// The measured cases.
    pub cases: Vec<CaseResult>,
    /// Convergence rates per shape and order.
    pub rates: Vec<Rate>,
    /// Max relative error the recommendation aims for.
    pub target_error: f64,
    /// Cheapest level meeting `target_error`, per shape and order.
    pub cheapest: Vec<Cheapest>,
    /// PNG files written by [`StudyReport::write_plots`].
    pub plots: Vec<PathBuf>,
}

impl StudyReport {
    /// Summarises `cases` (rates and the cheapest levels meeting `target_error`).
    pub fn new(cases: Vec<CaseResult>, target_error: f64) -> StudyReport {
        let mut rates = Vec::new();
        let mut cheapest = Vec::new();
        for (shape, order) in groups(&cases) {
            let group: Vec<&CaseResult> = select(&cases, shape, order).collect();
            let err = |c: &CaseResult| c.comparison.max_relative_error;
            let vs_h = fit_power_law(&group.iter().map(|c| (c.h_mean_m, err(c))).collect::<Vec<_>>());
            let vs_dofs = fit_power_law(&group.iter().map(|c| (c.dofs as f64, err(c))).collect::<Vec<_>>());
            rates.push(Rate { shape, order, vs_h, vs_dofs });
            let best = group
                .iter()
                .filter(|c| err(c) <= target_error && c.comparison.missing == 0)
                .min_by(|a, b| a.total_s.total_cmp(&b.total_s));
            cheapest.push(Cheapest {
                shape,
                order,
                h_m: best.map(|c| c.h_m),
                d_over_h: best.map(|c| shape.smallest_dimension_m() / c.h_m),
                total_s: best.map(|c| c.total_s),
                max_relative_error: best.map(|c| err(c)),
            });
        }
        StudyReport { cases, rates, target_error, cheapest, plots: Vec::new() }
    }

    /// Writes per shape `<shape>_error_vs_time.png` and `<shape>_error_vs_dofs.png` into
    /// `dir` (one curve per element order) and records their paths.
    pub fn write_plots(&mut self, dir: &Path) -> Result<(), StudyError> {
        let shapes: Vec<StudyShape> =
            StudyShape::ALL.into_iter().filter(|s| self.cases.iter().any(|c| c.spec.shape == *s)).collect();
        for shape in shapes {
            for (axis, x_label, file) in [
                (Axis::Time, "total wall time (s)", "error_vs_time"),
                (Axis::Dofs, "degrees of freedom", "error_vs_dofs"),
            ] {
                let series = self.series(shape, axis);
                let title =
                    format!("{}: max relative error of {} modes", shape.name(), shape.reference_hz().len());
                let plot =
                    LogLogPlot { title: &title, x_label, y_label: "max relative error", series: &series };
                let path = dir.join(format!("{}_{file}.png", shape.name()));
                write_loglog_png(&path, &plot)?;
                self.plots.push(path);
            }
        }
        Ok(())
    }

    fn series(&self, shape: StudyShape, axis: Axis) -> Vec<Series> {
        [1u8, 2]
            .into_iter()
            .filter_map(|order| {
                let points: Vec<(f64, f64)> = select(&self.cases, shape, order)
                    .map(|c| {
                        let x = match axis {
                            Axis::Time => c.total_s,
                            Axis::Dofs => c.dofs as f64,
                        };
                        (x, c.comparison.max_relative_error)
                    })
                    .collect();
                (!points.is_empty()).then(|| Series { label: order_name(order).into(), points })
            })
            .collect()
    }

    /// The report as markdown: case table, rates, cheapest levels, plot paths.
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        s.push_str(&self.case_table());
        s.push_str(&self.rate_table());
        s.push_str(&self.cheapest_table());
        if !self.plots.is_empty() {
            s.push_str("\nPlots:\n");
            for p in &self.plots {
                let _ = writeln!(s, "- `{}`", p.display());
            }
        }
        s
    }

    fn case_table(&self) -> String {
        let mut s = String::from(
            "| shape | elements | level | h (mm) | D/h | DOF | mesh s | assemble s | factor s | solve s | total s | peak RSS MB | modes | max rel. err | median rel. err |\n\
             |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        for c in &self.cases {
            let shape = c.spec.shape;
            let rss = c.peak_rss_bytes.map_or("–".into(), |b| format!("{:.0}", b as f64 / 1e6));
            let cmp = &c.comparison;
            let modes = if cmp.missing > 0 {
                format!("{} ({} missing)", cmp.relative_errors.len(), cmp.missing)
            } else {
                cmp.relative_errors.len().to_string()
            };
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.2} | {:.2} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {rss} | {modes} | {:.2e} | {:.2e} |",
                shape.name(),
                order_name(c.spec.order),
                c.spec.level,
                c.h_m * 1e3,
                shape.smallest_dimension_m() / c.h_m,
                c.dofs,
                c.mesh_s,
                c.assemble_s,
                c.factor_s,
                c.solve_s,
                c.total_s,
                cmp.max_relative_error,
                cmp.median_relative_error,
            );
        }
        s
    }

    fn rate_table(&self) -> String {
        let mut s = String::from(
            "\nConvergence of the max relative error, least-squares slope of log(error):\n\n\
             | shape | elements | vs log(mean cell size h) | vs log(DOF) | levels |\n|---|---|---|---|---|\n",
        );
        let fmt = |f: Option<PowerFit>| f.map_or("–".into(), |f| format!("{:.2}", f.slope));
        for r in &self.rates {
            let n = r.vs_h.map_or(0, |f| f.points);
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {n} |",
                r.shape.name(),
                order_name(r.order),
                fmt(r.vs_h),
                fmt(r.vs_dofs)
            );
        }
        s
    }

    fn cheapest_table(&self) -> String {
        let mut s = format!(
            "\nCheapest measured level with max relative error ≤ {:.1} % (D = smallest dimension: bar thickness, sphere diameter):\n\n\
             | shape | elements | h (mm) | D/h | total s | max rel. err |\n|---|---|---|---|---|---|\n",
            self.target_error * 100.0
        );
        for c in &self.cheapest {
            match (c.h_m, c.d_over_h, c.total_s, c.max_relative_error) {
                (Some(h), Some(n), Some(t), Some(e)) => {
                    let _ = writeln!(
                        s,
                        "| {} | {} | {:.2} | {n:.2} | {t:.2} | {e:.2e} |",
                        c.shape.name(),
                        order_name(c.order),
                        h * 1e3
                    );
                }
                _ => {
                    let _ = writeln!(
                        s,
                        "| {} | {} | not reached | – | – | – |",
                        c.shape.name(),
                        order_name(c.order)
                    );
                }
            }
        }
        s
    }
}

#[derive(Copy, Clone)]
enum Axis {
    Time,
    Dofs,
}

/// `TET4` or `TET10`.
pub fn order_name(order: u8) -> &'static str {
    if order == 1 {
        "TET4"
    } else {
        "TET10"
    }
}

/// Distinct (shape, order) pairs of `cases`, in report order.
fn groups(cases: &[CaseResult]) -> Vec<(StudyShape, u8)> {
    let mut out = Vec::new();
    for shape in StudyShape::ALL {
        for order in [1u8, 2] {
            if select(cases, shape, order).next().is_some() {
                out.push((shape, order));
            }
        }
    }
    out
}

fn select(cases: &[CaseResult], shape: StudyShape, order: u8) -> impl Iterator<Item = &CaseResult> {
    cases.iter().filter(move |c| c.spec.shape == shape && c.spec.order == order)
}
