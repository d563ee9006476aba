//! Tests of `check`, `connected_parts` and `boundary_surface`.

use modal_mesh::generate::box_mesh;
use modal_mesh::{
    boundary_surface, check, connected_parts, to_quadratic, Cells, MeshError, TetMesh, TET10_EDGES,
};

fn unit_tet(tet: [usize; 4]) -> TetMesh {
    TetMesh {
        nodes: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        cells: Cells::Tet4(vec![tet]),
        groups: Vec::new(),
    }
}

fn assert_midpoints(mesh: &TetMesh) {
    let Cells::Tet10(tets) = &mesh.cells else { panic!("not quadratic") };
    for t in tets {
        for (e, [a, b]) in TET10_EDGES.iter().enumerate() {
            let (p, q, m) = (mesh.nodes[t[*a]], mesh.nodes[t[*b]], mesh.nodes[t[4 + e]]);
            assert!((0..3).all(|c| (m[c] - 0.5 * (p[c] + q[c])).abs() < 1e-14), "edge {e} of {t:?}");
        }
    }
}

#[test]
fn negative_tet4_is_reoriented_and_counted() {
    let (mesh, report) = check(unit_tet([0, 2, 1, 3])).unwrap();
    assert_eq!(report.reoriented, 1);
    assert_eq!(report.warnings.len(), 1);
    assert!((report.volume - 1.0 / 6.0).abs() < 1e-15);
    let (again, report2) = check(mesh).unwrap();
    assert_eq!(report2.reoriented, 0);
    assert!((report2.volume - 1.0 / 6.0).abs() < 1e-15);
    assert_eq!(again.cells.len(), 1);
}

#[test]
fn negative_tet10_keeps_mid_edge_nodes_on_their_edges() {
    // Promote a negatively oriented box mesh: its mid-edge nodes are right
    // for the (negative) corner order; after reorientation they must still
    // sit on the edges TET10_EDGES names.
    let mut linear = box_mesh([1.0, 2.0, 3.0], [2, 1, 1]);
    if let Cells::Tet4(t) = &mut linear.cells {
        t.iter_mut().for_each(|t| t.swap(0, 3));
    }
    let (mesh, report) = check(to_quadratic(&linear)).unwrap();
    assert_eq!(report.reoriented, 12);
    assert!((report.volume - 6.0).abs() < 1e-12);
    assert_midpoints(&mesh);
}

#[test]
fn bad_meshes_name_the_element_or_node() {
    let mut nan = unit_tet([0, 1, 2, 3]);
    nan.nodes[2][1] = f64::NAN;
    assert!(matches!(check(nan), Err(MeshError::NonFiniteCoordinate { node: 2, .. })));

    let out_of_range = unit_tet([0, 1, 2, 4]);
    assert_eq!(check(out_of_range), Err(MeshError::NodeOutOfRange { element: 0, node: 4, node_count: 4 }));

    let repeated = unit_tet([0, 1, 1, 3]);
    assert_eq!(check(repeated), Err(MeshError::RepeatedNode { element: 0, node: 1 }));

    let mut duplicate = unit_tet([0, 1, 2, 3]);
    duplicate.cells = Cells::Tet4(vec![[0, 1, 2, 3], [3, 2, 1, 0]]);
    assert_eq!(check(duplicate), Err(MeshError::DuplicateTet { element: 1, first: 0 }));

    let mut flat = unit_tet([0, 1, 2, 3]);
    flat.nodes[3] = [0.3, 0.3, 0.0];
    let err = check(flat).unwrap_err();
    assert!(matches!(err, MeshError::DegenerateTet { element: 0, .. }), "{err}");
    assert!(err.to_string().starts_with("element 0 is degenerate"), "{err}");

    let empty = TetMesh { nodes: vec![], cells: Cells::Tet4(vec![]), groups: vec![] };
    assert_eq!(check(empty), Err(MeshError::NoTets));
}

