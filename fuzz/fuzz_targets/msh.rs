//! Fuzz target: Gmsh .msh (2.2 / 4.1, ASCII / binary). Must never panic, hang or allocate without bound.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = modal_mesh::io::read_msh(data, 1.0);
});
