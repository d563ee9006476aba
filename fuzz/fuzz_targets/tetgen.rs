//! Fuzz target: TetGen .node + .ele (split at the first NUL byte). Must never panic, hang or allocate without bound.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
    let (node, ele) = data.split_at(split);
    if let Ok(mesh) = modal_mesh::io::read_tetgen(node, ele.get(1..).unwrap_or(&[]), 1.0) {
        let _ = modal_mesh::check(mesh);
    }
});
