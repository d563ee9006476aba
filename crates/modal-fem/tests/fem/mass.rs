//! Mass properties of a box against the closed form (issue 2 acceptance).

use modal_fem::{element::is_straight, mass_properties, prepare_mesh};
use modal_mesh::generate::box_mesh;

use crate::common::{assert_close, jiggle_interior, translated};

/// Box `a × b × c` with its corner at `origin`: mass ρabc, centre at the
/// middle, inertia diag(m(b² + c²)/12, m(a² + c²)/12, m(a² + b²)/12).
fn check_box(order: u8, jiggle: bool) {
    let (a, b, c) = (0.3, 0.02, 0.01);
    let rho = 7850.0;
    let mut mesh = box_mesh([a, b, c], [6, 3, 2]);
    if jiggle {
        jiggle_interior(&mut mesh, [a, b, c], 0.005);
    }
    let origin = [1.5, -2.0, 0.25];
    let mesh = prepare_mesh(&translated(&mesh, origin), order).unwrap();
    let p = mass_properties(&mesh, rho);
    let m = rho * a * b * c;
    assert_close(p.volume_m3, a * b * c, 1e-12, "volume");
    assert_close(p.mass_kg, m, 1e-12, "mass");
    let centre = [origin[0] + a / 2.0, origin[1] + b / 2.0, origin[2] + c / 2.0];
    for k in 0..3 {
        assert_close(p.center_of_mass_m[k], centre[k], 1e-12, "centre of mass");
    }
    let diag = [m * (b * b + c * c) / 12.0, m * (a * a + c * c) / 12.0, m * (a * a + b * b) / 12.0];
    let scale = diag[1];
    for i in 0..3 {
        assert_close(p.inertia_kg_m2[i][i], diag[i], 1e-12, "principal inertia");
        for j in 0..3 {
            if i != j {
                assert!(p.inertia_kg_m2[i][j].abs() <= 1e-12 * scale, "product of inertia {i}{j}");
                assert_eq!(p.inertia_kg_m2[i][j], p.inertia_kg_m2[j][i]);
            }
        }
    }
}

#[test]
fn box_mass_and_inertia_tet4() {
    check_box(1, false);
    check_box(1, true);
}

#[test]
fn box_mass_and_inertia_tet10() {
    check_box(2, false);
    check_box(2, true);
}

#[test]
fn curved_tet10_mass_properties_are_exact() {
    // A unit cube mapped by x ↦ x + ε·bubble moves mid-edge nodes of
    // interior edges off the straight edges; the volume integral stays
    // the cube's because the boundary is untouched. The map is
    // quadratic, so degree-7 integration must be exact.
    let mut mesh = prepare_mesh(&box_mesh([1.0, 1.0, 1.0], [2, 2, 2]), 2).unwrap();
    for p in &mut mesh.nodes {
        let interior = (0..3).all(|c| p[c] > 1e-9 && p[c] < 1.0 - 1e-9);
        if interior {
            p[0] += 0.05 * (p[1] - 0.5);
            p[2] += 0.03;
        }
    }
    let curved = (0..mesh.cells.len())
        .filter(|&e| !is_straight(&mesh.cells.nodes_of(e).iter().map(|&n| mesh.nodes[n]).collect::<Vec<_>>()))
        .count();
    assert!(curved > 0, "the test mesh must have curved elements");
    let props = mass_properties(&mesh, 2.0);
    assert_close(props.volume_m3, 1.0, 1e-13, "curved volume");
    assert_close(props.mass_kg, 2.0, 1e-13, "curved mass");
}