#[test]
fn nearly_flat_but_valid_tet_passes() {
    // V / l^3 ~ 1e-7: a terrible sliver but not degenerate by our rule.
    let mut sliver = unit_tet([0, 1, 2, 3]);
    sliver.nodes[3] = [0.3, 0.3, 6e-7];
    let (_, report) = check(sliver).unwrap();
    assert_eq!(report.slivers, 1);
    assert!(report.min_dihedral_deg < 1e-3);
    assert!(
        report.warnings.iter().any(|w| w.contains("dihedral angle below 5 degrees")),
        "{:?}",
        report.warnings
    );
    let (_, regular) = check(unit_tet([0, 1, 2, 3])).unwrap();
    // The corner tet of a cube has dihedral angles 90°, 90°, 90°, 60°, 60°, 54.7°.
    assert_eq!(regular.slivers, 0);
    assert!((regular.min_dihedral_deg - (1.0f64 / 3.0f64.sqrt()).acos().to_degrees()).abs() < 1e-9);
}

#[test]
fn curved_tet10_inverted_inside_is_an_error() {
    let mut mesh = to_quadratic(&unit_tet([0, 1, 2, 3]));
    // Mid-edge node of edge (0,1) pushed past the opposite corner's side:
    // det J changes sign near corner 0.
    let Cells::Tet10(t) = &mesh.cells else { unreachable!() };
    let m01 = t[0][4];
    mesh.nodes[m01] = [0.9, 0.0, 0.0];
    let err = check(mesh.clone()).unwrap_err();
    assert!(matches!(err, MeshError::InvertedTet10 { element: 0, .. }), "{err}");
    // A moderate curve (edge node moved sideways by 10 % of the edge) is fine.
    mesh.nodes[m01] = [0.5, -0.1, 0.0];
    assert!(check(mesh).is_ok());
}

#[test]
fn unused_nodes_are_dropped_and_parts_counted() {
    let mut a = box_mesh([1.0, 1.0, 1.0], [1, 1, 1]);
    let b = box_mesh([1.0, 1.0, 1.0], [1, 1, 1]);
    let offset = a.nodes.len() + 1; // one unused node between the parts
    a.nodes.push([9.0, 9.0, 9.0]);
    a.nodes.extend(b.nodes.iter().map(|p| [p[0] + 5.0, p[1], p[2]]));
    if let (Cells::Tet4(ta), Cells::Tet4(tb)) = (&mut a.cells, &b.cells) {
        ta.extend(tb.iter().map(|t| t.map(|n| n + offset)));
    }
    let (count, ids) = connected_parts(&a);
    assert_eq!(count, 2);
    assert_eq!(ids[8], usize::MAX);
    assert!(ids[..8].iter().all(|&p| p == 0) && ids[9..].iter().all(|&p| p == 1));
    let (mesh, report) = check(a).unwrap();
    assert_eq!((report.unused_nodes_dropped, report.parts, report.nodes), (1, 2, 16));
    assert!(mesh.nodes.iter().all(|p| p[0] < 8.0));
    assert!((report.volume - 2.0).abs() < 1e-12);
    assert_eq!(connected_parts(&mesh).1, [vec![0; 8], vec![1; 8]].concat());
}

/// Σ over faces of centroid · area vector = ∫ x · n dA = 3 V (divergence
/// theorem for the field x).
fn flux_of_position(surface: &modal_mesh::Surface) -> f64 {
    (0..surface.triangles.len())
        .map(|t| {
            let tri = surface.triangles[t].map(|k| surface.positions[k]);
            let centroid = [0, 1, 2].map(|c| (tri[0][c] + tri[1][c] + tri[2][c]) / 3.0);
            let n = surface.area_vector(t);
            (0..3).map(|c| centroid[c] * n[c]).sum::<f64>()
        })
        .sum()
}

