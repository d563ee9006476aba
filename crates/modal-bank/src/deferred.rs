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

use crate::format::{decode_file, decode_light, decode_light_file};
use crate::{BankError, ModeBank};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
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
        let corrupt = |reason| BankError::CorruptCacheEntry { path: path.clone(), reason: Box::new(reason) };
        let light = match decode_light_file(&mut file) {
            Some(light) => light,
            // Anything unusual: read it all, so that the decoder names the problem.
            None => {
                let mut bytes = Vec::new();
                let read_err = |source| BankError::Read { path: path.clone(), source };
                file.seek(SeekFrom::Start(0)).map_err(read_err)?;
                file.read_to_end(&mut bytes).map_err(read_err)?;
                decode_light(&bytes).map_err(corrupt)?
            }
        };
        if light.info.input_hash != key {
            return Err(corrupt(BankError::KeyMismatch { key: key.into(), found: light.info.input_hash }));
        }
        Ok((light, DeferredBank { file, path, key: key.into() }))
    }

    /// Step 2: the complete bank, checksum verified and validated — or the error
    /// [`ModeBank::from_bytes`] gives, as [`BankError::CorruptCacheEntry`]. The
    /// file is decoded straight into the bank's buffers (as by [`ModeBank::load`]);
    /// anything unusual takes `from_bytes` on the whole file for the exact error.
    pub fn finish(mut self) -> Result<ModeBank, BankError> {
        let path = self.path;
        let corrupt = |reason| BankError::CorruptCacheEntry { path: path.clone(), reason: Box::new(reason) };
        let read_err = |source| BankError::Read { path: path.clone(), source };
        self.file.seek(SeekFrom::Start(0)).map_err(read_err)?;
        let bank = match decode_file(&mut self.file) {
            Some(bank) => bank,
            None => {
                let mut bytes = Vec::new();
                self.file.seek(SeekFrom::Start(0)).map_err(read_err)?;
                self.file.read_to_end(&mut bytes).map_err(read_err)?;
                ModeBank::from_bytes(&bytes).map_err(corrupt)?
            }
        };
        if bank.info.input_hash != self.key {
            return Err(corrupt(BankError::KeyMismatch { key: self.key, found: bank.info.input_hash }));
        }
        Ok(bank)
    }
}
