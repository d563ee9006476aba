//! `modal-batch`: precompute mode banks for a whole asset library.
//!
//! Input: a TOML manifest ([`Manifest`], format in `docs/asset-libraries.md`)
//! listing assets (`[[assets]]`) and glob patterns (`[[globs]]`) with per-asset
//! and `[defaults]` options, plus an optional shard selection ([`Shard`]: a
//! flag `I/N`, or a Slurm array / Kubernetes Indexed Job environment).
//! Output: one bank per asset in an output directory and a [`Catalogue`]
//! (`catalogue.json`, or `catalogue-shard-I-of-N.json` per shard) that
//! [`merge`] joins into one.
//!
//! Stages:
//! 1. [`Manifest::parse`] / [`Manifest::load`] — TOML, unknown keys rejected;
//! 2. [`Manifest::resolve`] — globs expanded (sorted), options merged
//!    (asset > glob > defaults), materials resolved, bank names derived and
//!    checked for collisions: a bad manifest fails before any work;
//! 3. [`Shard::owns`] — each asset belongs to exactly one of N shards, by a
//!    SHA-256 of its bank name (independent of N's other shards, of the order
//!    of the manifest and of the machine);
//! 4. [`run_batch`] — every asset through `modal-precompute` and the
//!    content-addressed [`modal_bank::BankCache`]; a failing asset becomes a
//!    catalogue entry with its error, never a stop. Progress is reported as
//!    [`Event`]s; this crate never prints.

#![warn(missing_docs)]

mod catalogue;
mod fsio;
mod glob;
mod manifest;
mod merge;
mod run;
mod shard;
mod terms;

pub use catalogue::{Catalogue, CatalogueEntry, Library, ShardInfo, CATALOGUE_FILE};
pub use glob::{expand as expand_glob, Pattern};
pub use manifest::{Accuracy, Asset, Manifest, Options};
pub use merge::{merge, MergeReport};
pub use run::{run_asset, run_batch, BatchOptions, Event, SNAPSHOT_INTERVAL};
pub use shard::{Shard, ShardEnv, MAX_SHARDS, SHARD_COUNT_ENV};

/// Everything that can stop a batch before it starts, or a merge.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    /// A file could not be read.
    #[error("cannot read {path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A file could not be written.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The manifest is not valid TOML or has unknown keys.
    #[error("manifest {path}: {message}")]
    Toml {
        /// The manifest.
        path: String,
        /// The parser's message and where, on one line (its caret diagram
        /// printed squashed into the error line).
        message: String,
    },
    /// The manifest parses but says something impossible.
    #[error("manifest {path}: {message}")]
    Manifest {
        /// The manifest.
        path: String,
        /// What is wrong, naming the table and key.
        message: String,
    },
    /// A shard selection that cannot be used.
    #[error("{0}")]
    Shard(String),
    /// A catalogue that cannot be read or merged.
    #[error("catalogue {path}: {message}")]
    Catalogue {
        /// The catalogue file or directory.
        path: String,
        /// What is wrong.
        message: String,
    },
}