#[test]
fn box_surface_area_orientation_and_closedness() {
    let (a, b, c) = (0.3, 0.02, 0.01);
    let (mesh, _) = check(box_mesh([a, b, c], [6, 2, 1])).unwrap();
    let s = boundary_surface(&mesh);
    assert_eq!(s.triangles.len(), 2 * 2 * (6 * 2 + 2 + 6));
    assert!((s.area() - 2.0 * (a * b + b * c + c * a)).abs() < 1e-15);
    assert!((flux_of_position(&s) - 3.0 * a * b * c).abs() < 1e-16, "{}", flux_of_position(&s));
    assert_eq!(s.open_edge_count(), 0);
    assert_eq!(s.triangle_edge_nodes, None);
    assert_eq!(s.bounding_box(), ([0.0; 3], [a, b, c]));
    for (k, &n) in s.node_ids.iter().enumerate() {
        assert_eq!(s.positions[k], mesh.nodes[n]);
    }
}

#[test]
fn a_sealed_cavity_is_not_surface() {
    // A unit cube of 3 × 3 × 3 cells with the middle cell's tets taken out:
    // a hollow box. The cavity's walls face into it (negative enclosed
    // volume); no sound leaves it, so only the outside is surface.
    let (full, _) = check(box_mesh([1.0, 1.0, 1.0], [3, 3, 3])).unwrap();
    let Cells::Tet4(tets) = &full.cells else { panic!("linear box") };
    let middle = |t: &[usize; 4]| {
        let c: Vec<f64> = (0..3).map(|k| t.iter().map(|&n| full.nodes[n][k]).sum::<f64>() / 4.0).collect();
        c.iter().all(|&x| x > 1.0 / 3.0 && x < 2.0 / 3.0)
    };
    let kept: Vec<[usize; 4]> = tets.iter().filter(|t| !middle(t)).copied().collect();
    assert!(kept.len() < tets.len(), "the middle cell has tets");
    let hollow = TetMesh { nodes: full.nodes.clone(), cells: Cells::Tet4(kept), groups: Vec::new() };
    let (hollow, _) = check(hollow).unwrap();
    let s = boundary_surface(&hollow);
    assert_eq!(s.triangles.len(), boundary_surface(&full).triangles.len());
    assert!((s.area() - 6.0).abs() < 1e-12, "{}", s.area());
    assert!((flux_of_position(&s) - 3.0).abs() < 1e-12, "the box's volume, cavity included");
    assert_eq!(s.open_edge_count(), 0);
}

#[test]
fn quadratic_surface_carries_mid_edge_nodes() {
    let (mesh, _) = check(to_quadratic(&box_mesh([1.0, 1.0, 1.0], [2, 2, 2]))).unwrap();
    let s = boundary_surface(&mesh);
    let edges = s.triangle_edge_nodes.as_ref().unwrap();
    assert_eq!(edges.len(), s.triangles.len());
    for (tri, mids) in s.triangles.iter().zip(edges) {
        for i in 0..3 {
            let (p, q, m) = (s.positions[tri[i]], s.positions[tri[(i + 1) % 3]], s.positions[mids[i]]);
            assert!((0..3).all(|c| (m[c] - 0.5 * (p[c] + q[c])).abs() < 1e-15));
        }
    }
    assert!((flux_of_position(&s) - 3.0).abs() < 1e-12);
    assert!((s.area() - 6.0).abs() < 1e-12);
}

/// Two unit tets on the face (1, 2, 3): apex 0 at the origin, the second apex
/// at `apex`. Opposite sides is a valid mesh; the same side is a fold.
fn two_tets(apex: [f64; 3]) -> TetMesh {
    TetMesh {
        nodes: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], apex],
        cells: Cells::Tet4(vec![[0, 1, 2, 3], [4, 1, 3, 2]]),
        groups: Vec::new(),
    }
}

