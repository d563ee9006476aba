//! Issue 14: near-zero modes that are not rigid-body modes (mechanisms). Two boxes joined
//! only along an edge have a zero-stiffness rotation about it; the solver must stop early
//! and say why (not run 200 restarts into "did not converge"), and the same boxes split into
//! separate bodies (what `modal_mesh::check` and `modal-tetra` do) must solve exactly.

mod common;

use modal_eigen::{solve, EigenError, EigenOptions, EigenSolution, STALL_RESTARTS};
use modal_fem::{assemble, node_parts, rigid_body_fields, Material};
use modal_mesh::generate::box_mesh;
use modal_mesh::{to_quadratic, Cells, TetMesh};

fn ceramic() -> Material {
    Material::custom(72e9, 0.19, 2700.0, 0.0, 0.0).unwrap()
}

/// Two boxes of `cells`³ linear cells (side 5 cm, then made quadratic) sharing one
/// vertical edge (node indices shared there): face-disconnected, node-connected.
fn hinged_boxes(cells: usize) -> TetMesh {
    let a = box_mesh([0.05; 3], [cells; 3]);
    let mut nodes = a.nodes.clone();
    let mut index = Vec::new();
    for p in &a.nodes {
        let q = [p[0] + 0.05, p[1] + 0.05, p[2]];
        match a.nodes.iter().position(|n| (0..3).all(|c| (n[c] - q[c]).abs() < 1e-12)) {
            Some(i) => index.push(i),
            None => {
                nodes.push(q);
                index.push(nodes.len() - 1);
            }
        }
    }
    let Cells::Tet4(ta) = &a.cells else { unreachable!() };
    let mut tets = ta.clone();
    tets.extend(ta.iter().map(|t| t.map(|v| index[v])));
    to_quadratic(&TetMesh { nodes, cells: Cells::Tet4(tets), groups: Vec::new() })
}

fn free_solve(
    mesh: &TetMesh,
    opts: &EigenOptions,
) -> (Result<EigenSolution, EigenError>, usize, modal_fem::Assembly) {
    let a = assemble(mesh, &ceramic()).unwrap();
    let (part, n) = node_parts(mesh);
    let rigid = rigid_body_fields(&mesh.nodes, &part, n, &[]);
    (solve(&a.k, &a.m, Some(rigid.as_ref()), opts, &mut |_| {}), n, a)
}

#[test]
fn a_hinge_mechanism_stops_early_with_a_message_instead_of_running_out_of_restarts() {
    // Node-connected through one edge only: one part by nodes, six rigid fields, and a
    // zero-stiffness rotation about the edge that no rigid field covers.
    let mesh = hinged_boxes(6);
    let opts = EigenOptions::default();
    let (r, parts, _) = free_solve(&mesh, &opts);
    assert_eq!(parts, 1);
    match r {
        Err(EigenError::Stalled { restarts, hint, .. }) => {
            // Two searches (the second with the lower inertia count), each stopped after
            // STALL_RESTARTS restarts without progress: far below max_restarts (200).
            assert!(restarts <= 2 * (STALL_RESTARTS + 10), "{restarts} restarts");
            assert!(hint.contains("1 modes besides the rigid-body ones lie below 20 Hz"), "{hint}");
            assert!(hint.contains("hinge"), "{hint}");
        }
        other => panic!("expected a stall with a message, got {:?}", other.map(|s| s.frequencies_hz())),
    }
}

#[test]
fn splitting_the_hinge_gives_two_free_boxes_with_the_single_box_modes_twice() {
    let mut mesh = hinged_boxes(6);
    let parts = modal_mesh::face_parts(&mesh);
    assert_eq!((parts.count, parts.hinges.len()), (2, 1));
    modal_mesh::split_hinges(&mut mesh, &parts);
    // modal-fem's node parts (they once lost a union here) agree with modal-mesh's.
    assert_eq!(node_parts(&mesh).1, modal_mesh::connected_parts(&mesh).0);
    let opts = EigenOptions { max_modes: 12, max_freq_hz: 1e6, ..Default::default() };
    let (pair, n, a) = free_solve(&mesh, &opts);
    assert_eq!(n, 2);
    let pair = pair.expect("the split problem solves");
    common::check_solution(&a.k, &a.m, &pair, &opts);
    assert_eq!(pair.stats.rigid_modes_removed, 12);
    let single = to_quadratic(&box_mesh([0.05; 3], [6; 3]));
    let one_opts = EigenOptions { max_modes: 6, max_freq_hz: 1e6, ..Default::default() };
    let (one, _, _) = free_solve(&single, &one_opts);
    let (f2, f1) = (pair.frequencies_hz(), one.unwrap().frequencies_hz());
    for k in 0..6 {
        for f in [f2[2 * k], f2[2 * k + 1]] {
            assert!((f / f1[k] - 1.0).abs() < 1e-7, "mode {k}: {f} Hz vs one box's {} Hz", f1[k]);
        }
    }
}
