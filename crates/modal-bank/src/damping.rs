//! Rayleigh damping of a mode, convention `C = αM + βK`
//! (`shared/reference/materials.md`).
//!
//! For undamped angular frequency `ω = 2π f` [rad/s]:
//! decay rate `d = (α + β ω²)/2` [1/s], damping ratio `ξ = (α/ω + β ω)/2`,
//! damped frequency `f_d = f √(1 − ξ²)` (none when ξ ≥ 1),
//! amplitude envelope `e^{−d t}`, `T60 = ln(1000)/d`.

use std::f64::consts::PI;

/// Damping ratio ξ [-] and decay rate d [1/s] of a mode of undamped
/// frequency `frequency_hz` under Rayleigh damping `C = αM + βK`
/// (`alpha` [1/s], `beta` [s]).
pub fn rayleigh(alpha: f64, beta: f64, frequency_hz: f64) -> (f64, f64) {
    let omega = 2.0 * PI * frequency_hz;
    let ratio = 0.5 * (alpha / omega + beta * omega);
    let rate = 0.5 * (alpha + beta * omega * omega);
    (ratio, rate)
}

/// `ln(1000)/d` [s]; infinite for `d = 0`.
pub(crate) fn t60_s(decay_rate: f64) -> f64 {
    if decay_rate == 0.0 {
        f64::INFINITY
    } else {
        1000f64.ln() / decay_rate
    }
}

/// `f √(1 − ξ²)` [Hz], 0 when ξ ≥ 1.
pub(crate) fn damped_frequency_hz(frequency_hz: f64, damping_ratio: f64) -> f64 {
    if damping_ratio >= 1.0 {
        0.0
    } else {
        frequency_hz * (1.0 - damping_ratio * damping_ratio).sqrt()
    }
}
