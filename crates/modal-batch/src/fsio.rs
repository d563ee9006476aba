//! Atomic file writes through [`modal_bank::write_file_atomically`]: readers
//! (and other shards writing beside us on a shared file system) see the old
//! file or the complete new one, never a partial one.

use std::io::Write;
use std::path::Path;

use crate::BatchError;

/// Writes `bytes` to `path` atomically, creating its directory.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), BatchError> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)
        .and_then(|()| modal_bank::write_file_atomically(path, |file| file.write_all(bytes)))
        .map_err(|source| BatchError::Write { path: path.display().to_string(), source })
}
