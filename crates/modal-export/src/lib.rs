//! `modal-export`: mode banks out to the tools people already use.
//!
//! Input: a validated [`modal_bank::ModeBank`]. Outputs:
//! - [`faust`]: a Faust modal model in the form mesh2faust writes
//!   (`pm.modeFilter` per mode; frequencies, T60s and one row of gains per
//!   excitation position), see `docs/faust.md`;
//! - [`gltf`]: a binary glTF with the surface mesh and the modal model in the
//!   `KHR_audio_rigid_bodies` draft extension, and the way back: any glTF
//!   with that extension (or the older `KHR_audio_modal`) read as a bank,
//!   see `docs/gltf-extension.md`.
//!
//! Library code only: every function returns a typed [`ExportError`] and
//! never prints; the `modal export` command writes the files atomically.

#![warn(missing_docs)]

mod error;
pub mod faust;
pub mod gltf;
mod inertia;

pub use error::ExportError;
