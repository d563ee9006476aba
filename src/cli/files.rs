//! Output files: made ready before the work ([`prepare_output`]: its
//! directory made, a file probed there), written atomically
//! ([`write_atomic`], [`write_atomic_all`] for a set that must appear
//! whole), and on failure nothing left behind: no temporary file, and no
//! directory this run made that stayed empty ([`remove_made_directories`]).

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use super::interrupt;

/// Directories [`prepare_output`] made in this run, deepest first.
static MADE_DIRECTORIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Removes the directories this run made that are still empty, deepest
/// first (a failed or interrupted run: an output directory it made for a
/// file it then did not write).
pub fn remove_made_directories() {
    let made = MADE_DIRECTORIES.lock().map(|mut m| std::mem::take(&mut *m)).unwrap_or_default();
    for dir in made {
        // Fails, and is meant to, on a directory that holds anything.
        let _ = std::fs::remove_dir(&dir);
    }
}

/// Makes sure, before any long work, that `path` can be written the way
/// [`write_atomic`] (or a library's atomic writer) will write it: `path` is
/// not a directory, its directory exists (missing directories are created,
/// as `precompute-batch` and `export-matrices` create theirs) and takes a new
/// file (a probe file is created there and removed). So a solve of minutes
/// never ends in "cannot write".
pub fn prepare_output(path: &Path) -> anyhow::Result<()> {
    let dir = directory_of(path);
    anyhow::ensure!(!path.is_dir(), "{} is a directory", path.display());
    // An output replaces its path by a rename: `-o /dev/null` as root would
    // replace the device with a file (a FIFO was). Only files are outputs.
    if let Ok(meta) = std::fs::metadata(path) {
        anyhow::ensure!(
            meta.is_file(),
            "{} is not a regular file (a device or a pipe): outputs are written to a temporary file and renamed \
             over their path, which would replace it; give a file path",
            path.display()
        );
    }
    let name = path.file_name().ok_or_else(|| anyhow::anyhow!("{} is not a file name", path.display()))?;
    if !dir.is_dir() {
        let missing: Vec<PathBuf> = dir
            .ancestors()
            .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
            .map(Path::to_path_buf)
            .collect();
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("cannot create directory {}: {e}", dir.display()))?;
        if let Ok(mut made) = MADE_DIRECTORIES.lock() {
            made.extend(missing);
        }
    }
    let probe = dir.join(format!(".{}.{}.probe", name.to_string_lossy(), std::process::id()));
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .map_err(|e| anyhow::anyhow!("cannot write in {}: {e}", dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// The directory a file `path` is in (`.` for a bare name).
pub fn directory_of(path: &Path) -> &Path {
    path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."))
}

/// Refuses an output `out` (given as `flag`) that is the input file
/// `input` itself (the same file, through any path, link or hard link): the
/// write would replace what the command reads, a bank by a WAV, a mesh by a
/// bank. Commands that update a file in place on purpose (`retune`,
/// `radiation --store`) do not call this.
pub fn check_not_input(out: &Path, input: &Path, flag: &str) -> anyhow::Result<()> {
    anyhow::ensure!(
        !same_file(out, input),
        "{flag} {} is the input file itself: writing there would destroy it; give the output its own name",
        out.display()
    );
    Ok(())
}

/// Whether `a` and `b` name one existing file.
fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) else { return false };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        ma.dev() == mb.dev() && ma.ino() == mb.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (ma, mb);
        matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
    }
}

/// Writes a file atomically: `write` fills a temporary file next to `path`,
/// which is then renamed over `path`. On any error the temporary file is
/// removed, so a failed or interrupted command never leaves a partial output.
pub fn write_atomic(path: &Path, write: impl FnOnce(&Path) -> anyhow::Result<()>) -> anyhow::Result<()> {
    write_atomic_all(vec![(path, Box::new(write))])
}

/// [`write_atomic`] of a file filled through a buffer ([`buffered`]); the
/// error names the file.
pub fn write_buffered(
    path: &Path,
    fill: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> anyhow::Result<()> {
    use anyhow::Context;
    write_atomic_all(vec![(path, buffered(fill))]).with_context(|| format!("cannot write {}", path.display()))
}

/// How one file of [`write_atomic_all`] is filled (given its temporary path).
pub type FileWriter<'a> = Box<dyn FnOnce(&Path) -> anyhow::Result<()> + 'a>;

/// The [`FileWriter`] that creates the file and fills it through a buffer.
pub fn buffered<'a>(
    fill: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()> + 'a,
) -> FileWriter<'a> {
    Box::new(move |tmp: &Path| {
        let mut file = std::io::BufWriter::new(std::fs::File::create(tmp)?);
        fill(&mut file)?;
        std::io::Write::flush(&mut file)?;
        Ok(())
    })
}

/// Writes several files as one output (export-matrices' K, M and nodes):
/// each into a temporary file next to it, then all renamed together once
/// every one is complete, and none if the program was interrupted
/// meanwhile. On any error every temporary file is removed, so the set is
/// there whole or not at all.
pub fn write_atomic_all(files: Vec<(&Path, FileWriter<'_>)>) -> anyhow::Result<()> {
    let mut written: Vec<(PathBuf, &Path)> = Vec::with_capacity(files.len());
    interrupt::guarded(|| {
        let result = (|| {
            for (path, write) in files {
                let dir = directory_of(path);
                let name = path
                    .file_name()
                    .ok_or_else(|| anyhow::anyhow!("{} is not a file name", path.display()))?;
                let tmp = dir.join(format!(".{}.{}.tmp", name.to_string_lossy(), std::process::id()));
                written.push((tmp.clone(), path));
                write(&tmp)?;
            }
            anyhow::ensure!(!interrupt::stopping(), "interrupted");
            for (tmp, path) in &written {
                std::fs::rename(tmp, path)?;
            }
            Ok(())
        })();
        if result.is_err() {
            written.iter().for_each(|(tmp, _)| drop(std::fs::remove_file(tmp)));
        }
        result
    })
}
