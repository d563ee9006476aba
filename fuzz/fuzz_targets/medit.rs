//! Fuzz target: Medit .mesh. Must never panic, hang or allocate without bound.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = modal_mesh::io::read_medit(data, 1.0);
});
