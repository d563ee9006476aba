//! Fuzz target: mode bank (safetensors). Must never panic, hang or allocate without bound.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = modal_bank::ModeBank::from_bytes(data);
});
