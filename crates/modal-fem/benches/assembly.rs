//! Assembly throughput of TET10 stiffness + mass on a ~100k-DOF box
//! (16 × 16 × 16 hexahedra → 24 576 ten-node tets, 35 937 nodes,
//! 107 811 DOF). Report elements/s and DOF/s from the median time.
//!
//! Run: `cargo bench -p modal-fem --bench assembly` (set
//! `RAYON_NUM_THREADS` to compare thread counts).

use modal_fem::{assemble, prepare_mesh, Material, SparsityPattern};
use modal_mesh::{generate::box_mesh, TetMesh};

fn main() {
    divan::main();
}

fn mesh() -> TetMesh {
    prepare_mesh(&box_mesh([0.16, 0.16, 0.16], [16, 16, 16]), 2).unwrap()
}

fn steel() -> Material {
    Material::custom(200e9, 0.3, 7850.0, 0.0, 0.0).unwrap()
}

/// Symbolic pattern + numeric values (what `assemble` does).
#[divan::bench(sample_count = 5)]
fn pattern_and_values(bencher: divan::Bencher) {
    let mesh = mesh();
    let material = steel();
    bencher
        .counter(divan::counter::ItemsCount::new(mesh.cells.len()))
        .bench_local(|| assemble(divan::black_box(&mesh), &material).unwrap());
}

/// Numeric values only, pattern reused.
#[divan::bench(sample_count = 5)]
fn values_only(bencher: divan::Bencher) {
    let mesh = mesh();
    let material = steel();
    let pattern = SparsityPattern::new(&mesh).unwrap();
    bencher
        .counter(divan::counter::ItemsCount::new(mesh.cells.len()))
        .bench_local(|| pattern.assemble(divan::black_box(&mesh), &material).unwrap());
}

/// Symbolic pattern only.
#[divan::bench(sample_count = 5)]
fn pattern_only(bencher: divan::Bencher) {
    let mesh = mesh();
    bencher
        .counter(divan::counter::ItemsCount::new(mesh.cells.len()))
        .bench_local(|| SparsityPattern::new(divan::black_box(&mesh)).unwrap());
}
