//! Loading a cache entry in two steps, so that work needing only a bank's
//! surface and mass (a rigid-body simulation) can start before the mode
//! shapes — most of the bytes — are read and the whole file is verified.
//!
//! Step 1 ([`crate::BankCache::get_deferred`]) reads the header and every tensor
//! but `shapes` into a buffer of the file's length (the unread part stays
//! untouched zero pages: reading 8 MB into fresh memory costs ≈ 8 ms of page
//! faults on the machines measured, the light tensors ≈ 0.4 MB) and decodes
//! everything but the shapes, checking framing, format, dtypes and tensor
//! shapes. The light bank has empty `shapes`, has **not** passed the checksum
//! nor [`ModeBank::validate`], and must not outlive a failed step 2.
//! Step 2 ([`DeferredBank::finish`]) is [`ModeBank::load`] of the same file: the
//! checksum, every check, the complete bank.

use crate::format::{decode_file, decode_light, T_SHAPES};
use crate::{BankError, ModeBank};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::PathBuf;

/// Longest header read in step 1 (longer ones take the plain path).
const MAX_LIGHT_HEADER_BYTES: u64 = 16 << 20;

/// A cache entry read in part, its light bank decoded, its verification pending.
#[derive(Debug)]
pub struct DeferredBank {
    file: File,
    buffer: Vec<u8>,
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
        let read_err = |source| BankError::Read { path: path.clone(), source };
        let len = file.metadata().map_err(read_err)?.len();
        let mut buffer = vec![
            0u8;
            usize::try_from(len)
                .map_err(|_| corrupt(BankError::Truncated { expected: 0, actual: len }))?
        ];
        let light = match light_ranges(&mut file, len) {
            Some(ranges) => {
                for (a, b) in ranges {
                    read_range(&mut file, &mut buffer[a..b], a).map_err(read_err)?;
                }
                decode_light(&buffer)
            }
            // Anything unusual: read it all, so that the decoder names the problem.
            None => {
                read_range(&mut file, &mut buffer, 0).map_err(read_err)?;
                decode_light(&buffer)
            }
        }
        .map_err(corrupt)?;
        if light.info.input_hash != key {
            return Err(corrupt(BankError::KeyMismatch { key: key.into(), found: light.info.input_hash }));
        }
        Ok((light, DeferredBank { file, buffer, path, key: key.into() }))
    }

    /// Step 2: the complete bank, checksum verified and validated — or the error
    /// [`ModeBank::from_bytes`] gives, as [`BankError::CorruptCacheEntry`]. The
    /// file is decoded straight into the bank's buffers (as by [`ModeBank::load`]);
    /// anything unusual takes `from_bytes` on the whole file for the exact error.
    pub fn finish(mut self) -> Result<ModeBank, BankError> {
        let path = self.path;
        let corrupt = |reason| BankError::CorruptCacheEntry { path: path.clone(), reason: Box::new(reason) };
        let read_err = |source| BankError::Read { path: path.clone(), source };
        drop(self.buffer);
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

/// Reads `out.len()` bytes at `offset`.
fn read_range(file: &mut File, out: &mut [u8], offset: usize) -> std::io::Result<()> {
    file.seek(SeekFrom::Start(offset as u64))?;
    file.read_exact(out)
}

/// Byte ranges of the file holding the length prefix, the header and every
/// tensor but `shapes`; `None` if the framing looks unusual in any way.
fn light_ranges(file: &mut File, len: u64) -> Option<Vec<(usize, usize)>> {
    let mut prefix = [0u8; 8];
    read_range(file, &mut prefix, 0).ok()?;
    let n = u64::from_le_bytes(prefix);
    if n > MAX_LIGHT_HEADER_BYTES || 8 + n > len {
        return None;
    }
    let mut header = vec![0u8; n as usize];
    read_range(file, &mut header, 8).ok()?;
    let json: serde_json::Map<String, serde_json::Value> = serde_json::from_slice(&header).ok()?;
    let base = 8 + n;
    let mut ranges = vec![(0, base as usize)];
    for (_, info) in json.iter().filter(|(k, _)| *k != "__metadata__" && *k != T_SHAPES) {
        let offsets = info.get("data_offsets")?;
        let (a, b) = (offsets.get(0)?.as_u64()?, offsets.get(1)?.as_u64()?);
        if a > b || base.checked_add(b)? > len {
            return None;
        }
        ranges.push(((base + a) as usize, (base + b) as usize));
    }
    Some(ranges)
}
