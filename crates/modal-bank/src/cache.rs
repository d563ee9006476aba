//! A content-addressed store of banks: `<dir>/<key>.bank`, one file per key.
//!
//! Keys come from [`crate::CacheKey`] (64 lowercase hex digits) and must equal
//! the stored bank's `info.input_hash`, so a bank is only ever served for the
//! inputs it was solved from (a retuned bank, whose hash is `retuned:…`,
//! cannot be stored). Writes are atomic (temporary file + rename), so
//! concurrent writers of one key are safe and readers never see partial files.
//! A damaged entry is reported as [`BankError::CorruptCacheEntry`], never served.
//!
//! Shared caches (many processes, several machines, a network file system):
//! no locks are taken. The temporary file is created in the cache directory
//! itself with a unique name and flushed (`fsync`) before the rename, and a
//! rename within one directory is atomic on POSIX file systems, NFS
//! included, so two writers of one key each publish a complete file (the same
//! bytes up to the solve timings) and the last rename wins. Whatever still
//! goes wrong — a torn copy, a crash on a file system without atomic rename,
//! bit rot, a stale NFS handle — fails the bank's SHA-256 checksum, the key
//! check or the read, and the caller recomputes and `put`s over it
//! (`modal-precompute` does).

use crate::fsio::{atomic_write, decode_open_file, open_regular};
use crate::DeferredBank;
use crate::{BankError, ModeBank};
use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// Environment variable overriding the cache directory.
pub const CACHE_DIR_ENV: &str = "MODAL_CACHE_DIR";

/// A directory of cached banks.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BankCache {
    dir: PathBuf,
}

impl BankCache {
    /// A cache in `dir` (created on the first `put`).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        BankCache { dir: dir.into() }
    }

    /// The default directory: `$MODAL_CACHE_DIR`, else
    /// `$XDG_CACHE_HOME/modal` (when set to an absolute path), else
    /// `$HOME/.cache/modal`. Empty variables count as unset.
    pub fn default_dir() -> Result<PathBuf, BankError> {
        let var = std::env::var_os;
        default_dir_from(var(CACHE_DIR_ENV), var("XDG_CACHE_HOME"), var("HOME"))
    }

    /// The cache directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The file of the entry `key`.
    pub fn path_for(&self, key: &str) -> Result<PathBuf, BankError> {
        check_key(key)?;
        Ok(self.dir.join(format!("{key}.bank")))
    }

    /// The bank stored under `key`: `Ok(None)` when there is none,
    /// `Err(CorruptCacheEntry)` when the entry exists but is damaged or was
    /// written for another key (warn, recompute, `put` over it).
    pub fn get(&self, key: &str) -> Result<Option<ModeBank>, BankError> {
        let path = self.path_for(key)?;
        let Some(mut file) = open_entry(&path)? else { return Ok(None) };
        let loaded = decode_open_file(&mut file, &path)?;
        checked_entry(loaded, &path, key).map(Some)
    }

    /// [`Self::get`] in two steps (see [`DeferredBank`]): `Ok(None)` when there
    /// is no entry; otherwise the light bank (no shapes, not yet verified) and
    /// the pending rest, whose [`DeferredBank::finish`] verifies everything and
    /// reports a damaged entry as [`BankError::CorruptCacheEntry`].
    pub fn get_deferred(&self, key: &str) -> Result<Option<(ModeBank, DeferredBank)>, BankError> {
        let path = self.path_for(key)?;
        let Some(file) = open_entry(&path)? else { return Ok(None) };
        DeferredBank::open(file, path, key).map(Some)
    }

    /// Stores `bank` under `key` atomically, replacing any previous entry.
    /// `bank.info.input_hash` must equal `key`.
    pub fn put(&self, key: &str, bank: &ModeBank) -> Result<(), BankError> {
        let path = self.path_for(key)?;
        if bank.info.input_hash != key {
            return Err(BankError::KeyMismatch { key: key.into(), found: bank.info.input_hash.clone() });
        }
        let bytes = bank.to_bytes()?;
        std::fs::create_dir_all(&self.dir)
            .map_err(|source| BankError::Write { path: self.dir.clone(), source })?;
        atomic_write(&path, |w| w.write_all(&bytes))
    }

    /// Deletes the entry `key`; `Ok(false)` when there was none.
    pub fn remove(&self, key: &str) -> Result<bool, BankError> {
        let path = self.path_for(key)?;
        match std::fs::remove_file(&path) {
            Ok(()) => Ok(true),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(false),
            Err(source) => Err(BankError::Write { path, source }),
        }
    }
}

fn check_key(key: &str) -> Result<(), BankError> {
    let hex = key.len() == 64 && key.bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b));
    if hex {
        Ok(())
    } else {
        Err(BankError::InvalidCacheKey(key.into()))
    }
}

/// [`BankCache::default_dir`] from explicit variable values (testable
/// without touching the process environment).
pub fn default_dir_from(
    modal_cache_dir: Option<OsString>,
    xdg_cache_home: Option<OsString>,
    home: Option<OsString>,
) -> Result<PathBuf, BankError> {
    let set = |v: Option<OsString>| v.filter(|v| !v.is_empty()).map(PathBuf::from);
    if let Some(dir) = set(modal_cache_dir) {
        return Ok(dir);
    }
    if let Some(xdg) = set(xdg_cache_home).filter(|p| p.is_absolute()) {
        return Ok(xdg.join("modal"));
    }
    set(home).map(|h| h.join(".cache").join("modal")).ok_or(BankError::NoCacheDir)
}

/// The entry file at `path`, `None` when it does not exist.
fn open_entry(path: &Path) -> Result<Option<std::fs::File>, BankError> {
    match open_regular(path) {
        Ok(file) => Ok(Some(file)),
        Err(BankError::Read { source, .. }) if source.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(e),
    }
}

/// A cache entry's bank as decoded (`loaded`) if it is sound and was stored
/// for `key`; otherwise [`BankError::CorruptCacheEntry`] with the reason.
pub(crate) fn checked_entry(
    loaded: Result<ModeBank, BankError>,
    path: &Path,
    key: &str,
) -> Result<ModeBank, BankError> {
    let corrupt =
        |reason| BankError::CorruptCacheEntry { path: path.to_path_buf(), reason: Box::new(reason) };
    let bank = loaded.map_err(corrupt)?;
    if bank.info.input_hash != key {
        return Err(corrupt(BankError::KeyMismatch { key: key.into(), found: bank.info.input_hash }));
    }
    Ok(bank)
}
