//! The bank file: a plain safetensors file (spec: `docs/bank-format.md`).
//!
//! Layout: an 8-byte little-endian header length `N`, `N` bytes of JSON
//! header (tensor dtypes, shapes, data offsets and a `__metadata__` string
//! map), then the tensor data. Every tensor is little-endian and
//! row-major. The writer is deterministic: the same bank gives the same bytes.

mod decode;
mod encode;
mod radiation_io;

use crate::{BankError, ModeBank};

/// Value of the metadata key `format`.
pub const FORMAT_NAME: &str = "modal-bank";
/// The format version this build writes (metadata `format_version`). It
/// reads every version from [`OLDEST_READABLE_VERSION`] to this one.
/// Version 2 added the optional radiation tensors (`crate::RadiationTable`).
pub const FORMAT_VERSION: u32 = 2;
/// The oldest format version this build still reads.
pub const OLDEST_READABLE_VERSION: u32 = 1;

pub(crate) const KEY_FORMAT: &str = "format";
pub(crate) const KEY_VERSION: &str = "format_version";
pub(crate) const KEY_UNITS: &str = "units";
pub(crate) const KEY_MATERIAL: &str = "material";
pub(crate) const KEY_SOLVE_INFO: &str = "solve_info";
pub(crate) const KEY_INPUT_HASH: &str = "input_hash";
pub(crate) const KEY_GENERATOR: &str = "generator";
pub(crate) const KEY_CHECKSUM: &str = "checksum";

pub(crate) const T_FREQUENCIES: &str = "frequencies_hz";
pub(crate) const T_DAMPING_RATIOS: &str = "damping_ratios";
pub(crate) const T_DECAY_RATES: &str = "decay_rates";
pub(crate) const T_RESIDUALS: &str = "residuals";
pub(crate) const T_SHAPES: &str = "shapes";
pub(crate) const T_POSITIONS: &str = "surface_positions";
pub(crate) const T_TRIANGLES: &str = "surface_triangles";
pub(crate) const T_EDGE_NODES: &str = "surface_triangle_edge_nodes";
pub(crate) const T_NODE_IDS: &str = "surface_node_ids";
pub(crate) const T_CENTER_OF_MASS: &str = "center_of_mass_m";
pub(crate) const T_INERTIA: &str = "inertia_kg_m2";
pub(crate) const T_VOLUME: &str = "volume_m3";
pub(crate) const T_MASS: &str = "mass_kg";

/// Units of every tensor, stored as JSON under the metadata key `units`.
pub(crate) const UNITS: [(&str, &str); 11] = [
    (T_FREQUENCIES, "Hz"),
    (T_DAMPING_RATIOS, "1"),
    (T_DECAY_RATES, "1/s"),
    (T_RESIDUALS, "1"),
    (T_SHAPES, "1/sqrt(kg)"),
    (T_POSITIONS, "m"),
    (T_CENTER_OF_MASS, "m"),
    (T_INERTIA, "kg*m^2"),
    (T_VOLUME, "m^3"),
    (T_MASS, "kg"),
    ("material", "SI: youngs_pa Pa, density_kg_m3 kg/m^3, alpha 1/s, beta s"),
];

/// A bank file decoded straight into the bank's buffers (see
/// `decode::from_file`); `None` when the plain path must be taken.
pub(crate) fn decode_file(file: &mut std::fs::File) -> Option<ModeBank> {
    decode::from_file(file)
}

/// Every field of a bank file but `shapes`, unverified (see `decode::light_from_bytes`).
pub(crate) fn decode_light(bytes: &[u8]) -> Result<ModeBank, BankError> {
    decode::light_from_bytes(bytes)
}

/// [`decode_light`] reading only the header and the tensors but `shapes` of a
/// file; `None` when the whole file must be read (see `decode::light_from_file`).
pub(crate) fn decode_light_file(file: &mut std::fs::File) -> Option<ModeBank> {
    decode::light_from_file(file)
}

impl ModeBank {
    /// Encodes the bank as a safetensors file in memory (validates first).
    pub fn to_bytes(&self) -> Result<Vec<u8>, BankError> {
        encode::to_bytes(self)
    }

    /// Decodes and validates a bank file held in memory: checks the
    /// safetensors framing, `format`, `format_version`, the checksum, every
    /// tensor's dtype and shape, then [`ModeBank::validate`]. Never panics on
    /// hostile bytes.
    pub fn from_bytes(bytes: &[u8]) -> Result<ModeBank, BankError> {
        decode::from_bytes(bytes)
    }

    /// [`ModeBank::to_bytes`] with the per-mode radiation table stored
    /// alongside (validated against the bank first).
    pub fn to_bytes_with_radiation(&self, table: &crate::RadiationTable) -> Result<Vec<u8>, BankError> {
        encode::to_bytes_with_radiation(self, Some(table))
    }

    /// Decodes a bank file held in memory and its radiation table, if it
    /// has one (`None` for version-1 banks and banks saved without one).
    pub fn from_bytes_with_radiation(
        bytes: &[u8],
    ) -> Result<(ModeBank, Option<crate::RadiationTable>), BankError> {
        let bank = decode::from_bytes(bytes)?;
        let table = radiation_io::read(bytes, &bank)?;
        Ok((bank, table))
    }
}
