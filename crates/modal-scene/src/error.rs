//! Errors of scene loading and rendering: one line each, naming the key path
//! (`objects[2].material`) or the object concerned.

use std::path::PathBuf;

/// Anything that can go wrong between a scene file and its channels.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The TOML text does not parse or does not match the schema.
    #[error("scene {}{message}", if path.is_empty() { String::new() } else { format!("{path}: ") })]
    Parse {
        /// Key path of the offending value (`objects[2].material`), empty when unknown.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A value is out of its range or inconsistent.
    #[error("scene {path}: {message}")]
    Invalid {
        /// Key path of the offending value.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A file could not be read or written.
    #[error("{}: {message}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The system's message.
        message: String,
    },
    /// The bank provider failed for an object.
    #[error("scene {path}: no mode bank: {source}")]
    Bank {
        /// Key path of the object (`objects[1]`).
        path: String,
        /// The provider's error.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The physics engine rejected a shape.
    #[error("scene {path}: cannot build a collider: {message}")]
    Collider {
        /// Key path of the object.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// Synthesis failed.
    #[error("synthesis of {object}: {message}")]
    Synthesis {
        /// Object name.
        object: String,
        /// The synthesizer's message.
        message: String,
    },
}

impl SceneError {
    /// A validation error at `path`.
    pub(crate) fn invalid(path: impl Into<String>, message: impl Into<String>) -> SceneError {
        SceneError::Invalid { path: path.into(), message: message.into() }
    }
}
