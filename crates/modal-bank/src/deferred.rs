//! Loading a cache entry in two steps, so that work needing only a bank's
//! surface and mass (a rigid-body simulation) can start before the mode
//! shapes — most of the bytes — are read and the whole file is verified.
//!
//! Step 1 ([`crate::BankCache::get_deferred`]) reads the header and every tensor
//! but `shapes` (≈ 0.4 MB of the demo bowl's 8 MB; reading 8 MB into fresh
//! memory costs ≈ 8 ms of page faults on the machines measured) and decodes
//! everything but the shapes, checking framing, format, dtypes and tensor
//! shapes. The light bank has empty `shapes`, has **not** passed the checksum
//! nor [`ModeBank::validate`], and must not outlive a failed step 2.
//! Step 2 ([`DeferredBank::finish`]) is [`ModeBank::load`] of the same file: the
//! checksum, every check, the complete bank.

use crate::cache::checked_entry;
use crate::format::{decode_light, decode_light_file};
use crate::fsio::{decode_open_file, read_whole};
use crate::{BankError, ModeBank};
use std::fs::File;
use std::path::PathBuf;

/// A cache entry read in part, its light bank decoded, its verification pending.
#[derive(Debug)]
pub struct DeferredBank {
    file: File,
    path: PathBuf,
    key: String,
}

impl DeferredBank {
    /// Step 1 for the entry at `path` (an existing regular file) that must carry
    /// `key`. Errors (as [`BankError::CorruptCacheEntry`]) are those
    /// [`crate::BankCache::get`] would give for a damaged or foreign entry.
    pub(crate) fn open(
        mut file: File,
        path: PathBuf,
        key: &str,
    ) -> Result<(ModeBank, DeferredBank), BankError> {
        let light = match decode_light_file(&mut file) {
            Some(light) => Ok(light),
            // Anything unusual: read it all, so that the decoder names the problem.
            None => decode_light(&read_whole(&mut file, &path)?),
        };
        let light = checked_entry(light, &path, key)?;
        Ok((light, DeferredBank { file, path, key: key.into() }))
    }

    /// Step 2: the complete bank, checksum verified and validated — or the error
    /// [`ModeBank::from_bytes`] gives, as [`BankError::CorruptCacheEntry`]. The
    /// file is decoded as by [`ModeBank::load`], from the file opened in step 1.
    pub fn finish(mut self) -> Result<ModeBank, BankError> {
        let loaded = decode_open_file(&mut self.file, &self.path)?;
        checked_entry(loaded, &self.path, &self.key)
    }
}
