//! `sin x` and `cos x` written so that a loop over many arguments
//! vectorizes (no call, no branch), for the batched kernels of
//! [`crate::batch`]:
//!
//! `x = n·π/2 + r`, `|r| ≤ π/4`, `n` the nearest integer to `x·2/π`
//! (Cody–Waite: `π/2` in three parts, the first two with 33 significant
//! bits so that `n·(π/2)₁` and `n·(π/2)₂` are exact for `|n| < 2²⁰`);
//! `sin r`, `cos r` by their Taylor series to degree 17 and 18 (truncation
//! `≤ (π/4)¹⁹/19! ≈ 8·10⁻²⁰`); then by `n mod 4`
//! `(sin x, cos x) = (s, c), (c, −s), (−s, −c), (−c, s)`.
//!
//! The integer part and `n mod 4` come from adding `1.5·2⁵²` (the float
//! then holds `n` in its low mantissa bits), the quadrant's swap and signs
//! from bit masks: every step is an add, a multiply or a bitwise operation
//! on 64-bit lanes. Agrees with libm within 2 ulp for `|x| ≤`
//! [`MAX_ARGUMENT`] (test below).

/// Largest `|x|` the reduction is exact for (`|n| < 2²⁰` with margin).
pub const MAX_ARGUMENT: f64 = 1.0e5;

const TWO_OVER_PI: f64 = std::f64::consts::FRAC_2_PI;
/// `π/2 = PIO2_1 + PIO2_2 + PIO2_3` (33, 33 and 53 significant bits).
const PIO2_1: f64 = 1.5707963267341256;
const PIO2_2: f64 = 6.077100506303966e-11;
const PIO2_3: f64 = 2.0222662487959506e-21;
/// Adding it rounds to an integer held in the low mantissa bits.
const ROUND_MAGIC: f64 = 6755399441055744.0;

/// `(sin x, cos x)` for `|x| ≤` [`MAX_ARGUMENT`] (module doc); beyond it
/// the result loses accuracy, and the caller checks the range itself
/// ([`crate::batch`] tests `k·r` in the same loop and evaluates such a
/// block again with libm), since a check here could not be vectorized.
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let shifted = x * TWO_OVER_PI + ROUND_MAGIC;
    let n = shifted - ROUND_MAGIC;
    let quadrant = shifted.to_bits();
    let r = ((x - n * PIO2_1) - n * PIO2_2) - n * PIO2_3;
    let r2 = r * r;
    let s = r + r * r2 * sin_tail(r2);
    let c = 1.0 - 0.5 * r2 + r2 * r2 * cos_tail(r2);
    let swap = (quadrant & 1).wrapping_neg();
    let (sb, cb) = (s.to_bits(), c.to_bits());
    let sin_bits = (sb & !swap) | (cb & swap);
    let cos_bits = (cb & !swap) | (sb & swap);
    let sin_sign = (quadrant & 2) << 62;
    let cos_sign = (quadrant.wrapping_add(1) & 2) << 62;
    (f64::from_bits(sin_bits ^ sin_sign), f64::from_bits(cos_bits ^ cos_sign))
}

/// `(sin r − r)/r³` as a polynomial in `r²` (Taylor, to `r¹⁷`).
#[inline(always)]
fn sin_tail(r2: f64) -> f64 {
    const C: [f64; 8] = [
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5040.0,
        1.0 / 362880.0,
        -1.0 / 39916800.0,
        1.0 / 6227020800.0,
        -1.0 / 1307674368000.0,
        1.0 / 355687428096000.0,
    ];
    horner(&C, r2)
}

/// `(cos r − 1 + r²/2)/r⁴` as a polynomial in `r²` (Taylor, to `r¹⁸`).
#[inline(always)]
fn cos_tail(r2: f64) -> f64 {
    const C: [f64; 8] = [
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40320.0,
        -1.0 / 3628800.0,
        1.0 / 479001600.0,
        -1.0 / 87178291200.0,
        1.0 / 20922789888000.0,
        -1.0 / 6402373705728000.0,
    ];
    horner(&C, r2)
}

#[inline(always)]
fn horner(c: &[f64; 8], t: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ci| acc * t + ci)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(a: f64, b: f64) -> f64 {
        (a - b).abs() / (f64::EPSILON * b.abs().max(f64::MIN_POSITIVE))
    }

    #[test]
    fn agrees_with_libm_over_the_range_the_kernels_use() {
        // Quadrant boundaries, tiny arguments, negatives and a dense sweep
        // up to the largest argument allowed.
        let mut xs: Vec<f64> = (-8..=8).map(|q| q as f64 * std::f64::consts::FRAC_PI_4).collect();
        xs.extend([0.0, -0.0, 1e-300, 1e-8, -1e-8, 0.5, MAX_ARGUMENT, -MAX_ARGUMENT]);
        xs.extend((0..200_000).map(|i| (i as f64 * 0.618_034).powf(1.7) % MAX_ARGUMENT));
        let (mut worst_abs, mut worst_ulp) = (0.0f64, 0.0f64);
        for x in xs {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            worst_abs = worst_abs.max((s - s0).abs()).max((c - c0).abs());
            // Relative where the value is not near a zero of the function.
            if s0.abs() > 1e-3 {
                worst_ulp = worst_ulp.max(ulps(s, s0));
            }
            if c0.abs() > 1e-3 {
                worst_ulp = worst_ulp.max(ulps(c, c0));
            }
        }
        assert!(worst_abs < 4e-16, "largest absolute difference {worst_abs:e}");
        assert!(worst_ulp <= 2.0, "largest difference {worst_ulp} ulp");
    }

    #[test]
    fn keeps_sin_odd_and_cos_even_and_the_pythagorean_identity() {
        for i in 0..10_000 {
            let x = i as f64 * 0.0137;
            let ((s, c), (sm, cm)) = (sin_cos(x), sin_cos(-x));
            assert_eq!((s, c), (-sm, cm), "x = {x}");
            assert!((s * s + c * c - 1.0).abs() < 4.0 * f64::EPSILON, "x = {x}");
        }
    }
}
