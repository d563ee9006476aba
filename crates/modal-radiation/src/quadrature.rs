//! Quadrature rules: Gauss–Legendre on `[−1, 1]` and a degree-5 rule on
//! triangles.
//!
//! Gauss–Legendre nodes are the roots of `P_n`, found by Newton's method
//! from the Chebyshev guess `cos(π(i − ¼)/(n + ½))`, with weights
//! `2 / ((1 − x²) P_n'(x)²)`. The triangle rule is Dunavant's 7-point rule
//! (exact for polynomials of degree 5), weights summing to 1 (multiply by
//! the area).

/// Gauss–Legendre nodes and weights on `[−1, 1]` (`n ≥ 1`), ascending.
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (p, d) = legendre_and_derivative(n, x);
            dp = d;
            let dx = p / d;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let (_, d) = legendre_and_derivative(n, x);
        if d != 0.0 {
            dp = d;
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        nodes[i] = -x;
        nodes[n - 1 - i] = x;
        weights[i] = w;
        weights[n - 1 - i] = w;
    }
    if n % 2 == 1 {
        nodes[n / 2] = 0.0;
    }
    (nodes, weights)
}

/// Gauss–Legendre nodes and weights mapped to `[0, 1]` (weights summing
/// to 1): the rule of the singular integrals along a panel edge and along
/// a ray.
pub fn gauss_legendre_unit(n: usize) -> (Vec<f64>, Vec<f64>) {
    let (x, w) = gauss_legendre(n);
    (x.iter().map(|x| 0.5 * (x + 1.0)).collect(), w.iter().map(|w| 0.5 * w).collect())
}

/// `P_n(x)` and `P_n'(x)` by the three-term recurrence.
fn legendre_and_derivative(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

/// The point of triangle `t` with barycentric coordinates `b`:
/// `b₀ t₀ + b₁ t₁ + b₂ t₂` [m].
#[inline]
pub fn on_triangle(b: [f64; 3], t: [[f64; 3]; 3]) -> [f64; 3] {
    [0, 1, 2].map(|k| b[0] * t[0][k] + b[1] * t[1][k] + b[2] * t[2][k])
}

/// The four children of triangle `t` split at its edge midpoints (corners
/// as positions or as barycentric coordinates), the centre child last.
#[inline]
pub fn quarters(t: [[f64; 3]; 3]) -> [[[f64; 3]; 3]; 4] {
    let m = |p: [f64; 3], q: [f64; 3]| [0, 1, 2].map(|k| 0.5 * (p[k] + q[k]));
    let (ab, bc, ca) = (m(t[0], t[1]), m(t[1], t[2]), m(t[2], t[0]));
    [[t[0], ab, ca], [ab, t[1], bc], [ca, bc, t[2]], [ab, bc, ca]]
}

/// Strang–Fix 3-point rule at the edge-interior points `(2/3, 1/6, 1/6)`,
/// exact for polynomials of degree 2, weights summing to 1.
pub const TRIANGLE_3: [([f64; 3], f64); 3] = [
    ([2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0], 1.0 / 3.0),
    ([1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0], 1.0 / 3.0),
    ([1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0], 1.0 / 3.0),
];

/// Dunavant's 7-point rule, exact for polynomials of degree 5, weights
/// summing to 1.
pub const TRIANGLE_7: [([f64; 3], f64); 7] = {
    const A1: f64 = 0.059_715_871_789_770;
    const B1: f64 = 0.470_142_064_105_115;
    const W1: f64 = 0.132_394_152_788_506;
    const A2: f64 = 0.797_426_985_353_087;
    const B2: f64 = 0.101_286_507_323_456;
    const W2: f64 = 0.125_939_180_544_827;
    [
        ([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], 0.225),
        ([A1, B1, B1], W1),
        ([B1, A1, B1], W1),
        ([B1, B1, A1], W1),
        ([A2, B2, B2], W2),
        ([B2, A2, B2], W2),
        ([B2, B2, A2], W2),
    ]
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        for n in [1, 2, 5, 12, 33] {
            let (x, w) = gauss_legendre(n);
            for p in 0..2 * n {
                let got: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p as i32)).sum();
                let want = if p % 2 == 1 { 0.0 } else { 2.0 / (p as f64 + 1.0) };
                assert!((got - want).abs() < 1e-13, "n={n} p={p} {got} {want}");
            }
        }
    }

    #[test]
    fn triangle_rule_is_exact_to_degree_five() {
        // ∫ over the unit simplex of a^i b^j = i! j! / (i + j + 2)!, times 2 (area ½).
        let fact = |n: usize| (1..=n).product::<usize>() as f64;
        for i in 0..=5 {
            for j in 0..=5 - i {
                let got: f64 =
                    TRIANGLE_7.iter().map(|(b, w)| w * b[0].powi(i as i32) * b[1].powi(j as i32)).sum();
                let want = 2.0 * fact(i) * fact(j) / fact(i + j + 2);
                assert!((got - want).abs() < 1e-13, "{i} {j}");
            }
        }
    }
}
