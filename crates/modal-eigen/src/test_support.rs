//! Shared by the unit tests and the ignored speed tests: the steel TET10 box the benchmarks
//! use, and a timer.

/// K and M of a free steel box 0.2 × 0.15 × 0.1 m (E 200 GPa, ν 0.3, ρ 7850) of `cells`
/// hexahedra per axis, split into tets and promoted to TET10. `[14, 11, 7]` is the 30k-DOF
/// benchmark box.
pub fn steel_box(cells: [usize; 3]) -> modal_fem::Assembly {
    let mesh = modal_mesh::to_quadratic(&modal_mesh::generate::box_mesh([0.2, 0.15, 0.1], cells));
    let steel = modal_fem::Material::custom(200e9, 0.3, 7850.0, 0.0, 0.0).expect("steel");
    modal_fem::assemble(&mesh, &steel).expect("assembly")
}

/// Mean milliseconds of `reps` calls of `f`.
pub fn time_ms(reps: usize, f: &mut dyn FnMut()) -> f64 {
    let start = std::time::Instant::now();
    for _ in 0..reps {
        f();
    }
    start.elapsed().as_secs_f64() / reps as f64 * 1e3
}

/// faer's own numeric factor (`kind`) of the upper triangle of `a` (must succeed): the
/// reference the tiled solves and the two-core factorization are compared with.
pub fn faer_numeric(
    sym: &faer::sparse::linalg::cholesky::SymbolicCholesky<usize>,
    a: faer::sparse::SparseColMatRef<'_, usize, f64>,
    kind: crate::tiled::FactorKind,
) -> Vec<f64> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::cholesky::{ldlt::factor::LdltRegularization, llt::factor::LltRegularization};
    use faer::{Par, Side};
    let mut values = vec![0.0; sym.len_val()];
    let req = sym
        .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
        .or(sym.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()));
    let mut buf = MemBuffer::new(req);
    let stack = MemStack::new(&mut buf);
    let (up, seq) = (Side::Upper, Par::Seq);
    match kind {
        crate::tiled::FactorKind::Llt => {
            let reg = LltRegularization::default();
            sym.factorize_numeric_llt(&mut values, a, up, reg, seq, stack, Default::default()).unwrap();
        }
        crate::tiled::FactorKind::Ldlt => {
            let reg = LdltRegularization::default();
            sym.factorize_numeric_ldlt(&mut values, a, up, reg, seq, stack, Default::default()).unwrap();
        }
    }
    values
}
