//! The 6-node (quadratic) surface triangle's map and its normal:
//! `x(ξ, η) = Σ_k N_k(ξ, η) x_k`, nodes ordered corners 0–2 then the
//! mid-edge nodes of edges (0,1), (1,2), (2,0), with `λ₀ = 1 − ξ − η`,
//! `N_k = λ_k (2λ_k − 1)` at corners and `4 λ_a λ_b` at mid-edge nodes.

use crate::validate::cross;

/// `∂x/∂ξ × ∂x/∂η` of the 6-node triangle with nodes `x` at `(ξ, η)`: the
/// curved surface's normal scaled by twice the local area element.
pub fn quadratic_triangle_normal(x: &[[f64; 3]; 6], xi: f64, eta: f64) -> [f64; 3] {
    let l0 = 1.0 - xi - eta;
    let d_xi = [-(4.0 * l0 - 1.0), 4.0 * xi - 1.0, 0.0, 4.0 * (l0 - xi), 4.0 * eta, -4.0 * eta];
    let d_eta = [-(4.0 * l0 - 1.0), 0.0, 4.0 * eta - 1.0, -4.0 * xi, 4.0 * xi, 4.0 * (l0 - eta)];
    let mut a = [0.0; 3];
    let mut b = [0.0; 3];
    for k in 0..6 {
        for q in 0..3 {
            a[q] += d_xi[k] * x[k][q];
            b[q] += d_eta[k] * x[k][q];
        }
    }
    cross(a, b)
}
