//! Cross-checks with the independent scikit-fem reference on committed Gmsh
//! meshes (issue 2 acceptance), and the Gmsh 10-node ordering.
//!
//! Reference values were produced by (E = 200 GPa, ν = 0.3, ρ = 7850):
//! ```text
//! /work/.venv-ref/bin/python shared/tools/reference_modes.py meshes/bar_p1.msh \
//!     --order 1 --modes 12 --E 200e9 --nu 0.3 --rho 7850      # 768 DOF
//! /work/.venv-ref/bin/python shared/tools/reference_modes.py meshes/bar_p1.msh \
//!     --order 2 --modes 12 --E 200e9 --nu 0.3 --rho 7850      # 4149 DOF
//! ```
//! (scikit-fem P1/P2 tets, consistent mass, ARPACK shift-invert); the six
//! rigid modes it prints (≈1e-3 Hz) are omitted below.

use std::collections::HashMap;
use std::path::PathBuf;

use modal_fem::{assemble, prepare_mesh};
use modal_mesh::{read_mesh, TetMesh};

use crate::common::{assert_close, hz, lowest_eigenvalues, steel};

const P1_REFERENCE_HZ: [f64; 12] = [
    1007.2099602584342,
    1534.563651572388,
    2797.8089675289953,
    4117.892725496074,
    5383.189991135931,
    7712.653895616837,
    8414.137716065632,
    8493.937440132535,
    8717.897759134083,
    12029.502441426675,
    12635.697306416543,
    16695.774397861103,
];

const P2_REFERENCE_HZ: [f64; 12] = [
    574.4780346908829,
    1135.2858614083805,
    1573.9977572461848,
    3045.830868218998,
    3059.037573896931,
    4003.824102320651,
    5001.671119375016,
    5757.453692730367,
    7371.176929990669,
    8022.399237067743,
    8410.840567817646,
    9110.840864151056,
];

fn committed_mesh(name: &str) -> TetMesh {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../meshes").join(name);
    read_mesh(&path, 1.0).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn lowest_hz(mesh: &TetMesh, count: usize) -> Vec<f64> {
    let a = assemble(mesh, &steel()).unwrap();
    hz(&lowest_eigenvalues(&a.k, &a.m, count))
}

fn check_against_reference(order: u8, reference: &[f64; 12]) {
    let mesh = prepare_mesh(&committed_mesh("bar_p1.msh"), order).unwrap();
    let f = lowest_hz(&mesh, 18);
    assert!(f[..6].iter().all(|&x| x < 1.0), "6 rigid modes expected: {:?}", &f[..7]);
    for (i, (got, want)) in f[6..].iter().zip(reference).enumerate() {
        assert_close(*got, *want, 1e-6, &format!("P{order} elastic mode {}", i + 1));
    }
}

#[test]
fn p1_frequencies_match_independent_reference() {
    check_against_reference(1, &P1_REFERENCE_HZ);
}

#[test]
fn p2_promoted_frequencies_match_independent_reference() {
    check_against_reference(2, &P2_REFERENCE_HZ);
}

/// Node coordinates rounded to 1e-9 m, as a lookup key.
fn key(p: [f64; 3]) -> [i64; 3] {
    p.map(|x| (x * 1e9).round() as i64)
}

#[test]
fn gmsh_order2_mesh_equals_promoted_order1_mesh() {
    let gmsh_p2 = committed_mesh("bar_p2.msh");
    let promoted = prepare_mesh(&committed_mesh("bar_p1.msh"), 2).unwrap();
    assert_eq!(gmsh_p2.order(), 2);
    assert_eq!(gmsh_p2.node_count(), promoted.node_count());
    // Node permutation by position: gmsh node i is promoted node perm[i].
    let index: HashMap<[i64; 3], usize> =
        promoted.nodes.iter().enumerate().map(|(i, &p)| (key(p), i)).collect();
    let perm: Vec<usize> = gmsh_p2.nodes.iter().map(|&p| index[&key(p)]).collect();
    let a = assemble(&gmsh_p2, &steel()).unwrap();
    let b = assemble(&promoted, &steel()).unwrap();
    for (x, y, what) in [(&a.k, &b.k, "K"), (&a.m, &b.m, "M")] {
        let y_dense = y.to_dense();
        let scale = y.val().iter().fold(0.0f64, |s, v| s.max(v.abs()));
        let (s, v) = x.parts();
        assert_eq!(x.val().len(), y.val().len(), "{what}: different sparsity patterns");
        for j in 0..x.ncols() {
            for p in s.col_ptr()[j]..s.col_ptr()[j + 1] {
                let i = s.row_idx()[p];
                let (pi, pj) = (3 * perm[i / 3] + i % 3, 3 * perm[j / 3] + j % 3);
                let diff = (v[p] - y_dense[(pi, pj)]).abs();
                assert!(diff <= 1e-10 * scale, "{what}[{i}, {j}] differs by {diff:e} (scale {scale:e})");
            }
        }
    }
    // And the spectra (lowest 18 modes) agree.
    let fa = lowest_hz(&gmsh_p2, 18);
    let fb = lowest_hz(&promoted, 18);
    for (x, y) in fa[6..].iter().zip(&fb[6..]) {
        assert_close(*x, *y, 1e-10, "Gmsh P2 vs promoted P1 frequency");
    }
}
