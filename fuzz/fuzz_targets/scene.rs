//! Fuzz target: scene TOML. Must never panic, hang or allocate without bound.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = modal_scene::Scene::from_toml_str(text, std::path::Path::new("."));
    }
});
