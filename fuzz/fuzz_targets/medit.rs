//! Fuzz target: Medit .mesh. Must never panic, hang or allocate without bound.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // A parsed mesh also goes through the checks (orientation, folds, quality).
    if let Ok(mesh) = modal_mesh::io::read_medit(data, 1.0) {
        let _ = modal_mesh::check(mesh);
    }
});
