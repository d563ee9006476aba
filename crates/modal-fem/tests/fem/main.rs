//! Acceptance tests of issue 2 for `modal-fem` (one test binary, several modules).

// Index loops mirror the tensor notation of the checked formulas.
#![allow(clippy::needless_range_loop)]

mod common;
mod mass;
mod rigid_modes;
