//! Typed errors of the exporters; each message is one line naming the bad value.

/// Everything that can go wrong exporting or importing a bank.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The bank has no mode with a positive damped frequency to export.
    #[error("the bank has no underdamped mode to export (every mode is overdamped, ξ ≥ 1, or it has none)")]
    NoModes,
    /// No excitation position was given.
    #[error("no excitation position: give at least one --at X,Y,Z")]
    NoPositions,
    /// An excitation point could not be placed on the surface.
    #[error("excitation position {index} ({x}, {y}, {z}): {source}", x = point[0], y = point[1], z = point[2])]
    Position {
        /// 0-based index of the position.
        index: usize,
        /// The requested point \[m\].
        point: [f64; 3],
        /// Why it was refused.
        #[source]
        source: modal_synth::SynthError,
    },
    /// The bank cannot be used by the synthesizer (inconsistent arrays, …).
    #[error("the bank cannot be struck: {0}")]
    Bank(#[source] modal_synth::SynthError),
    /// A name that is not a Faust identifier.
    #[error("'{0}' is not a Faust identifier (letters, digits and '_', a letter first after any '_')")]
    Identifier(String),
    /// A Faust keyword or primitive (or `process`), which no definition can be named after.
    #[error("`{0}` is a Faust keyword; choose another name")]
    FaustKeyword(String),
    /// An environment of Faust's `stdfaust.lib`, which the generated library
    /// imports, so the name would be defined twice.
    #[error("`{0}` is a Faust standard library environment (stdfaust.lib); choose another name")]
    FaustEnvironment(String),
    /// The bank fails its own validation.
    #[error("invalid bank: {0}")]
    InvalidBank(#[source] modal_bank::BankError),
    /// The bank has no surface triangles.
    #[error("the bank has no surface triangles to export")]
    NoSurface,
    /// A count beyond what the format can index.
    #[error("too large for glTF: {0}")]
    TooLarge(String),
    /// The file is not glTF, or fails the glTF crate's validation.
    #[error("not a valid glTF file: {0}")]
    Gltf(String),
    /// The glTF has no modal extension.
    #[error("the glTF has no KHR_audio_rigid_bodies (or KHR_audio_modal) modal data")]
    NoExtension,
    /// The modal model breaks a rule of the draft or cannot make a bank.
    #[error("glTF modal model: {0}")]
    Model(String),
    /// Reading a file failed.
    #[error("cannot read {path}: {source}")]
    Read {
        /// The file.
        path: std::path::PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// Writing the output failed.
    #[error("write failed: {0}")]
    Io(#[from] std::io::Error),
}
