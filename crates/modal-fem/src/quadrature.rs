//! Quadrature rules on the reference tetrahedron.
//!
//! **Reference tet** (stated once for the crate): vertices `(0,0,0)`,
//! `(1,0,0)`, `(0,1,0)`, `(0,0,1)` in coordinates `ξ = (ξ, η, ζ)`, volume
//! 1/6, barycentric coordinates `L₀ = 1 − ξ − η − ζ`, `L₁ = ξ`, `L₂ = η`,
//! `L₃ = ζ`. Every rule approximates `∫ f dξ ≈ Σ wᵢ f(ξᵢ)` with `Σ wᵢ = 1/6`.
//!
//! Rules (all exact for polynomials up to the stated degree; the unit tests
//! check every monomial `ξᵃ ηᵇ ζᶜ`, `a + b + c ≤ degree`, against the exact
//! value `a! b! c! / (a + b + c + 3)!`):
//! - degree 1: the centroid, weight 1/6.
//! - degree 2: 4 points `L = (b, a, a, a)` and permutations with
//!   `a = (5 − √5)/20`, `b = 1 − 3a`, weights 1/24 (Hammer, Marlowe & Stroud 1956).
//! - degree 3: 8 points with positive weights, derived here from the symmetric
//!   moment equations: the 4 vertices (weight 1/240) and the 4 face centroids
//!   (weight 3/80). Exactness: Σw = 1/6, ∫L₀² = 1/60, ∫L₀³ = 1/120 hold.
//! - degree 5: the classical 14-point rule with positive weights (as listed
//!   e.g. by Walkington 2000, "Quadrature on simplices of arbitrary
//!   dimension"): two orbits `(a, a, a, 1 − 3a)` and one orbit
//!   `(b, b, ½ − b, ½ − b)`; its 16-digit constants are verified by the
//!   exactness test, not trusted.
//! - any odd degree `2s + 1`: Grundmann & Möller 1978 ("Invariant integration
//!   formulas for the n-simplex by combinatorial methods", SIAM J. Numer.
//!   Anal. 15), built from its closed formula; it has negative weights and is
//!   used only where a degree above 5 is needed (mass properties of curved
//!   10-node tets, degree 7).

/// A quadrature rule on the reference tet: points `ξᵢ` and weights `wᵢ`.
#[derive(Clone, Debug, PartialEq)]
pub struct QuadratureRule {
    /// Highest total polynomial degree integrated exactly.
    pub degree: u32,
    /// Points in reference coordinates `(ξ, η, ζ)`.
    pub points: Vec<[f64; 3]>,
    /// Weights, summing to 1/6.
    pub weights: Vec<f64>,
}