/// The two tets of [`two_tets`] with the shared face's corner 3 given to
/// the second tet as a separate node `offset` away (a crack).
fn cracked_tets(offset: f64) -> TetMesh {
    let mut mesh = two_tets([1.0, 1.0, 1.0]);
    mesh.nodes.push([0.0, offset, 1.0]);
    mesh.cells = Cells::Tet4(vec![[0, 1, 2, 3], [4, 1, 5, 2]]);
    mesh
}

#[test]
fn coincident_boundary_faces_are_an_internal_crack_not_surface() {
    // Intact: 6 faces; cracked by a hair (the mesher's cut point computed
    // twice): the shared face's two copies are dropped, not kept as two
    // opposite panels at zero distance.
    let intact = boundary_surface(&two_tets([1.0, 1.0, 1.0]));
    assert_eq!(intact.triangles.len(), 6);
    let hair = boundary_surface(&cracked_tets(5.9e-19));
    assert_eq!(hair.triangles.len(), 6);
    assert!((hair.area() - intact.area()).abs() < 1e-15);
    // ∮ x·n = 3V of the union: the surface is still closed around both tets.
    assert!((flux_of_position(&hair) - 1.5).abs() < 1e-15, "{}", flux_of_position(&hair));
    // A real gap (1e-6 of the size) is surface: 8 faces.
    assert_eq!(boundary_surface(&cracked_tets(1e-6)).triangles.len(), 8);
}

#[test]
fn tets_on_opposite_sides_of_a_shared_face_pass() {
    let (_, report) = check(two_tets([1.0, 1.0, 1.0])).unwrap();
    assert_eq!(report.reoriented, 0);
    assert!((report.volume - (1.0 / 6.0 + 1.0 / 3.0)).abs() < 1e-12, "{}", report.volume);
}

#[test]
fn folded_tets_are_an_error_not_silently_reoriented() {
    // The second apex lies on the first tet's side: element 1 is inverted
    // inside the mesh. Reorienting it would double-count the overlap.
    let err = check(two_tets([0.1, 0.1, 0.1])).unwrap_err();
    assert_eq!(err, MeshError::FoldedTets { element: 1, first: 0 });
    assert!(err.to_string().contains("elements 0 and 1 overlap"), "{err}");
}

#[test]
fn an_interior_node_pushed_through_a_face_folds_a_box_mesh() {
    // A 2×2×2-cell box has one interior node (the centre); moving it past
    // the boundary folds the tets around it.
    let mut mesh = box_mesh([1.0, 1.0, 1.0], [2, 2, 2]);
    let centre = mesh.nodes.iter().position(|p| p.iter().all(|c| (c - 0.5).abs() < 1e-12)).unwrap();
    let (_, ok) = check(mesh.clone()).unwrap();
    assert_eq!(ok.reoriented, 0);
    mesh.nodes[centre] = [0.5, 0.5, 1.4];
    let err = check(mesh).unwrap_err();
    assert!(matches!(err, MeshError::FoldedTets { .. }), "{err}");
}

#[test]
fn a_whole_mesh_in_the_other_vertex_order_is_reoriented_not_rejected() {
    let mut mesh = box_mesh([1.0, 2.0, 3.0], [3, 2, 2]);
    if let Cells::Tet4(t) = &mut mesh.cells {
        t.iter_mut().for_each(|t| t.swap(1, 2));
    }
    let (_, report) = check(mesh).unwrap();
    assert_eq!(report.reoriented, report.tets);
}

#[test]
fn three_tets_on_one_face_are_an_error() {
    let mut mesh = two_tets([1.0, 1.0, 1.0]);
    mesh.nodes.push([2.0, 2.0, 2.0]);
    if let Cells::Tet4(t) = &mut mesh.cells {
        t.push([5, 1, 3, 2]);
    }
    let err = check(mesh).unwrap_err();
    assert!(matches!(err, MeshError::OverlappingTets { element: 2, first: 0, second: 1 }), "{err}");
}
