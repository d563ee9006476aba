//! Typed errors of the bank crate: one clear line each, naming the offending
//! file, tensor, metadata key, field or index.

use std::path::PathBuf;

/// Everything that can go wrong reading, writing, validating, caching,
/// retuning or exporting a mode bank.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BankError {
    /// The file could not be opened or read.
    #[error("cannot read {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The path exists but is a directory or another non-regular file.
    #[error("{} is not a file", path.display())]
    NotAFile {
        /// The path.
        path: PathBuf,
    },
    /// The output could not be written (nothing is left behind).
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The destination.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// Another kind of file users mix up with a bank (a mesh, a WAV, a scene).
    #[error("this is {0}, not a mode bank")]
    OtherFile(&'static str),
    /// The bytes are not a safetensors file at all.
    #[error("not a safetensors file: {0}")]
    NotSafetensors(String),
    /// The file ends before the data its header announces.
    #[error("bank is truncated: {expected} bytes expected, only {actual} present")]
    Truncated {
        /// Bytes the header (or the 8-byte length prefix) requires.
        expected: u64,
        /// Bytes present.
        actual: u64,
    },
    /// A safetensors file that is not a mode bank.
    #[error("not a modal bank: metadata 'format' is {}, expected \"modal-bank\"", found.as_deref().map_or_else(|| "missing".to_string(), |f| format!("{f:?}")))]
    WrongFormat {
        /// The `format` metadata value found, if any.
        found: Option<String>,
    },
    /// A mode bank of a format version this build cannot read.
    #[error("unsupported bank format version {found:?} (this build reads versions 1 to {supported})")]
    UnsupportedVersion {
        /// The `format_version` metadata value found.
        found: String,
        /// The newest version this build reads (and the one it writes).
        supported: u32,
    },
    /// The stored checksum does not match the file contents.
    #[error("bank is corrupted: checksum mismatch")]
    ChecksumMismatch {
        /// Checksum stored in the metadata.
        stored: String,
        /// Checksum computed from the contents.
        computed: String,
    },
    /// A required tensor is absent.
    #[error("bank has no tensor '{0}'")]
    MissingTensor(String),
    /// A required metadata key is absent.
    #[error("bank metadata has no key '{0}'")]
    MissingMetadata(String),
    /// A metadata value does not parse.
    #[error("bank metadata '{key}' is invalid: {detail}")]
    BadMetadata {
        /// The metadata key.
        key: String,
        /// What is wrong with it.
        detail: String,
    },
    /// A tensor has the wrong element type.
    #[error("tensor '{name}' has dtype {found}, expected {expected}")]
    WrongDtype {
        /// Tensor name.
        name: String,
        /// Dtype found.
        found: String,
        /// Dtype required.
        expected: String,
    },
    /// A tensor has the wrong shape.
    #[error("tensor '{name}' has shape {found:?}, expected {expected}")]
    WrongShape {
        /// Tensor name.
        name: String,
        /// Shape found.
        found: Vec<usize>,
        /// Shape required, e.g. `[n_modes=4, n_surface=10, 3]`.
        expected: String,
    },
    /// Array lengths that must agree do not.
    #[error("inconsistent bank: {0}")]
    Inconsistent(String),
    /// A NaN or infinite value.
    #[error("{field} is not finite ({value})")]
    NonFinite {
        /// The field and index, e.g. `frequencies_hz[3]`.
        field: String,
        /// The value.
        value: f64,
    },
    /// Frequencies must be non-decreasing.
    #[error("frequencies_hz is not ascending: mode {index} is {value} Hz, below mode {} at {previous} Hz", index - 1)]
    NotAscending {
        /// The first mode whose frequency is lower than its predecessor's.
        index: usize,
        /// Its frequency [Hz].
        value: f64,
        /// The predecessor's frequency [Hz].
        previous: f64,
    },
    /// A finite value outside its physical range.
    #[error("{field} = {value} is out of range: {rule}")]
    OutOfRange {
        /// The field and index, e.g. `decay_rates[2]`.
        field: String,
        /// The value.
        value: f64,
        /// The rule it breaks.
        rule: String,
    },
    /// A surface index that does not name a surface node.
    #[error("{field} = {value} is not a surface node index (the surface has {count} nodes)")]
    BadIndex {
        /// The field and index, e.g. `surface_triangles[5][1]`.
        field: String,
        /// The index found.
        value: i128,
        /// Number of surface nodes.
        count: usize,
    },
    /// An impossible material.
    #[error("invalid material: {0}")]
    InvalidMaterial(String),
    /// Retune asked for a different Poisson's ratio.
    #[error("changing Poisson's ratio needs a new solve (bank ν = {bank}, requested ν = {requested})")]
    PoissonChanged {
        /// ν of the bank.
        bank: f64,
        /// ν requested.
        requested: f64,
    },
    /// Retune asked for a non-positive or non-finite geometric scale.
    #[error("invalid scale {0}: must be finite and > 0")]
    InvalidScale(f64),
    /// A cache key that is not a SHA-256 hex digest.
    #[error("invalid cache key '{0}': expected 64 lowercase hex digits")]
    InvalidCacheKey(String),
    /// No cache directory could be determined.
    #[error("no cache directory: set MODAL_CACHE_DIR, XDG_CACHE_HOME or HOME")]
    NoCacheDir,
    /// A bank stored under a cache key must carry that key as its input hash.
    #[error("bank input_hash '{found}' does not match cache key '{key}'")]
    KeyMismatch {
        /// The cache key.
        key: String,
        /// The bank's `info.input_hash`.
        found: String,
    },
    /// A cache entry exists but cannot be served; recompute and overwrite it.
    #[error("cache entry {} is unusable: {reason}", path.display())]
    CorruptCacheEntry {
        /// The entry's file.
        path: PathBuf,
        /// Why it was rejected.
        reason: Box<BankError>,
    },
    /// Writing an export to a caller-supplied sink failed.
    #[error("cannot write VTU output: {0}")]
    Export(#[source] std::io::Error),
}

impl BankError {
    /// True for [`BankError::CorruptCacheEntry`]: the caller should warn,
    /// recompute and overwrite the entry.
    pub fn is_corrupt_cache_entry(&self) -> bool {
        matches!(self, BankError::CorruptCacheEntry { .. })
    }
}
