//! Finite contact time: the half-sine force spectrum and Hertz theory.
//!
//! A strike delivering impulse `J` over a contact of duration τ is modelled
//! by the unit-area half-sine force `F(t) = J · π/(2τ) · sin(π t/τ)`, `0 ≤ t ≤ τ`.
//! For a mode with complex frequency `s = −d + iω_d` the response after the
//! contact is exactly that of an impulse `J·C(sτ)` applied at the force
//! centroid `t₀ + τ/2`, where (Laplace transform of the centred pulse)
//!
//! `C(u) = π² cosh(u/2) / (u² + π²)`,  `u = s τ`.
//!
//! `C(0) = 1` (a short contact is an impulse); for an undamped mode it is the
//! classic `π² cos(ωτ/2) / (π² − ω²τ²)`, which rolls off above `ω ≈ π/τ` with
//! nulls at `ωτ = 3π, 5π, …`. The removable singularity at `u = ±iπ` is
//! evaluated by its series. Applying `C` costs nothing per sample.
//!
//! Hertz contact time of a sphere on a body (Johnson, *Contact Mechanics*,
//! §11.4): `t_c = 2.8683 (m² / (R E*² v))^{1/5}` with the effective mass
//! `1/m = 1/m₁ + 1/m₂`, radius `1/R = 1/R₁ + 1/R₂`, modulus
//! `1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂` and approach speed `v`.

use crate::complex::C64;
use std::f64::consts::PI;

/// Default contact time of a strike \[s\]: 0.1 ms, a hard mallet. Fixed (not
/// speed dependent) so the output stays linear in the impulse.
pub const DEFAULT_CONTACT_TIME_S: f64 = 1e-4;

/// The default contact time for a body whose lowest sounding mode is at
/// `lowest_mode_hz` \[s\]: [`DEFAULT_CONTACT_TIME_S`], shortened to half
/// that mode's period when it rings above 5 kHz, so `ωτ ≤ π` and the mode
/// keeps at least `C = π/4` (−2.1 dB) of the impulse. A fixed 0.1 ms put a
/// 9 cm steel ball's lowest modes (13.9–14.7 kHz, `ωτ ≈ 2.9π`) on the
/// spectrum's first null: a default strike wrote one 16-bit step. Hard
/// contacts are that short: a 5 mm steel ball on steel at 1 m/s touches for
/// 35 µs (Hertz, tested below). Independent of the impulse, so the output
/// stays linear in it.
pub fn default_contact_time_s(lowest_mode_hz: f64) -> f64 {
    if lowest_mode_hz.is_finite() && lowest_mode_hz > 0.0 {
        DEFAULT_CONTACT_TIME_S.min(0.5 / lowest_mode_hz)
    } else {
        DEFAULT_CONTACT_TIME_S
    }
}

/// Longest accepted contact time \[s\].
pub const MAX_CONTACT_TIME_S: f64 = 0.1;

/// Centred half-sine contact spectrum `C(sτ)` for complex frequency `s` [1/s]
/// and contact time `tau_s` \[s\] (see module doc). Returns 0 when the value
/// overflows (a mode that decays completely during a long contact).
pub fn half_sine_spectrum(s: C64, tau_s: f64) -> C64 {
    if tau_s == 0.0 {
        return C64::new(1.0, 0.0);
    }
    let u = s.scale(tau_s);
    let pi2 = PI * PI;
    // sinh(ε/2)/ε for small ε by its Taylor series.
    let sinhc = |e: C64| {
        let e2 = e * e;
        C64::new(0.5, 0.0) + e2.scale(1.0 / 48.0) + (e2 * e2).scale(1.0 / 3840.0)
    };
    let near_pos = u - C64::new(0.0, PI);
    let near_neg = u + C64::new(0.0, PI);
    let c = if near_pos.abs() < 1e-3 {
        // cosh(u/2) = i sinh(ε/2), u² + π² = ε (ε + 2iπ).
        (C64::new(0.0, pi2) * sinhc(near_pos)).quot(near_pos + C64::new(0.0, 2.0 * PI))
    } else if near_neg.abs() < 1e-3 {
        // cosh(u/2) = −i sinh(ε/2), u² + π² = ε (ε − 2iπ).
        (C64::new(0.0, -pi2) * sinhc(near_neg)).quot(near_neg - C64::new(0.0, 2.0 * PI))
    } else {
        let h = u.scale(0.5);
        let cosh = (h.exp() + h.scale(-1.0).exp()).scale(0.5);
        cosh.scale(pi2).quot(u * u + C64::new(pi2, 0.0))
    };
    if c.is_finite() {
        c
    } else {
        C64::ZERO
    }
}

