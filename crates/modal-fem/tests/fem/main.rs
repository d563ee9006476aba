//! Acceptance tests of issue 2 for `modal-fem` (one test binary, several modules).

// Index loops mirror the tensor notation of the checked formulas.
#![allow(clippy::needless_range_loop)]

mod assembly;
mod bar;
mod common;
mod cpu_time;
mod mass;
mod patch;
mod reference;
mod rigid_modes;
