//! Phases for a direction-free level estimate of modes of one frequency.
//!
//! Without a listener's transfer each mode is heard through a real level
//! `g_i` (the RMS normal velocity of its shape, say). Symmetric bodies (a
//! bowl, a bell, a cylinder) have pairs of modes of one frequency whose
//! basis the eigensolver turns arbitrarily: struck at one point the pair
//! gets modal amplitudes `a₁ = A cos θ`, `a₂ = A sin θ`, θ set by that
//! arbitrary turn, and real levels sum them coherently, `g A (cos θ + sin θ)`:
//! anything from 0 to `√2 g A`. The physical pair's far fields are
//! orthogonal over directions, so the level a direction-free estimate
//! should give is the energy sum `g √(a₁² + a₂²) = g A`, whatever θ. Giving
//! the second mode the phase `i` does exactly that:
//! `|a₁ + i a₂| = √(a₁² + a₂²)`.
//!
//! A group of `n` modes within [`DEGENERATE_TOLERANCE`] of the group's
//! lowest frequency gets the phases `e^{iπk/n}`, `k = 0..n`: for pairs the
//! quadrature above. (For `n ≥ 3` no fixed phases can make the sum
//! independent of the turn, since a real 3-vector always has a direction
//! that cancels in ℂ; spread phases still avoid the coherent sum's `√n`
//! peaks.)

use crate::complex::C64;

/// Relative frequency difference within which modes form one group (the
/// radiation solver groups at the same tolerance).
pub const DEGENERATE_TOLERANCE: f64 = 1e-3;

/// One phase per mode for frequencies `frequencies_hz` (module doc);
/// isolated modes get 1.
pub fn degenerate_phases(frequencies_hz: &[f64]) -> Vec<C64> {
    let mut order: Vec<usize> = (0..frequencies_hz.len()).collect();
    order.sort_by(|&a, &b| frequencies_hz[a].total_cmp(&frequencies_hz[b]).then(a.cmp(&b)));
    let mut phases = vec![C64::new(1.0, 0.0); frequencies_hz.len()];
    let mut start = 0;
    while start < order.len() {
        let lowest = frequencies_hz[order[start]];
        let mut end = start + 1;
        while end < order.len() && frequencies_hz[order[end]] - lowest <= DEGENERATE_TOLERANCE * lowest.abs()
        {
            end += 1;
        }
        let n = end - start;
        for (k, &mode) in order[start..end].iter().enumerate() {
            let angle = std::f64::consts::PI * k as f64 / n as f64;
            phases[mode] = C64::new(angle.cos(), angle.sin());
        }
        start = end;
    }
    phases
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_are_in_quadrature_and_their_level_does_not_depend_on_the_turn() {
        let f = [500.0, 1200.0, 1200.4, 3000.0, 2999.9, 2999.95, 7000.0];
        let p = degenerate_phases(&f);
        assert_eq!(p[0], C64::new(1.0, 0.0));
        assert_eq!(p[6], C64::new(1.0, 0.0));
        // The pair (1, 2): 1 and i.
        assert_eq!(p[1], C64::new(1.0, 0.0));
        assert!((p[2] - C64::new(0.0, 1.0)).abs() < 1e-15);
        for theta in [0.0, 0.3, 0.785, 2.0, 2.356] {
            let (a1, a2) = (f64::cos(theta), f64::sin(theta));
            let sum = p[1].scale(a1) + p[2].scale(a2);
            assert!((sum.abs() - 1.0).abs() < 1e-12, "θ {theta}: {}", sum.abs());
        }
        // The triple (3, 4, 5), lowest first: e^{iπk/3}.
        for (mode, k) in [(4, 0), (5, 1), (3, 2)] {
            let angle = std::f64::consts::PI * k as f64 / 3.0;
            assert!((p[mode] - C64::new(angle.cos(), angle.sin())).abs() < 1e-15, "mode {mode}");
        }
    }
}
