//! Special functions: spherical Bessel and Hankel functions of the first
//! kind and orthonormal complex spherical harmonics.
//!
//! - `j_l(x)` from `j_0 = sin x / x`, `j_1 = sin x / x² − cos x / x`: the
//!   upward recurrence `j_{l+1} = (2l+1)/x · j_l − j_{l−1}` where it is
//!   stable (`l < x`), otherwise Miller's downward recurrence from
//!   `l_0 = L + √(40 L) + 16 + x` (zero start, rescaled against overflow)
//!   normalized by `j_0` or `j_1`, whichever is larger.
//! - `h_l(x) = j_l(x) + i y_l(x)`, from `h_0(x) = −i e^{ix}/x`,
//!   `h_1(x) = −e^{ix}(x + i)/x²` and the upward recurrence
//!   `h_{l+1} = (2l+1)/x · h_l − h_{l−1}` (stable for `h_l`, whose modulus
//!   grows with `l`); `h_l'(x) = h_{l−1}(x) − (l+1)/x · h_l(x)`,
//!   `h_0' = −h_1`. Far away `h_l(x) → (−i)^{l+1} e^{ix}/x`.
//! - `Y_l^m(θ, φ) = Q_l^m(cos θ) e^{imφ}` with `∫|Y_l^m|² dΩ = 1` and the
//!   Condon–Shortley phase; `Q` by the standard normalized three-term
//!   recurrence in `l`; `Y_l^{−m} = (−1)^m conj(Y_l^m)`.
//!   Coefficient index of `(l, m)` is `l² + l + m`.

use faer::c64;

/// `h_l(x)` for `l = 0..=order` (`x > 0`).
pub fn spherical_hankel(order: usize, x: f64) -> Vec<c64> {
    let e = c64::new(x.cos(), x.sin());
    let mut h = Vec::with_capacity(order + 1);
    h.push(e * c64::new(0.0, -1.0 / x));
    if order >= 1 {
        h.push(-e * c64::new(x, 1.0) / (x * x));
    }
    for l in 1..order {
        let next = h[l] * ((2 * l + 1) as f64 / x) - h[l - 1];
        h.push(next);
    }
    h
}

/// `j_l(x)` for `l = 0..=order` (`x ≥ 0`), see the module doc.
pub fn spherical_bessel_j(order: usize, x: f64) -> Vec<f64> {
    let mut j = vec![0.0; order + 1];
    if x == 0.0 {
        j[0] = 1.0;
        return j;
    }
    let (j0, j1) = if x < 1e-3 {
        let x2 = x * x;
        (1.0 - x2 / 6.0 + x2 * x2 / 120.0, x / 3.0 * (1.0 - x2 / 10.0))
    } else {
        let (s, c) = x.sin_cos();
        (s / x, s / (x * x) - c / x)
    };
    j[0] = j0;
    if order == 0 {
        return j;
    }
    j[1] = j1;
    if (order as f64) < x {
        for l in 1..order {
            j[l + 1] = (2 * l + 1) as f64 / x * j[l] - j[l - 1];
        }
        return j;
    }
    let start = order + (40.0 * order as f64).sqrt() as usize + 16 + x as usize;
    let (mut above, mut here) = (0.0f64, 1e-300f64);
    for l in (1..=start).rev() {
        // here = f_l, above = f_{l+1}; f_{l−1} = (2l+1)/x f_l − f_{l+1}.
        if l <= order {
            j[l] = here;
        }
        let below = (2 * l + 1) as f64 / x * here - above;
        above = here;
        here = below;
        if here.abs() > 1e250 {
            here *= 1e-250;
            above *= 1e-250;
            for v in j.iter_mut().skip(l) {
                *v *= 1e-250;
            }
        }
    }
    j[0] = here;
    let scale = if j0.abs() >= j1.abs() { j0 / j[0] } else { j1 / j[1] };
    for v in &mut j {
        *v *= scale;
    }
    j
}

/// `h_l'(x)` for `l = 0..=order` (`x > 0`).
pub fn spherical_hankel_derivative(order: usize, x: f64) -> Vec<c64> {
    let h = spherical_hankel(order + 1, x);
    (0..=order).map(|l| if l == 0 { -h[1] } else { h[l - 1] - h[l] * ((l + 1) as f64 / x) }).collect()
}

/// Index of the coefficient of degree `l`, order `m` (`|m| ≤ l`).
pub fn lm_index(l: usize, m: i64) -> usize {
    ((l * l + l) as i64 + m) as usize
}

/// Orthonormal complex spherical harmonics `Y_l^m(d̂)` for every
/// `l ≤ order`, `|m| ≤ l`, at the direction `d` (need not be unit length,
/// must be non-zero), in the order of [`lm_index`]. For many directions at
/// one order, [`Harmonics`] keeps the recurrence's coefficients and the
/// output buffer (same values, bit for bit).
pub fn spherical_harmonics(order: usize, d: [f64; 3]) -> Vec<c64> {
    let mut y = vec![c64::new(0.0, 0.0); (order + 1) * (order + 1)];
    Harmonics::new(order).evaluate(d, &mut y);
    y
}

