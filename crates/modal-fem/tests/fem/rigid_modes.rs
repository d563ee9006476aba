//! Rigid-body fields are in the null space of K; dense eigen solves show
//! exactly 6 zero modes per connected part (issue 2 acceptance).

use modal_fem::{assemble, node_parts, prepare_mesh, rigid_body_fields};
use modal_mesh::generate::box_mesh;

use crate::common::{dense, generalized_eigenvalues, jiggle_interior, mul, steel, translated, union};

#[test]
fn k_annihilates_rigid_fields() {
    for order in [1, 2] {
        let mut mesh = box_mesh([0.3, 0.02, 0.01], [6, 2, 2]);
        jiggle_interior(&mut mesh, [0.3, 0.02, 0.01], 0.005);
        let mesh = prepare_mesh(&mesh, order).unwrap();
        let a = assemble(&mesh, &steel()).unwrap();
        let (parts, n_parts) = node_parts(&mesh);
        assert_eq!(n_parts, 1);
        let fields = rigid_body_fields(&mesh.nodes, &parts, n_parts, &[]);
        assert_eq!(fields.ncols(), 6);
        let k_norm = a.k.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for j in 0..6 {
            let f: Vec<f64> = (0..fields.nrows()).map(|i| fields[(i, j)]).collect();
            let f_norm = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let kf = mul(&a.k, &f);
            let r = kf.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(r <= 1e-10 * k_norm * f_norm, "order {order}, field {j}: |Kf| = {r:e}");
        }
    }
}

/// Counts eigenvalues below 1e-8 of the largest; asserts the rest positive.
fn zero_mode_count(mesh: &modal_mesh::TetMesh) -> usize {
    let a = assemble(mesh, &steel()).unwrap();
    let lambda = generalized_eigenvalues(&dense(&a.k), &dense(&a.m));
    let max = lambda.last().copied().unwrap();
    let zeros = lambda.iter().filter(|l| l.abs() < 1e-8 * max).count();
    assert!(lambda[zeros..].iter().all(|&l| l > 1e-8 * max), "negative or tiny eigenvalue");
    zeros
}

#[test]
fn six_zero_modes_per_connected_part() {
    for order in [1, 2] {
        let one = box_mesh([0.1, 0.05, 0.04], [2, 1, 1]);
        let two = union(&one, &translated(&one, [0.2, 0.0, 0.0]));
        let one = prepare_mesh(&one, order).unwrap();
        let two = prepare_mesh(&two, order).unwrap();
        assert_eq!(node_parts(&two).1, 2);
        assert_eq!(zero_mode_count(&one), 6, "order {order}, one box");
        assert_eq!(zero_mode_count(&two), 12, "order {order}, two boxes");
    }
}
