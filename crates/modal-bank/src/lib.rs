//! `modal-bank`: the mode bank — what the offline stage hands to the runtime.
//!
//! Input: the elastic modes of a solid (from `modal-eigen`), its surface and
//! material. Output: a [`ModeBank`] in memory and on disk (safetensors, see
//! `docs/bank-format.md`).

mod types;
pub use types::*;
