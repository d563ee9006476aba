//! Free-free steel bar 0.3 × 0.02 × 0.01 m: first flat-bending mode against
//! the 3D converged 574.27 Hz of `shared/reference/analytic.md`.

use modal_fem::{assemble, prepare_mesh};
use modal_mesh::generate::box_mesh;

use crate::common::{dense, generalized_eigenvalues, hz, steel};

/// First elastic frequency [Hz] of the bar meshed with `cells` hexahedra.
fn first_elastic_hz(cells: [usize; 3], order: u8) -> f64 {
    let mesh = prepare_mesh(&box_mesh([0.3, 0.02, 0.01], cells), order).unwrap();
    let a = assemble(&mesh, &steel()).unwrap();
    let f = hz(&generalized_eigenvalues(&dense(&a.k), &dense(&a.m)));
    assert!(f[..6].iter().all(|&x| x < 1.0), "6 rigid modes expected: {:?}", &f[..7]);
    f[6]
}

#[test]
fn first_flat_bending_mode_tet10_within_1_percent_tet4_stiffer() {
    let cells = [15, 2, 1];
    let p2 = first_elastic_hz(cells, 2);
    let p1 = first_elastic_hz(cells, 1);
    assert!((p2 - 574.27).abs() / 574.27 < 0.01, "TET10 first bending mode {p2} Hz");
    assert!(p1 > 1.05 * 574.27, "TET4 should be visibly stiffer: {p1} Hz");
}
