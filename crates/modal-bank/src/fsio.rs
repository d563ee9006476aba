//! Files: atomic writes (temporary file in the destination's directory, then
//! rename) and bank save/load.
//!
//! A rename within one directory is atomic on POSIX file systems, so readers
//! see either the old file or the complete new one, concurrent writers of the
//! same path each publish a complete file, and a failed write leaves nothing
//! behind (the temporary file is deleted on drop).
//!
//! A process ended while a write is under way (`exit` runs no destructor)
//! would leave the temporary file. So the writes in progress are counted,
//! and a program that stops on a signal first calls [`request_stop`]: no
//! write starts after it, none under way is renamed into place, and the
//! program ends once [`writes_in_progress`] is zero (the CLI's SIGINT/SIGTERM
//! handler).

use crate::{BankError, ModeBank};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering::SeqCst};

static WRITES_IN_PROGRESS: AtomicUsize = AtomicUsize::new(0);
static STOP_REQUESTED: AtomicBool = AtomicBool::new(false);

/// Refuses every atomic write that has not started yet (it fails with
/// [`std::io::ErrorKind::Interrupted`]); the ones under way finish their
/// temporary file, which is then removed instead of renamed into place.
pub fn request_stop() {
    STOP_REQUESTED.store(true, SeqCst);
}

/// Atomic writes under way in this process.
pub fn writes_in_progress() -> usize {
    WRITES_IN_PROGRESS.load(SeqCst)
}

/// Counts one write while it lives.
struct WriteInProgress;

impl WriteInProgress {
    /// `None` once a stop was requested.
    fn start() -> Option<WriteInProgress> {
        WRITES_IN_PROGRESS.fetch_add(1, SeqCst);
        if STOP_REQUESTED.load(SeqCst) {
            WRITES_IN_PROGRESS.fetch_sub(1, SeqCst);
            return None;
        }
        Some(WriteInProgress)
    }
}

impl Drop for WriteInProgress {
    fn drop(&mut self) {
        WRITES_IN_PROGRESS.fetch_sub(1, SeqCst);
    }
}

/// Writes `path` atomically: `write` fills a temporary file in the same
/// directory (which must exist: a typo in a path is an error, not a new
/// directory), which is flushed to disk and then renamed
/// over `path`. Readers and concurrent writers of the same path (shards on a
/// shared file system) see the old file or a complete new one, never a partial
/// one; on error nothing is left behind. The one place every crate writes
/// outputs through (banks, catalogues, WAVs).
pub fn write_file_atomically(
    path: &Path,
    write: impl FnOnce(&mut std::fs::File) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let Some(_counted) = WriteInProgress::start() else {
        return Err(std::io::Error::new(std::io::ErrorKind::Interrupted, "the program is stopping"));
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let prefix = format!(".{}.", path.file_name().map_or("out".into(), |n| n.to_string_lossy()));
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    // Like a plain `File::create`: 0o666 minus the umask, not tempfile's 0o600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut tmp = builder.tempfile_in(&dir)?;
    write(tmp.as_file_mut())?;
    tmp.as_file().sync_all()?;
    if STOP_REQUESTED.load(SeqCst) {
        // Stopped while it was written: the file is complete but the command
        // is not (a strike of an hour cut at 2 s was left whole, then said
        // "interrupted"). Nothing is left behind; the temporary file goes.
        return Err(std::io::Error::new(std::io::ErrorKind::Interrupted, "the program is stopping"));
    }
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// [`write_file_atomically`] through a buffered sink, errors as [`BankError::Write`].
pub(crate) fn atomic_write(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), BankError> {
    write_file_atomically(path, |file| {
        let mut w = BufWriter::new(file);
        write(&mut w)?;
        w.flush()
    })
    .map_err(|source| BankError::Write { path: path.to_path_buf(), source })
}

fn is_file(f: &std::fs::File) -> bool {
    f.metadata().is_ok_and(|m| m.is_file())
}

/// The whole content of the open file `file` (named `path` in I/O errors), from its start.
pub(crate) fn read_whole(file: &mut std::fs::File, path: &Path) -> Result<Vec<u8>, BankError> {
    use std::io::{Read, Seek, SeekFrom};
    let read_err = |source| BankError::Read { path: path.to_path_buf(), source };
    let mut bytes = Vec::new();
    file.seek(SeekFrom::Start(0)).map_err(read_err)?;
    file.read_to_end(&mut bytes).map_err(read_err)?;
    Ok(bytes)
}

impl ModeBank {
    /// Validates and writes the bank to `path` atomically (temporary file in
    /// the same directory, then rename; nothing is left behind on error).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), BankError> {
        let bytes = self.to_bytes()?;
        atomic_write(path.as_ref(), |w| w.write_all(&bytes))
    }

    /// Validates and writes the bank with its radiation table to `path`
    /// atomically (see [`ModeBank::save`]).
    pub fn save_with_radiation(
        &self,
        path: impl AsRef<Path>,
        table: &crate::RadiationTable,
    ) -> Result<(), BankError> {
        let bytes = self.to_bytes_with_radiation(table)?;
        atomic_write(path.as_ref(), |w| w.write_all(&bytes))
    }

    /// Reads the bank at `path` and its radiation table, if it has one.
    pub fn load_with_radiation(
        path: impl AsRef<Path>,
    ) -> Result<(ModeBank, Option<crate::RadiationTable>), BankError> {
        let path = path.as_ref();
        let bytes = read_whole(&mut open_regular(path)?, path)?;
        ModeBank::from_bytes_with_radiation(&bytes)
    }

    /// Reads, verifies (format, version, checksum, shapes) and validates the
    /// bank at `path`. Content errors do not repeat the path; I/O errors do.
    pub fn load(path: impl AsRef<Path>) -> Result<ModeBank, BankError> {
        read_bank(path.as_ref())?
    }
}

/// Opens the regular file at `path` (I/O errors and non-files name the path).
pub(crate) fn open_regular(path: &Path) -> Result<std::fs::File, BankError> {
    let file =
        std::fs::File::open(path).map_err(|source| BankError::Read { path: path.to_path_buf(), source })?;
    if !is_file(&file) {
        return Err(BankError::NotAFile { path: path.to_path_buf() });
    }
    Ok(file)
}

/// Reads and decodes the bank file at `path`: the outer error is about
/// reading the file (missing, not a file, I/O), the inner one about its
/// content (format, checksum, validation).
pub(crate) fn read_bank(path: &Path) -> Result<Result<ModeBank, BankError>, BankError> {
    decode_open_file(&mut open_regular(path)?, path)
}

/// Decodes the open bank file `file` (named `path` in I/O errors) from its
/// start, straight into the bank's buffers (`format::decode_file`); anything
/// unusual takes the whole file through [`ModeBank::from_bytes`], which gives
/// the exact error. Outer error: I/O; inner: content.
pub(crate) fn decode_open_file(
    file: &mut std::fs::File,
    path: &Path,
) -> Result<Result<ModeBank, BankError>, BankError> {
    use std::io::{Seek, SeekFrom};
    file.seek(SeekFrom::Start(0)).map_err(|source| BankError::Read { path: path.to_path_buf(), source })?;
    if let Some(bank) = crate::format::decode_file(file) {
        return Ok(Ok(bank));
    }
    Ok(ModeBank::from_bytes(&read_whole(file, path)?))
}
