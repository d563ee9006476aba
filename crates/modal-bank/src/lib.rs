//! `modal-bank`: the mode bank — what the offline stage hands to the runtime.
//!
//! Input: the elastic modes of a solid (from `modal-eigen`), its surface,
//! material and mass properties. Output: a validated [`ModeBank`] in memory
//! and on disk as a plain safetensors file (spec: `docs/bank-format.md`),
//! a content-addressed cache of banks, material/size retuning without a new
//! eigen solve, and a ParaView (`.vtu`) export of the mode shapes.
//!
//! - [`ModeBank::save`] / [`ModeBank::load`] / [`ModeBank::to_bytes`] /
//!   [`ModeBank::from_bytes`]: the file format, checksum verified on every load;
//! - [`ModeBank::validate`]: every invariant of a bank;
//! - [`RadiationTable`]: optional per-mode acoustic transfer (multipole
//!   coefficients) stored with the bank ([`ModeBank::save_with_radiation`]);
//! - [`BankCache`] and [`CacheKey`]: content-addressed storage of banks;
//! - [`retune`]: new material (same ν) and/or size by exact scaling;
//! - [`export_vtu`] / [`export_vtu_file`]: surface + mode shapes for ParaView;
//! - [`rayleigh`], [`ModeBank::t60_s`], [`ModeBank::damped_frequency_hz`]:
//!   the damping convention `C = αM + βK`.

#![warn(missing_docs)]

mod cache;
mod checksum;
mod damping;
mod deferred;
mod error;
mod format;
mod fsio;
mod key;
mod radiation;
mod retune;
mod types;
mod validate;
mod vtu;

pub use cache::{default_dir_from, BankCache, CACHE_DIR_ENV};
pub use key::CacheKey;
pub use retune::{keeping_poisson, poisson_shift, retune, retune_radiation, RetuneSpec, RETUNED_PREFIX};
pub use vtu::{export_vtu, export_vtu_file, mode_array_name};

pub use damping::rayleigh;
pub use deferred::DeferredBank;
pub use error::BankError;
pub use format::{FORMAT_NAME, FORMAT_VERSION, OLDEST_READABLE_VERSION};
pub use fsio::{request_stop, write_file_atomically, writes_in_progress};
pub use radiation::{ModeTransfer, RadiationTable};
pub use types::*;
