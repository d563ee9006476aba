//! Patch tests (issue 2 acceptance): fields the element space contains are
//! reproduced exactly. A linear displacement gives the exact strain energy
//! with TET4 and TET10; a quadratic displacement gives the exact strain
//! energy and kinetic norm `uᵀMu = ρ∫|u|²` with (straight) TET10. The exact
//! integrals come from a tensor 4-point Gauss–Legendre rule on the box
//! (exact to degree 7 per axis), independent of the tets.

use modal_fem::{assemble, prepare_mesh, Lame};
use modal_mesh::generate::box_mesh;

use crate::common::{dot, jiggle_interior, mul, steel};

const SIZE: [f64; 3] = [0.3, 0.2, 0.1];

/// A displacement field: `u(x)` and its gradient `∂uᵢ/∂xⱼ`.
struct Field {
    u: fn([f64; 3]) -> [f64; 3],
    grad: fn([f64; 3]) -> [[f64; 3]; 3],
}

const LINEAR: Field = Field {
    u: |x| {
        [
            1e-3 + 2e-3 * x[0] - 1e-3 * x[1] + 4e-3 * x[2],
            -2e-3 + 0.5e-3 * x[0] + 3e-3 * x[1] - 2e-3 * x[2],
            3e-3 - 1.5e-3 * x[0] + 2.5e-3 * x[1] + 1e-3 * x[2],
        ]
    },
    grad: |_| [[2e-3, -1e-3, 4e-3], [0.5e-3, 3e-3, -2e-3], [-1.5e-3, 2.5e-3, 1e-3]],
};

const QUADRATIC: Field = Field {
    u: |x| {
        [
            1e-3 * x[0] * x[0] - 2e-3 * x[1] * x[2] + 1e-3 * x[1],
            3e-3 * x[0] * x[1] + 1e-3 * x[2] * x[2] - 2e-3,
            -1e-3 * x[1] * x[1] + 2e-3 * x[0] * x[2] + 5e-4 * x[0],
        ]
    },
    grad: |x| {
        [
            [2e-3 * x[0], -2e-3 * x[2] + 1e-3, -2e-3 * x[1]],
            [3e-3 * x[1], 3e-3 * x[0], 2e-3 * x[2]],
            [2e-3 * x[2] + 5e-4, -2e-3 * x[1], 2e-3 * x[0]],
        ]
    },
};

/// `∫_box f dV` by 4-point Gauss–Legendre per axis.
fn box_integral(f: impl Fn([f64; 3]) -> f64) -> f64 {
    let (a, b) = (0.339_981_043_584_856_3, 0.861_136_311_594_052_6);
    let (wa, wb) = (0.652_145_154_862_546_1, 0.347_854_845_137_453_9);
    let gl = [(-b, wb), (-a, wa), (a, wa), (b, wb)];
    let mut sum = 0.0;
    for (s, ws) in gl {
        for (t, wt) in gl {
            for (r, wr) in gl {
                let x = [SIZE[0] * (s + 1.0) / 2.0, SIZE[1] * (t + 1.0) / 2.0, SIZE[2] * (r + 1.0) / 2.0];
                sum += ws * wt * wr * f(x);
            }
        }
    }
    sum * SIZE[0] * SIZE[1] * SIZE[2] / 8.0
}

/// Strain energy density `½(λ (tr ε)² + 2μ ε:ε)`.
fn energy_density(g: [[f64; 3]; 3], lame: Lame) -> f64 {
    let eps = |i: usize, j: usize| 0.5 * (g[i][j] + g[j][i]);
    let tr = eps(0, 0) + eps(1, 1) + eps(2, 2);
    let mut ee = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            ee += eps(i, j) * eps(i, j);
        }
    }
    0.5 * (lame.lambda * tr * tr + 2.0 * lame.mu * ee)
}

/// Relative errors of `½uᵀKu` and `uᵀMu` against the exact integrals.
fn relative_errors(order: u8, field: &Field) -> (f64, f64) {
    let mut mesh = box_mesh(SIZE, [3, 3, 3]);
    jiggle_interior(&mut mesh, SIZE, 0.1);
    let mesh = prepare_mesh(&mesh, order).unwrap();
    let material = steel();
    let a = assemble(&mesh, &material).unwrap();
    let u: Vec<f64> = mesh.nodes.iter().flat_map(|&x| (field.u)(x)).collect();
    let lame = material.lame();
    let exact_energy = box_integral(|x| energy_density((field.grad)(x), lame));
    let energy = 0.5 * dot(&u, &mul(&a.k, &u));
    let rho = material.density_kg_m3;
    let exact_kinetic = box_integral(|x| rho * (field.u)(x).iter().map(|v| v * v).sum::<f64>());
    let kinetic = dot(&u, &mul(&a.m, &u));
    ((energy - exact_energy).abs() / exact_energy, (kinetic - exact_kinetic).abs() / exact_kinetic)
}

#[track_caller]
fn assert_exact(order: u8, field: &Field) {
    let (energy, kinetic) = relative_errors(order, field);
    assert!(energy < 1e-12, "order {order}: strain energy relative error {energy:e}");
    assert!(kinetic < 1e-12, "order {order}: uᵀMu relative error {kinetic:e}");
}

#[test]
fn linear_field_gives_exact_strain_energy_tet4() {
    assert_exact(1, &LINEAR);
}

#[test]
fn linear_field_gives_exact_strain_energy_tet10() {
    assert_exact(2, &LINEAR);
}

#[test]
fn quadratic_field_is_reproduced_exactly_by_tet10() {
    assert_exact(2, &QUADRATIC);
}

#[test]
fn quadratic_field_is_not_exact_with_tet4() {
    // Guards the test itself: TET4 cannot represent the quadratic field.
    let (energy, _) = relative_errors(1, &QUADRATIC);
    assert!(
        energy > 1e-4,
        "TET4 reproduced a quadratic field (error {energy:e}): the patch test is not discriminating"
    );
}
