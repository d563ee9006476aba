//! Convergence rates: least-squares slope of `log e` against `log x`.
//!
//! For points `(x_i, e_i)` with both positive, the fit `log10 e = p · log10 x + c`
//! minimises `Σ (log10 e_i − p log10 x_i − c)²`, so `e ≈ C x^p`. Against the element
//! size h a method of order q gives `p ≈ q` (eigenvalue error of degree-k elements:
//! `q = 2k` on smooth problems); against the DOF count N in 3D, `N ∝ h⁻³` and
//! `p ≈ −q/3`.

use serde::{Deserialize, Serialize};

/// A fitted power law `e ≈ 10^intercept · x^slope`.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PowerFit {
    /// The exponent p.
    pub slope: f64,
    /// log10 of the prefactor C.
    pub intercept: f64,
    /// Points used (positive and finite in both coordinates).
    pub points: usize,
}

/// Fits `e ≈ C x^p` to the positive finite points; `None` with fewer than two such
/// points or when all x are equal.
pub fn fit_power_law(points: &[(f64, f64)]) -> Option<PowerFit> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, e)| *x > 0.0 && *e > 0.0 && x.is_finite() && e.is_finite())
        .map(|(x, e)| (x.log10(), e.log10()))
        .collect();
    let n = logs.len() as f64;
    if logs.len() < 2 {
        return None;
    }
    let mx = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let my = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    if sxx <= 1e-300 {
        return None;
    }
    let slope = sxy / sxx;
    Some(PowerFit { slope, intercept: my - slope * mx, points: logs.len() })
}
