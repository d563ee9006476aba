//! The dihedral-angle bound [9°, 166°] on many shape × rotation × cell-size
//! combinations (the stencil diagonal rule differs from the paper's parity
//! rule, so the bound is checked empirically here).

mod common;

use common::assert_good;
use modal_tetra::{shapes, tetrahedralize, TetOptions, TriSurface};

fn rotate(s: &mut TriSurface, angles: [f64; 3]) {
    let (a, b, c) = (angles[0], angles[1], angles[2]);
    for p in &mut s.vertices {
        let [x, y, z] = *p;
        let (y, z) = (y * a.cos() - z * a.sin(), y * a.sin() + z * a.cos());
        let (x, z) = (x * b.cos() + z * b.sin(), -x * b.sin() + z * b.cos());
        let (x, y) = (x * c.cos() - y * c.sin(), x * c.sin() + y * c.cos());
        *p = [x, y, z];
    }
}

fn corpus() -> Vec<TriSurface> {
    vec![
        shapes::icosphere(0.05, 3),
        shapes::torus(0.05, 0.02, 48, 16),
        shapes::cuboid(0.1, 0.06, 0.03),
        shapes::bowl(0.08, 0.008, 32),
        shapes::bell(0.15, 0.08, 0.01, 32),
        shapes::mug(0.04, 0.1, 0.006, 32),
    ]
}

fn run(cases: usize, cells: std::ops::Range<f64>) {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let shapes = corpus();
    for k in 0..cases {
        let mut s = shapes[k % shapes.len()].clone();
        rotate(&mut s, [6.3 * next(), 6.3 * next(), 6.3 * next()]);
        let cpd = cells.start + (cells.end - cells.start) * next();
        let options = TetOptions { cells_per_diagonal: cpd, cells_per_thickness: 0.5, ..Default::default() };
        let (m, r) = tetrahedralize(&s, &options).expect("meshes");
        assert_good(&m, &r);
    }
}

#[test]
fn dihedral_bounds_hold_on_rotated_shapes_and_varied_cells() {
    run(12, 8.0..18.0);
}

#[test]
#[ignore = "long quality sweep (minutes)"]
fn dihedral_bounds_sweep() {
    run(300, 8.0..40.0);
}

/// A dense scan's noise is not a sharp feature. An 81 920-triangle sphere
/// (edges ≈ 0.8 mm) with up to 0.5 % radial noise has thousands of edges
/// sharper than the feature angle; snapping boundary nodes onto them moved
/// the nodes off the surface and flattened tets down to the snap guard.
#[test]
fn the_noise_of_a_dense_scan_is_not_snapped_to() {
    let mut s = shapes::icosphere(0.05, 6);
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    for p in &mut s.vertices {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let bump = 1.0 + 0.005 * (2.0 * (state >> 11) as f64 / (1u64 << 53) as f64 - 1.0);
        *p = p.map(|c| c * bump);
    }
    let (mesh, report) = tetrahedralize(&s, &TetOptions::default()).expect("meshes");
    assert_good(&mesh, &report);
    // Unsnapped, the boundary nodes stay on the surface and the tets far from the guard.
    assert!(report.max_surface_deviation_m < 1e-9, "{} m off the surface", report.max_surface_deviation_m);
    assert!(report.min_dihedral_deg > 15.0, "{}°", report.min_dihedral_deg);
}
