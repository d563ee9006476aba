//! Reference frequencies (Hz) the study measures against, with their provenance.
//!
//! Material of every case: steel E = 200 GPa, ν = 0.3, ρ = 7850 kg/m³ (the values of
//! `shared/reference/analytic.md`, not the steel preset, whose ν = 0.29).
//!
//! - Free-free bar 0.3 × 0.02 × 0.01 m: the "3D converged" column of analytic.md §1
//!   (27-node hexahedra, 176k DOF, ≤ 0.02 % from the previous refinement): 12 modes.
//! - Free sphere, radius 0.05 m: Lamb (1882) roots η = ω a / c_T of analytic.md §2,
//!   `f = η c_T / (2π a)`, c_T = √(G/ρ); the 20 lowest elastic modes are
//!   T2 (×5), S2 (×5), S1 (×3), T3 (×7). η is given to 5 digits (≤ 2e-5 relative).
//! - Cantilever (the bar clamped on its face x = 0): beam theory (analytic.md §1,
//!   clamped-free roots) describes only slender bending, and a 3D clamp also stops
//!   the Poisson contraction at the root, so the reference is an independent 3D
//!   solution: scikit-fem P2 tets on structured meshes with 90 and 120 cells
//!   along the bar, Richardson-extrapolated with the P2 rate h⁴ (script and output in
//!   `docs/accuracy/cantilever_reference.py` / `.json`). The same script without the
//!   clamp reproduces the free-free "3D converged" table to ≤ 1e-4 relative for every
//!   family, torsion included (`docs/accuracy/free_bar_check.json`), so that is the
//!   reference's uncertainty. The first two flat-bending modes lie within 0.3 % of
//!   Timoshenko beam theory (see [`timoshenko_cantilever_check`]; the 3D clamp, which
//!   also stops the Poisson contraction at the root, makes the body slightly stiffer).

use std::f64::consts::PI;

/// Young's modulus of the study steel (Pa).
pub const STEEL_E_PA: f64 = 200e9;
/// Poisson's ratio of the study steel.
pub const STEEL_NU: f64 = 0.3;
/// Density of the study steel (kg/m³).
pub const STEEL_RHO: f64 = 7850.0;

/// Bar dimensions (m): length x, width y, thickness z.
pub const BAR_SIZE: [f64; 3] = [0.3, 0.02, 0.01];
/// Sphere radius (m).
pub const SPHERE_RADIUS: f64 = 0.05;

/// The "3D converged" free-free bar frequencies of analytic.md §1 (Hz), ascending.
pub const BAR_FREE_HZ: [f64; 12] = [
    574.27, 1135.11, 1571.96, 3044.17, 3050.84, 3866.33, 4977.96, 5750.86, 7320.56, 7738.85, 8410.84, 9092.97,
];

/// Lamb roots η (ν = 0.3) and multiplicities of the 20 lowest free-sphere modes.
const LAMB_NU_030: [(f64, usize); 4] = [(2.5011, 5), (2.6462, 5), (3.5300, 3), (3.8647, 7)];

/// The 20 lowest elastic frequencies (Hz) of the free steel sphere of radius `radius_m`.
pub fn sphere_lamb_hz(radius_m: f64) -> Vec<f64> {
    let shear = STEEL_E_PA / (2.0 * (1.0 + STEEL_NU));
    let c_t = (shear / STEEL_RHO).sqrt();
    LAMB_NU_030
        .iter()
        .flat_map(|&(eta, mult)| std::iter::repeat_n(eta * c_t / (2.0 * PI * radius_m), mult))
        .collect()
}

/// The 20 lowest cantilever frequencies (Hz), ascending (see the module docs).
pub const CANTILEVER_HZ: [f64; 20] = [
    90.799, 180.933, 566.100, 1111.242, 1572.450, 1946.483, 3018.491, 3046.645, 4212.490, 4965.351, 5680.162,
    5842.808, 7294.057, 8958.579, 9749.110, 9995.772, 12632.343, 12715.425, 13032.561, 13671.721,
];

/// Timoshenko-beam check of the two lowest flat-bending cantilever modes (Hz): the
/// Euler–Bernoulli values `(β_n L)² / (2π L²) √(EI/ρA)` with clamped-free roots
/// 1.875104 and 4.694091, lowered by the first-order shear and rotary-inertia factor
/// `1 − ½ (β_n r)² (1 + E/(κG))`, r² = I/A, κ = 10(1+ν)/(12+11ν) (analytic.md §1).
pub fn timoshenko_cantilever_check() -> [f64; 2] {
    let [l, b, h] = BAR_SIZE;
    let (area, inertia) = (b * h, b * h.powi(3) / 12.0);
    let shear = STEEL_E_PA / (2.0 * (1.0 + STEEL_NU));
    let kappa = 10.0 * (1.0 + STEEL_NU) / (12.0 + 11.0 * STEEL_NU);
    let r2 = inertia / area;
    let stiff = (STEEL_E_PA * inertia / (STEEL_RHO * area)).sqrt();
    [1.875104, 4.694091].map(|bl: f64| {
        let eb = bl * bl / (2.0 * PI * l * l) * stiff;
        let beta2 = (bl / l).powi(2);
        eb * (1.0 - 0.5 * beta2 * r2 * (1.0 + STEEL_E_PA / (kappa * shear)))
    })
}