/// Hertz contact time \[s\] of an impact with effective mass `m_eff_kg`,
/// effective radius `r_eff_m`, effective modulus `e_star_pa` and normal
/// approach speed `speed_m_s`: `2.8683 (m²/(R E*² v))^{1/5}`.
/// Returns `None` unless all inputs are finite and positive.
pub fn hertz_contact_time(m_eff_kg: f64, r_eff_m: f64, e_star_pa: f64, speed_m_s: f64) -> Option<f64> {
    let ok = |x: f64| x.is_finite() && x > 0.0;
    if !(ok(m_eff_kg) && ok(r_eff_m) && ok(e_star_pa) && ok(speed_m_s)) {
        return None;
    }
    Some(2.8683 * (m_eff_kg * m_eff_kg / (r_eff_m * e_star_pa * e_star_pa * speed_m_s)).powf(0.2))
}

/// Effective Hertz modulus `E* = 1 / ((1−ν₁²)/E₁ + (1−ν₂²)/E₂)` \[Pa\].
/// Pass `f64::INFINITY` for a rigid second body.
pub fn effective_modulus(e1_pa: f64, nu1: f64, e2_pa: f64, nu2: f64) -> f64 {
    1.0 / ((1.0 - nu1 * nu1) / e1_pa + (1.0 - nu2 * nu2) / e2_pa)
}

/// Harmonic combination `1/(1/a + 1/b)` used for effective mass and radius;
/// `f64::INFINITY` stands for an immovable body or a flat surface.
pub fn harmonic(a: f64, b: f64) -> f64 {
    1.0 / (1.0 / a + 1.0 / b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_contact_excites_the_lowest_mode_within_2_db() {
        for f in [50.0, 1000.0, 5000.0, 14_000.0, 40_000.0] {
            let tau = default_contact_time_s(f);
            assert!(tau <= DEFAULT_CONTACT_TIME_S);
            let c = half_sine_spectrum(C64::new(0.0, 2.0 * PI * f), tau).abs();
            assert!(c >= PI / 4.0 - 1e-12, "{f} Hz: C = {c}");
        }
        assert_eq!(default_contact_time_s(1000.0), DEFAULT_CONTACT_TIME_S);
        assert_eq!(default_contact_time_s(f64::NAN), DEFAULT_CONTACT_TIME_S);
        // The fixed 0.1 ms left a 14.7 kHz mode 38 dB down.
        let old = half_sine_spectrum(C64::new(0.0, 2.0 * PI * 14_700.0), DEFAULT_CONTACT_TIME_S).abs();
        assert!(old < 0.03, "{old}");
    }

    #[test]
    fn hertz_example_of_analytic_md() {
        // analytic.md §3: steel ball R = 5 mm (4.110 g) on a massive steel flat
        // at 1 m/s (E = 200 GPa, ν = 0.3): t_c = 35.24 µs.
        let e_star = effective_modulus(200e9, 0.3, 200e9, 0.3);
        let m = harmonic(4.110e-3, f64::INFINITY);
        let r = harmonic(5e-3, f64::INFINITY);
        let t = hertz_contact_time(m, r, e_star, 1.0).unwrap();
        assert!((t - 35.24e-6).abs() < 0.01e-6, "{t}");
        // t_c ∝ v^(−1/5).
        let t32 = hertz_contact_time(m, r, e_star, 32.0).unwrap();
        assert!((t32 / t - 0.5).abs() < 1e-12);
        assert!(hertz_contact_time(m, r, e_star, 0.0).is_none());
        assert!(hertz_contact_time(f64::NAN, r, e_star, 1.0).is_none());
    }

    /// Numerical Laplace transform of the centred unit-area half-sine.
    fn quadrature(s: C64, tau: f64) -> C64 {
        let n = 20000;
        let h = tau / n as f64;
        let mut acc = C64::ZERO;
        for k in 0..n {
            let t = (k as f64 + 0.5) * h;
            let f = PI / (2.0 * tau) * (PI * t / tau).sin();
            acc += s.scale(-(t - tau / 2.0)).exp().scale(f * h);
        }
        acc
    }

    #[test]
    fn spectrum_matches_quadrature_including_resonance() {
        let tau = 1e-4;
        for s in [
            C64::new(-3.0, 2.0 * PI * 440.0),
            C64::new(-800.0, 2.0 * PI * 7000.0),
            C64::new(0.0, PI / tau),           // exactly the removable singularity
            C64::new(-2.0, PI / tau * 1.0001), // next to it
            C64::new(-50.0, 3.0 * PI / tau),   // first null
        ] {
            let (a, b) = (half_sine_spectrum(s, tau), quadrature(s, tau));
            assert!((a - b).abs() < 1e-7, "{s:?}: {a:?} vs {b:?}");
        }
        assert_eq!(half_sine_spectrum(C64::new(-5.0, 1000.0), 0.0), C64::new(1.0, 0.0));
        // Overflow is mapped to zero, never NaN.
        assert_eq!(half_sine_spectrum(C64::new(-1e6, 1e3), 0.1), C64::ZERO);
    }
}
