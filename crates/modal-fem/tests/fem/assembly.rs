//! Assembly contracts: thread-count determinism, pattern reuse, errors,
//! constraints, MatrixMarket output.

use modal_fem::{
    assemble, fix_box, prepare_mesh, restrict, write_matrix_market, write_nodes_csv, FemError, Material,
    SparsityPattern,
};
use modal_mesh::{generate::box_mesh, Cells, TetMesh};

use crate::common::{jiggle_interior, steel};

fn small_mesh(order: u8) -> TetMesh {
    let mut mesh = box_mesh([0.3, 0.02, 0.01], [12, 2, 2]);
    jiggle_interior(&mut mesh, [0.3, 0.02, 0.01], 0.005);
    prepare_mesh(&mesh, order).unwrap()
}

fn assemble_with_threads(mesh: &TetMesh, threads: usize) -> (Vec<f64>, Vec<f64>) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let a = pool.install(|| assemble(mesh, &steel()).unwrap());
    (a.k.val().to_vec(), a.m.val().to_vec())
}

#[test]
fn assembly_is_bit_identical_for_any_thread_count() {
    for order in [1, 2] {
        let mesh = small_mesh(order);
        let one = assemble_with_threads(&mesh, 1);
        for threads in [2, 3] {
            let many = assemble_with_threads(&mesh, threads);
            let same = |x: &[f64], y: &[f64]| x.iter().zip(y).all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(
                same(&one.0, &many.0) && same(&one.1, &many.1),
                "order {order}, {threads} threads differ"
            );
        }
    }
}

#[test]
fn matrices_are_exactly_symmetric_and_pattern_is_reusable() {
    let mesh = small_mesh(2);
    let pattern = SparsityPattern::new(&mesh).unwrap();
    let a = pattern.assemble(&mesh, &steel()).unwrap();
    for m in [&a.k, &a.m] {
        let d = m.to_dense();
        for i in 0..d.nrows() {
            for j in 0..i {
                assert_eq!(d[(i, j)].to_bits(), d[(j, i)].to_bits(), "asymmetric at ({i}, {j})");
            }
        }
    }
    // Same pattern, other material: K scales with E, M with ρ.
    let soft = Material::custom(100e9, 0.3, 2.0 * 7850.0, 0.0, 0.0).unwrap();
    let b = pattern.assemble(&mesh, &soft).unwrap();
    for (x, y) in a.k.val().iter().zip(b.k.val()) {
        assert!((0.5 * x - y).abs() <= 1e-15 * x.abs().max(1.0));
    }
    for (x, y) in a.m.val().iter().zip(b.m.val()) {
        assert!((2.0 * x - y).abs() <= 1e-15 * x.abs());
    }
    assert_eq!(pattern.dof_count(), 3 * mesh.node_count());
}

#[test]
fn inverted_element_is_named_in_the_error() {
    let mut mesh = box_mesh([1.0, 1.0, 1.0], [2, 1, 1]);
    let Cells::Tet4(tets) = &mut mesh.cells else { unreachable!() };
    tets[5].swap(0, 1);
    for order in [1, 2] {
        let m = prepare_mesh(&mesh, order).unwrap();
        match assemble(&m, &steel()) {
            Err(FemError::NonPositiveJacobian { element: 5, det }) => assert!(det < 0.0),
            other => panic!("order {order}: expected NonPositiveJacobian for element 5, got {other:?}"),
        }
    }
    let err = assemble(&prepare_mesh(&mesh, 2).unwrap(), &steel()).unwrap_err().to_string();
    assert!(err.contains("element 5"), "{err}");
}

#[test]
fn bad_input_gives_typed_errors() {
    let mut mesh = box_mesh([1.0, 1.0, 1.0], [1, 1, 1]);
    let Cells::Tet4(tets) = &mut mesh.cells else { unreachable!() };
    tets[2][3] = 99;
    assert_eq!(
        assemble(&mesh, &steel()).unwrap_err(),
        FemError::NodeOutOfRange { element: 2, node: 99, node_count: 8 }
    );
    let empty = TetMesh { nodes: vec![], cells: Cells::Tet4(vec![]), groups: vec![] };
    assert_eq!(assemble(&empty, &steel()).unwrap_err(), FemError::EmptyMesh);
    assert_eq!(prepare_mesh(&empty, 3).unwrap_err(), FemError::UnsupportedOrder(3));
    let bad = Material { poisson: 0.5, ..steel() };
    assert!(matches!(assemble(&box_mesh([1.0; 3], [1, 1, 1]), &bad), Err(FemError::Material(_))));
    let mut nan = box_mesh([1.0; 3], [1, 1, 1]);
    nan.nodes[7][0] = f64::NAN;
    assert!(matches!(assemble(&nan, &steel()), Err(FemError::NonPositiveJacobian { .. })));
}

#[test]
fn restrict_removes_clamped_dofs_and_expand_puts_them_back() {
    let mesh = small_mesh(2);
    let a = assemble(&mesh, &steel()).unwrap();
    let clamped = fix_box(&mesh.nodes, [-1.0, -1.0, -1.0, 1e-9, 1.0, 1.0]);
    let n_clamped_nodes = mesh.nodes.iter().filter(|p| p[0] <= 1e-9).count();
    assert_eq!(clamped.iter().filter(|&&c| c).count(), 3 * n_clamped_nodes);
    let r = restrict(&a.k, &a.m, &clamped).unwrap();
    assert_eq!(r.k.nrows(), 3 * (mesh.node_count() - n_clamped_nodes));
    let (kd, kf) = (a.k.to_dense(), r.k.to_dense());
    for (fi, &i) in r.dofs.free_to_full.iter().enumerate() {
        for (fj, &j) in r.dofs.free_to_full.iter().enumerate().step_by(7) {
            assert_eq!(kf[(fi, fj)], kd[(i, j)]);
        }
    }
    let v: Vec<f64> = (0..r.dofs.free_count()).map(|i| i as f64 + 1.0).collect();
    let full = r.dofs.expand(&v).unwrap();
    assert!(full.iter().zip(&clamped).all(|(x, &c)| (*x == 0.0) == c));
    assert!(r.dofs.expand(&v[1..]).is_err());
    assert!(restrict(&a.k, &a.m, &clamped[1..]).is_err());
}