impl QuadratureRule {
    /// The cheapest rule here that is exact to at least `degree`
    /// (degrees 0–5 from the positive-weight rules, higher from
    /// Grundmann–Möller).
    pub fn exact_to(degree: u32) -> QuadratureRule {
        match degree {
            0 | 1 => centroid(),
            2 => degree2(),
            3 => degree3(),
            4 | 5 => degree5(),
            d => grundmann_moller(d.div_ceil(2).saturating_sub(1) as usize),
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True for a rule without points (never produced by this module).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    fn from_barycentric(degree: u32, orbits: &[(Vec<[f64; 4]>, f64)]) -> QuadratureRule {
        let mut points = Vec::new();
        let mut weights = Vec::new();
        for (members, w) in orbits {
            for l in members {
                points.push([l[1], l[2], l[3]]);
                weights.push(*w);
            }
        }
        QuadratureRule { degree, points, weights }
    }
}

/// All distinct permutations of barycentric point `(a, a, a, 1 − 3a)`.
fn orbit_31(a: f64) -> Vec<[f64; 4]> {
    let b = 1.0 - 3.0 * a;
    (0..4)
        .map(|k| {
            let mut l = [a; 4];
            l[k] = b;
            l
        })
        .collect()
}

/// All distinct permutations of barycentric point `(b, b, ½ − b, ½ − b)`.
fn orbit_22(b: f64) -> Vec<[f64; 4]> {
    let c = 0.5 - b;
    let pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
    pairs
        .iter()
        .map(|&(i, j)| {
            let mut l = [c; 4];
            l[i] = b;
            l[j] = b;
            l
        })
        .collect()
}

fn centroid() -> QuadratureRule {
    QuadratureRule { degree: 1, points: vec![[0.25; 3]], weights: vec![1.0 / 6.0] }
}

fn degree2() -> QuadratureRule {
    let a = (5.0 - 5f64.sqrt()) / 20.0;
    QuadratureRule::from_barycentric(2, &[(orbit_31(a), 1.0 / 24.0)])
}

fn degree3() -> QuadratureRule {
    QuadratureRule::from_barycentric(3, &[(orbit_31(0.0), 1.0 / 240.0), (orbit_31(1.0 / 3.0), 3.0 / 80.0)])
}

fn degree5() -> QuadratureRule {
    // Walkington (2000), 14-point rule; weights below are for volume 1/6.
    QuadratureRule::from_barycentric(
        5,
        &[
            (orbit_31(0.092_735_250_310_891_2), 0.073_493_043_116_361_9 / 6.0),
            (orbit_31(0.310_885_919_263_300_6), 0.112_687_925_718_015_9 / 6.0),
            (orbit_22(0.045_503_704_125_649_6), 0.042_546_020_777_081_5 / 6.0),
        ],
    )
}

/// Grundmann–Möller rule of degree `2s + 1` on the 3-simplex:
/// `Σᵢ₌₀ˢ (−1)ⁱ 2⁻²ˢ (d+n−2i)ᵈ / (i! (d+n−i)!) Σ_{|β| = s−i} f((2β + 1)/(d+n−2i))`,
/// `d = 2s + 1`, `n = 3`, β ranging over 4-tuples of non-negative integers.
fn grundmann_moller(s: usize) -> QuadratureRule {
    let n = 3usize;
    let d = 2 * s + 1;
    let factorial = |k: usize| (1..=k).map(|v| v as f64).product::<f64>();
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for i in 0..=s {
        let denom = (d + n - 2 * i) as f64;
        let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
        let w =
            sign * 2f64.powi(-2 * s as i32) * denom.powi(d as i32) / (factorial(i) * factorial(d + n - i));
        let total = s - i;
        for b1 in 0..=total {
            for b2 in 0..=total - b1 {
                for b3 in 0..=total - b1 - b2 {
                    let coord = |b: usize| (2 * b + 1) as f64 / denom;
                    points.push([coord(b1), coord(b2), coord(b3)]);
                    weights.push(w);
                }
            }
        }
    }
    QuadratureRule { degree: d as u32, points, weights }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exact_monomial(a: u32, b: u32, c: u32) -> f64 {
        let f = |k: u32| (1..=k).map(f64::from).product::<f64>();
        f(a) * f(b) * f(c) / f(a + b + c + 3)
    }

    /// Largest relative error over all monomials of total degree ≤ `degree`.
    fn max_error(rule: &QuadratureRule, degree: u32) -> f64 {
        let mut worst: f64 = 0.0;
        for a in 0..=degree {
            for b in 0..=degree - a {
                for c in 0..=degree - a - b {
                    let q: f64 = rule
                        .points
                        .iter()
                        .zip(&rule.weights)
                        .map(|(p, w)| w * p[0].powi(a as i32) * p[1].powi(b as i32) * p[2].powi(c as i32))
                        .sum();
                    let exact = exact_monomial(a, b, c);
                    worst = worst.max((q - exact).abs() / exact);
                }
            }
        }
        worst
    }

    #[test]
    fn each_rule_is_exact_to_its_degree_and_not_beyond() {
        for (degree, n_points) in [(1, 1), (2, 4), (3, 8), (5, 14), (7, 35)] {
            let rule = QuadratureRule::exact_to(degree);
            assert_eq!(rule.degree, degree);
            assert_eq!(rule.len(), n_points);
            let err = max_error(&rule, degree);
            assert!(err < 1e-13, "degree {degree}: relative error {err}");
            assert!(max_error(&rule, degree + 1) > 1e-6, "degree {degree} rule is exact beyond its degree");
        }
    }

    #[test]
    fn low_order_rules_have_positive_weights_inside_the_tet() {
        for degree in [1, 2, 3, 5] {
            let rule = QuadratureRule::exact_to(degree);
            assert!(rule.weights.iter().all(|&w| w > 0.0));
            for p in &rule.points {
                assert!(p.iter().all(|&x| x >= 0.0) && p.iter().sum::<f64>() <= 1.0 + 1e-15);
            }
        }
    }

    #[test]
    fn grundmann_moller_low_degrees_are_exact() {
        for s in 0..4 {
            let rule = grundmann_moller(s);
            assert!(max_error(&rule, 2 * s as u32 + 1) < 1e-12, "s = {s}");
        }
    }
}
