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
