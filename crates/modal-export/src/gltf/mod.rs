//! glTF 2.0 binary (`.glb`) with the modal data of a bank, following the
//! `KHR_audio_rigid_bodies` draft (the successor of `KHR_audio_modal`; both
//! are read). Spec notes and where we depart: `docs/gltf-extension.md`.
//!
//! What a file holds (one bank = one mesh, one node, one modal model):
//! - the surface as a triangle mesh (`POSITION`, `indices`); a quadratic
//!   bank's 6-node triangles are split into 4 flat triangles through their
//!   mid-edge nodes, so every surface node is a vertex;
//! - root `extensions.KHR_audio_rigid_bodies`: `acousticMaterials` (ρ, E, ν,
//!   α, β) and `modalModels` with `frequencies` (damped, Hz), `decayRates`
//!   (1/s), `positions` (the mesh's vertices), `shapes` (VEC3, mode-major,
//!   mass-normalized, 1/√kg), `indices` (the mesh's triangles), `material`,
//!   `massProperties` (mass, centre of mass, principal inertia and its axes);
//! - node `extensions.KHR_audio_rigid_bodies`: `{modalModel, gain}`;
//! - `extras.modal` on the model: what the f32 accessors cannot carry exactly
//!   (f64 frequencies, damping, positions, the corner triangles and mid-edge
//!   nodes, material name, mass properties, solve info), so a bank exported
//!   and imported again is bit for bit the same bank. A reader that ignores
//!   it still gets a complete model; the importer uses it only when it agrees
//!   with the KHR data (else the file was edited by another tool).

mod read;
mod write;

pub use read::{holds_modal_model, import_glb, import_gltf_file, is_gltf_path, Imported};
pub use write::{export_glb, glb_container, GlbExport};

/// Name of the extension written (and read).
pub const EXTENSION: &str = "KHR_audio_rigid_bodies";
/// The earlier draft's name, still read.
pub const LEGACY_EXTENSION: &str = "KHR_audio_modal";
/// Key of our exact side data inside the model's `extras`.
pub const EXTRAS_KEY: &str = "modal";

/// glTF component types.
pub(crate) const FLOAT: u32 = 5126;
pub(crate) const UNSIGNED_INT: u32 = 5125;
pub(crate) const UNSIGNED_SHORT: u32 = 5123;