/// The coefficients of the normalized associated Legendre recurrence up to
/// one degree `L`, computed once (two square roots per `(l, m)`, which
/// otherwise dominate an evaluation):
///
/// `Q_m^m = c_m s Q_{m−1}^{m−1}`, `c_m = −√((2m+1)/(2m))`, `Q_0^0 = 1/√(4π)`;
/// `Q_{m+1}^m = √(2m+3) x Q_m^m`;
/// `Q_l^m = a_lm (x Q_{l−1}^m − b_lm Q_{l−2}^m)`,
/// `a_lm = √((4l²−1)/(l²−m²))`, `b_lm = √(((l−1)²−m²)/(4(l−1)²−1))`,
///
/// `x = cos θ`, `s = sin θ`, and `Y_l^m = Q_l^m e^{imφ}`,
/// `Y_l^{−m} = (−1)^m conj(Y_l^m)`.
#[derive(Clone, Debug)]
pub struct Harmonics {
    order: usize,
    /// `c_m` for `m = 0..=L` (`c_0` unused).
    diagonal: Vec<f64>,
    /// `√(2m+3)`.
    first: Vec<f64>,
    /// `(a_lm, b_lm)` at `l·(L+1) + m`.
    recurrence: Vec<(f64, f64)>,
}

impl Harmonics {
    /// The table for degrees `0..=order`.
    pub fn new(order: usize) -> Harmonics {
        let n = order + 1;
        let mut recurrence = vec![(0.0, 0.0); n * n];
        for m in 0..=order {
            for l in m + 2..=order {
                let (lf, mf) = (l as f64, m as f64);
                let a = ((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf)).sqrt();
                let b = (((lf - 1.0) * (lf - 1.0) - mf * mf) / (4.0 * (lf - 1.0) * (lf - 1.0) - 1.0)).sqrt();
                recurrence[l * n + m] = (a, b);
            }
        }
        Harmonics {
            order,
            diagonal: (0..=order)
                .map(|m| if m == 0 { 0.0 } else { -((2 * m + 1) as f64 / (2 * m) as f64).sqrt() })
                .collect(),
            first: (0..=order).map(|m| ((2 * m + 3) as f64).sqrt()).collect(),
            recurrence,
        }
    }

    /// Highest degree `L`.
    pub fn order(&self) -> usize {
        self.order
    }

    /// Writes `Y_l^m(d̂)` for `l ≤ L` into `y[lm_index(l, m)]`
    /// (`y.len() ≥ (L+1)²`; `d` need not be unit length, must be non-zero).
    pub fn evaluate(&self, d: [f64; 3], y: &mut [c64]) {
        self.evaluate_to(self.order, d, y);
    }

