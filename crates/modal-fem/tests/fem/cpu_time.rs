//! Single-thread CPU time of the assembly phases on the ~100k-DOF TET10
//! benchmark box (ignored: a measurement, not a check). Run with
//! `cargo test -p modal-fem --test fem cpu_time -- --ignored --nocapture`.
//! CPU time (Linux `/proc/thread-self/schedstat`) is robust on a loaded
//! machine where wall-clock benchmarks are not.

use modal_fem::element::{element_matrices_into, ElementRules};
use modal_fem::{prepare_mesh, SparsityPattern};
use modal_mesh::generate::box_mesh;

use crate::common::steel;

fn cpu_seconds() -> f64 {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
    text.split(' ').next().and_then(|s| s.parse::<f64>().ok()).unwrap_or(f64::NAN) * 1e-9
}

#[test]
#[ignore]
fn assembly_phases_cpu_time() {
    let mesh = prepare_mesh(&box_mesh([0.16; 3], [16, 16, 16]), 2).unwrap();
    let material = steel();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    pool.install(|| {
        let rules = ElementRules::default();
        let (mut k, mut m) = (vec![0.0; 900], vec![0.0; 900]);
        let t0 = cpu_seconds();
        for e in 0..mesh.cells.len() {
            let x: Vec<[f64; 3]> = mesh.cells.nodes_of(e).iter().map(|&n| mesh.nodes[n]).collect();
            element_matrices_into(e, &x, material.lame(), material.density_kg_m3, &rules, &mut k, &mut m).unwrap();
        }
        let t1 = cpu_seconds();
        let pattern = SparsityPattern::new(&mesh).unwrap();
        let t2 = cpu_seconds();
        let a = pattern.assemble(&mesh, &material).unwrap();
        let t3 = cpu_seconds();
        eprintln!(
            "{} TET10 elements, {} DOF, nnz {}: element kernels {:.3} s, pattern {:.3} s, values (kernels + scatter) {:.3} s CPU",
            mesh.cells.len(),
            pattern.dof_count(),
            a.k.val().len(),
            t1 - t0,
            t2 - t1,
            t3 - t2
        );
    });
}