#[test]
fn matrix_market_is_lower_triangle_one_based_full_precision() {
    let mesh = prepare_mesh(&box_mesh([0.1, 0.05, 0.04], [2, 1, 1]), 2).unwrap();
    let a = assemble(&mesh, &steel()).unwrap();
    let mut text = Vec::new();
    let written = write_matrix_market(&a.k, &mut text).unwrap();
    let text = String::from_utf8(text).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('%') || l.starts_with("%%"));
    assert_eq!(lines.next(), Some("%%MatrixMarket matrix coordinate real symmetric"));
    let size: Vec<usize> = lines.next().unwrap().split(' ').map(|s| s.parse().unwrap()).collect();
    let n = 3 * mesh.node_count();
    assert_eq!(&size[..2], &[n, n]);
    let dense = a.k.to_dense();
    let mut rebuilt = faer::Mat::<f64>::zeros(n, n);
    let mut count = 0;
    for line in lines {
        let f: Vec<&str> = line.split(' ').collect();
        let (i, j): (usize, usize) = (f[0].parse().unwrap(), f[1].parse().unwrap());
        assert!(i >= j && j >= 1 && i <= n, "entry ({i}, {j}) not in the 1-based lower triangle");
        assert!(f[2].contains("e+") || f[2].contains("e-"), "C-style exponent: {}", f[2]);
        let v: f64 = f[2].parse().unwrap();
        rebuilt[(i - 1, j - 1)] = v;
        rebuilt[(j - 1, i - 1)] = v;
        count += 1;
    }
    assert_eq!((count, written), (size[2], size[2]), "the count returned is the count written");
    for i in 0..n {
        for j in 0..n {
            assert_eq!(
                rebuilt[(i, j)].to_bits(),
                dense[(i, j)].to_bits(),
                "entry ({i}, {j}) does not round-trip"
            );
        }
    }

    let mut csv = Vec::new();
    write_nodes_csv(&mesh.nodes, &mut csv).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    let mut rows = csv.lines();
    assert_eq!(rows.next(), Some("x,y,z"));
    let parsed: Vec<[f64; 3]> = rows
        .map(|r| {
            let v: Vec<f64> = r.split(',').map(|s| s.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    assert_eq!(parsed, mesh.nodes);
}

#[test]
fn a_pattern_beyond_the_memory_limit_is_refused_with_what_it_would_need() {
    let mesh = small_mesh(2);
    let full = SparsityPattern::new(&mesh).unwrap();
    let needed = modal_fem::matrices_bytes(full.nnz() as u64, full.dof_count() as u64);
    // K and M: values and row indices each, plus the shared pattern, 8 bytes an entry.
    assert!(needed >= 5 * 8 * full.nnz() as u64);
    assert!(SparsityPattern::new_within(&mesh, Some(needed)).is_ok(), "exactly at the limit fits");
    match SparsityPattern::new_within(&mesh, Some(needed - 1)) {
        Err(e @ modal_fem::FemError::TooLarge { .. }) => {
            let text = e.to_string();
            assert!(
                text.contains(&format!("{} DOF", full.dof_count())) && text.contains("coarser mesh"),
                "{text}"
            );
        }
        other => panic!("expected TooLarge, got {other:?}"),
    }
}

#[test]
fn quadratic_meshes_hold_at_least_the_lower_bound_of_node_pairs() {
    use modal_mesh::generate::{generate_sized, Shape};
    // One tet (all 45 pairs distinct), a jiggled bar, and generated shapes
    // whose tets meet in many ways (O-grids, wedges cut in three, a thin wall).
    let one = TetMesh {
        nodes: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        cells: Cells::Tet4(vec![[0, 1, 2, 3]]),
        groups: Vec::new(),
    };
    let mut meshes = vec![prepare_mesh(&one, 2).unwrap(), small_mesh(2)];
    for shape in [
        Shape::Sphere { radius: 0.03 },
        Shape::Cylinder { radius: 0.02, length: 0.1 },
        Shape::Tube { inner_radius: 0.012, outer_radius: 0.014, length: 0.1 },
        Shape::Bowl { radius: 0.05, thickness: 0.004 },
    ] {
        meshes.push(generate_sized(&shape, shape.default_sizes(2), 2).unwrap());
    }
    for mesh in &meshes {
        let pattern = SparsityPattern::new(mesh).unwrap();
        let tets = mesh.cells.len() as u64;
        let bound = modal_fem::min_quadratic_matrices_bytes(tets);
        let actual = modal_fem::matrices_bytes(pattern.nnz() as u64, pattern.dof_count() as u64);
        assert!(actual >= bound, "{tets} tets: {actual} B below the bound {bound} B");
        // Close enough to the truth to refuse what cannot fit: ≥ 40 % of it here.
        assert!(bound as f64 >= 0.4 * actual as f64 || tets == 1, "{tets} tets: {bound} B vs {actual} B");
    }
}