    /// [`Harmonics::evaluate`] for the degrees `l ≤ order ≤ L` only
    /// (`y.len() ≥ (order+1)²`).
    pub fn evaluate_to(&self, order: usize, d: [f64; 3], y: &mut [c64]) {
        assert!(order <= self.order, "degree {order} above the table's {}", self.order);
        let n = self.order + 1;
        debug_assert!(y.len() >= (order + 1) * (order + 1));
        let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let x = d[2] / r;
        let rho = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let (cos_phi, sin_phi) = if rho > 0.0 { (d[0] / rho, d[1] / rho) } else { (1.0, 0.0) };
        let s = rho / r; // sin θ ≥ 0
                         // e^{imφ} by repeated multiplication.
        let mut eim = c64::new(1.0, 0.0);
        let e1 = c64::new(cos_phi, sin_phi);
        let mut qmm = (1.0 / (4.0 * std::f64::consts::PI)).sqrt();
        for m in 0..=order {
            if m > 0 {
                qmm *= self.diagonal[m] * s;
            }
            let sign = if m % 2 == 0 { 1.0 } else { -1.0 };
            let mut put = |l: usize, q: f64| {
                let v = eim * q;
                y[lm_index(l, m as i64)] = v;
                if m > 0 {
                    y[lm_index(l, -(m as i64))] = v.conj() * sign;
                }
            };
            put(m, qmm);
            if m < order {
                let (mut below, mut here) = (qmm, self.first[m] * x * qmm);
                put(m + 1, here);
                for l in m + 2..=order {
                    let (a, b) = self.recurrence[l * n + m];
                    let next = a * (x * here - b * below);
                    put(l, next);
                    below = here;
                    here = next;
                }
            }
            eim *= e1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hankel_matches_closed_forms() {
        for &x in &[0.1, 1.0, 3.7, 25.0] {
            let h = spherical_hankel(3, x);
            let (s, c) = (x.sin(), x.cos());
            // j_2, y_2 closed forms.
            let j2 = (3.0 / (x * x) - 1.0) * s / x - 3.0 * c / (x * x);
            let y2 = -(3.0 / (x * x) - 1.0) * c / x - 3.0 * s / (x * x);
            assert!((h[2].re - j2).abs() <= 1e-9 * h[2].norm(), "x={x}");
            assert!((h[2].im - y2).abs() <= 1e-12 * h[2].norm(), "x={x}");
            let j0 = s / x;
            assert!((h[0].re - j0).abs() < 1e-15);
        }
    }

    #[test]
    fn bessel_j_matches_hankel_real_part_and_small_argument_series() {
        // Where the upward recurrence of h_l is accurate for its real part
        // (|j_l| not much below |h_l|): l ≤ x.
        for &x in &[0.5, 3.7, 25.0, 80.0] {
            let order = 60;
            let j = spherical_bessel_j(order, x);
            let h = spherical_hankel(order, x);
            for l in 0..=order.min(x as usize) {
                assert!(
                    (j[l] - h[l].re).abs() <= 1e-10 * h[l].norm(),
                    "l={l} x={x}: {} vs {}",
                    j[l],
                    h[l].re
                );
            }
        }
        // l ≫ x: j_l(x) ≈ x^l/(2l+1)!! · (1 − x²/(2(2l+3))), the next term O(x⁴).
        for &x in &[1e-4, 0.01, 0.3] {
            let j = spherical_bessel_j(40, x);
            let mut dfact = 1.0f64;
            for (l, jl) in j.iter().enumerate() {
                dfact *= (2 * l + 1) as f64;
                let series = x.powi(l as i32) / dfact * (1.0 - x * x / (2.0 * (2 * l + 3) as f64));
                let rel = x.powi(4) / ((2 * l + 3) as f64 * (2 * l + 5) as f64);
                assert!((jl - series).abs() <= (rel + 1e-12) * series.abs(), "l={l} x={x}: {jl} vs {series}");
            }
        }
        // A zero of j_0 (x = π): normalized through j_1.
        let j = spherical_bessel_j(3, std::f64::consts::PI);
        let h = spherical_hankel(3, std::f64::consts::PI);
        for l in 0..=3 {
            assert!((j[l] - h[l].re).abs() < 1e-12, "l={l}");
        }
    }

    #[test]
    fn hankel_derivative_matches_finite_differences() {
        for &x in &[0.3, 2.0, 9.0] {
            let d = spherical_hankel_derivative(4, x);
            let e = 1e-6;
            let (a, b) = (spherical_hankel(4, x + e), spherical_hankel(4, x - e));
            for l in 0..=4 {
                let fd = (a[l] - b[l]) / (2.0 * e);
                assert!((fd - d[l]).norm() <= 1e-6 * d[l].norm(), "l={l} x={x}");
            }
        }
    }

    #[test]
    fn harmonics_are_orthonormal_on_a_product_grid() {
        let order = 6;
        let (nt, np) = (12, 16);
        let (nodes, weights) = crate::quadrature::gauss_legendre(nt);
        let nc = (order + 1) * (order + 1);
        let mut gram = vec![c64::new(0.0, 0.0); nc * nc];
        for (t, w) in nodes.iter().zip(&weights) {
            for p in 0..np {
                let phi = 2.0 * std::f64::consts::PI * p as f64 / np as f64;
                let st = (1.0 - t * t).sqrt();
                let y = spherical_harmonics(order, [st * phi.cos(), st * phi.sin(), *t]);
                let wq = w * 2.0 * std::f64::consts::PI / np as f64;
                for a in 0..nc {
                    for b in 0..nc {
                        gram[a * nc + b] += y[a] * y[b].conj() * wq;
                    }
                }
            }
        }
        for a in 0..nc {
            for b in 0..nc {
                let want = if a == b { 1.0 } else { 0.0 };
                assert!((gram[a * nc + b] - want).norm() < 1e-12, "{a} {b} {}", gram[a * nc + b]);
            }
        }
        // Y_1^0 = sqrt(3/4π) cos θ.
        let y = spherical_harmonics(1, [0.3, -0.2, 0.5]);
        let r = (0.09f64 + 0.04 + 0.25).sqrt();
        let want = (3.0 / (4.0 * std::f64::consts::PI)).sqrt() * 0.5 / r;
        assert!((y[lm_index(1, 0)].re - want).abs() < 1e-15);
    }

    #[test]
    fn a_table_evaluates_any_lower_degree_and_reuses_its_buffer() {
        // The table of degree 12 indexes its recurrence by 13 columns; a
        // degree-5 evaluation must still equal a fresh degree-5 one, and a
        // dirty buffer must be fully overwritten.
        let table = Harmonics::new(12);
        let mut y = vec![c64::new(f64::NAN, f64::NAN); 13 * 13];
        for d in [[0.3, -0.2, 0.5], [0.0, 0.0, -2.0], [1.0, 2.0, 0.0]] {
            table.evaluate_to(5, d, &mut y);
            let fresh = Harmonics::new(5);
            let mut want = vec![c64::new(0.0, 0.0); 36];
            fresh.evaluate(d, &mut want);
            assert_eq!(&y[..36], &want[..]);
            table.evaluate(d, &mut y);
            assert_eq!(y, spherical_harmonics(12, d));
            assert!(y.iter().all(|v| v.re.is_finite() && v.im.is_finite()));
        }
    }
}
