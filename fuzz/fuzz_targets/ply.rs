//! Fuzz target: PLY surface (ASCII / binary). Must never panic, hang or allocate without bound.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = modal_tetra::parse_surface(data, modal_tetra::SurfaceFormat::Ply, 1.0, None);
});
