//! Generator tests: conformity (closed boundary), orientation, volume,
//! quality, boundary nodes on the true surface, curved quadratic meshes.

use std::f64::consts::PI;

use modal_mesh::generate::{generate, Shape, MAX_GENERATED_TETS};
use modal_mesh::{boundary_surface, check, min_dihedral_angle_deg, MeshError, MeshReport, Surface, TetMesh};

fn checked(shape: &Shape, h: f64, order: u8) -> (TetMesh, MeshReport, Surface) {
    let mesh = generate(shape, h, order).unwrap();
    let (mesh, report) = check(mesh).unwrap_or_else(|e| panic!("{shape:?}: {e}"));
    assert_eq!(report.reoriented, 0, "{shape:?}: generator made negative tets");
    assert_eq!(report.unused_nodes_dropped, 0);
    assert_eq!(report.parts, 1);
    let surface = boundary_surface(&mesh);
    assert_eq!(surface.open_edge_count(), 0, "{shape:?}: boundary not closed (non-conforming mesh?)");
    (mesh, report, surface)
}

fn norm(p: [f64; 3]) -> f64 {
    (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt()
}

/// Relative volume error bound of an inscribed faceted mesh with edge
/// length ~h on curvature radius R: about (h/R)^2 / 8.. we allow (h/R)^2/2.
fn assert_volume(report: &MeshReport, exact: f64, h_over_r: f64) {
    let rel = (report.volume - exact) / exact;
    assert!(
        rel <= 1e-12 && rel > -0.5 * h_over_r * h_over_r,
        "volume {} vs {exact} (rel {rel})",
        report.volume
    );
}

#[test]
fn box_matches_its_closed_form() {
    let (_, report, surface) = checked(&Shape::Box { size: [0.3, 0.02, 0.01] }, 0.005, 1);
    assert_eq!(report.tets, 6 * 60 * 4 * 2);
    assert!((report.volume - 6e-5).abs() < 1e-17);
    assert!((surface.area() - 2.0 * (0.3 * 0.02 + 0.02 * 0.01 + 0.01 * 0.3)).abs() < 1e-15);
}

#[test]
fn sphere_is_a_good_ball() {
    let r = 0.05;
    let (mesh, report, surface) = checked(&Shape::Sphere { radius: r }, r / 5.0, 1);
    assert_volume(&report, 4.0 / 3.0 * PI * r.powi(3), 0.2 * 1.5);
    assert!(surface.positions.iter().all(|&p| (norm(p) - r).abs() < 1e-12 * r));
    let angle = min_dihedral_angle_deg(&mesh);
    // Measured 2026-11-22: 19.5 deg at h = R/5 (the O-grid's cube corners).
    assert!(angle > 15.0, "min dihedral angle {angle}");
}

#[test]
fn cylinder_boundary_lies_on_the_cylinder() {
    let (r, l) = (0.02, 0.1);
    let (mesh, report, surface) = checked(&Shape::Cylinder { radius: r, length: l }, 0.005, 1);
    assert_volume(&report, PI * r * r * l, 0.25 * 1.5);
    for p in &surface.positions {
        let on_side = (p[0].hypot(p[1]) - r).abs() < 1e-12 * r;
        let on_cap = p[2].abs() < 1e-15 || (p[2] - l).abs() < 1e-15;
        assert!(on_side || on_cap, "{p:?}");
    }
    let angle = min_dihedral_angle_deg(&mesh);
    assert!(angle > 15.0, "min dihedral angle {angle}");
}

#[test]
fn tube_is_closed_across_the_seam() {
    let (ri, ro, l) = (0.015, 0.02, 0.05);
    let (mesh, report, surface) =
        checked(&Shape::Tube { inner_radius: ri, outer_radius: ro, length: l }, 0.004, 1);
    assert_volume(&report, PI * (ro * ro - ri * ri) * l, 0.004 / ri);
    for p in &surface.positions {
        let rho = p[0].hypot(p[1]);
        let on_wall = (rho - ri).abs() < 1e-12 || (rho - ro).abs() < 1e-12;
        assert!(on_wall || p[2].abs() < 1e-15 || (p[2] - l).abs() < 1e-15, "{p:?}");
    }
    assert!(min_dihedral_angle_deg(&mesh) > 15.0);
}

#[test]
fn bowl_is_a_hemispherical_shell() {
    let (r, t) = (0.1, 0.01);
    let (mesh, report, surface) = checked(&Shape::Bowl { radius: r, thickness: t }, 0.01, 1);
    let exact = 2.0 / 3.0 * PI * (r.powi(3) - (r - t).powi(3));
    assert_volume(&report, exact, 0.01 / (r - t) * 1.5);
    for p in &surface.positions {
        let d = norm(*p);
        let on_shell = (d - r).abs() < 1e-12 || (d - (r - t)).abs() < 1e-12;
        assert!(on_shell || p[2].abs() < 1e-15, "{p:?}");
        assert!(p[2] <= 1e-15);
    }
    assert!(min_dihedral_angle_deg(&mesh) > 10.0, "{}", min_dihedral_angle_deg(&mesh));
}

#[test]
fn quadratic_curved_meshes_put_edge_nodes_on_the_surface() {
    let r = 0.05;
    let (_, _, surface) = checked(&Shape::Sphere { radius: r }, r / 3.0, 2);
    let edges = surface.triangle_edge_nodes.as_ref().unwrap();
    assert!(edges.iter().flatten().all(|&k| (norm(surface.positions[k]) - r).abs() < 1e-12 * r));
    let (_, _, tube) =
        checked(&Shape::Tube { inner_radius: 0.01, outer_radius: 0.02, length: 0.02 }, 0.005, 2);
    for &k in tube.triangle_edge_nodes.as_ref().unwrap().iter().flatten() {
        let p = tube.positions[k];
        let rho = p[0].hypot(p[1]);
        assert!(
            (rho - 0.01).abs() < 1e-12
                || (rho - 0.02).abs() < 1e-12
                || p[2].abs() < 1e-15
                || (p[2] - 0.02).abs() < 1e-15
        );
    }
    checked(&Shape::Cylinder { radius: 0.01, length: 0.03 }, 0.005, 2);
    checked(&Shape::Bowl { radius: 0.1, thickness: 0.02 }, 0.02, 2);
    checked(&Shape::Box { size: [0.1, 0.02, 0.01] }, 0.01, 2);
}

#[test]
fn refinement_converges_to_the_ball_volume() {
    // Faceting error ∝ h²: halving h cuts it by about four.
    let r = 1.0;
    let exact = 4.0 / 3.0 * PI;
    let err = |h: f64| exact - check(generate(&Shape::Sphere { radius: r }, h, 1).unwrap()).unwrap().1.volume;
    let (coarse, fine) = (err(0.4), err(0.2));
    assert!(coarse > 0.0 && fine > 0.0);
    assert!(coarse / fine > 3.0 && coarse / fine < 5.0, "{coarse} / {fine}");
}

#[test]
fn bad_parameters_are_rejected() {
    let bad = [
        (Shape::Sphere { radius: -1.0 }, 0.1, 1, "radius"),
        (Shape::Sphere { radius: f64::NAN }, 0.1, 1, "radius"),
        (Shape::Sphere { radius: 1.0 }, 0.0, 1, "h"),
        (Shape::Sphere { radius: 1.0 }, f64::INFINITY, 1, "h"),
        (Shape::Sphere { radius: 1.0 }, 0.5, 3, "order"),
        (Shape::Box { size: [1.0, 0.0, 1.0] }, 0.5, 1, "size y"),
        (Shape::Cylinder { radius: 1.0, length: -2.0 }, 0.5, 1, "length"),
        (Shape::Tube { inner_radius: 2.0, outer_radius: 1.0, length: 1.0 }, 0.5, 1, "inner_radius"),
        (Shape::Tube { inner_radius: 1.0, outer_radius: 1.0, length: 1.0 }, 0.5, 1, "inner_radius"),
        (Shape::Bowl { radius: 1.0, thickness: 1.0 }, 0.5, 1, "thickness"),
    ];
    for (shape, h, order, name) in bad.iter().cloned() {
        match generate(&shape, h, order) {
            Err(MeshError::InvalidParameter { name: got, .. }) => assert_eq!(got, name, "{shape:?}"),
            other => panic!("{shape:?}: {other:?}"),
        }
    }
    for shape in [
        Shape::Sphere { radius: 1.0 },
        Shape::Box { size: [1.0; 3] },
        Shape::Cylinder { radius: 1.0, length: 1.0 },
    ] {
        let err = generate(&shape, 1e-6, 1).unwrap_err();
        assert!(matches!(err, MeshError::TooManyElements { limit: MAX_GENERATED_TETS, .. }), "{err}");
    }
}

#[test]
fn curved_quadratic_sphere_has_nearly_the_exact_volume() {
    // Faceted P1 loses O(h²) of the volume; curved P2 boundaries O(h⁴).
    let r: f64 = 0.05;
    let exact = 4.0 / 3.0 * PI * r.powi(3);
    let p1 = modal_mesh::mesh_volume(&generate(&Shape::Sphere { radius: r }, r / 3.0, 1).unwrap());
    let p2_mesh = generate(&Shape::Sphere { radius: r }, r / 3.0, 2).unwrap();
    let p2 = modal_mesh::mesh_volume(&p2_mesh);
    let straight = modal_mesh::mesh_volume(&modal_mesh::to_quadratic(&modal_mesh::to_linear(&p2_mesh)));
    let (e1, e2) = ((exact - p1) / exact, (exact - p2).abs() / exact);
    assert!((straight - p1).abs() < 1e-12 * exact, "straight P2 volume must equal P1");
    assert!(e1 > 0.01, "P1 error {e1}");
    // Measured 2026-11-22 at h = R/3: P1 3.28e-2, curved P2 1.99e-4.
    assert!(e2 < 0.01 * e1, "P2 error {e2} vs P1 error {e1}");
}

#[test]
fn curved_quadratic_volumes_match_every_shape() {
    // Curved P2 meshes reproduce the exact volume far better than P1.
    let shapes = [
        (Shape::Cylinder { radius: 0.02, length: 0.05 }, 0.006),
        (Shape::Tube { inner_radius: 0.015, outer_radius: 0.02, length: 0.03 }, 0.005),
        (Shape::Bowl { radius: 0.1, thickness: 0.01 }, 0.015),
    ];
    for (shape, h) in shapes {
        let exact = shape.volume();
        let p1 = modal_mesh::mesh_volume(&generate(&shape, h, 1).unwrap());
        let p2 = modal_mesh::mesh_volume(&generate(&shape, h, 2).unwrap());
        let (e1, e2) = ((exact - p1) / exact, ((exact - p2) / exact).abs());
        assert!(e1 > 0.0 && e2 < 0.05 * e1, "{shape:?}: P1 {e1:e}, P2 {e2:e}");
    }
}
