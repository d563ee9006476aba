//! Command-line interface: one module per subcommand. Results go to stdout
//! (or JSON with `--json`), progress and warnings to stderr, errors as one
//! line `error: …` with a non-zero exit code.

mod args;
mod bank_cmds;
mod bank_report;
mod batch;
mod bench;
mod catalogue;
mod corpus;
mod export;
mod interrupt;
mod listener;
mod material;
mod mesh;
mod output;
mod precompute;
mod progress;
mod radiation;
mod render;
mod strike;

use std::path::Path;
use std::process::ExitCode;

use clap::Parser;

pub use args::{Cli, Command};

/// Parses the command line, runs the command and maps the outcome to an exit code.
pub fn run() -> ExitCode {
    let cli = Cli::parse();
    // `--json` is a flag of every command that has it, never an option's value.
    let json = std::env::args_os().any(|a| a == "--json");
    interrupt::install();
    match dispatch(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) if output::is_broken_pipe(&err) => ExitCode::SUCCESS,
        Err(err) => {
            output::print_error(&err, json);
            ExitCode::from(1)
        }
    }
}

fn dispatch(cli: Cli) -> anyhow::Result<()> {
    if matches!(cli.command, None | Some(Command::Render(_)) | Some(Command::Strike(_))) {
        crate::alloc::advise_huge_pages();
    }
    match cli.command {
        None => render::run(args::RenderArgs::default()),
        Some(Command::Precompute(args)) => precompute::run(args),
        Some(Command::ExportMatrices(args)) => precompute::export_matrices(args),
        Some(Command::PrecomputeBatch(args)) => batch::run(args),
        Some(Command::Catalogue(command)) => catalogue::run(command),
        Some(Command::Info(args)) => bank_cmds::info(args),
        Some(Command::Retune(args)) => bank_cmds::retune(args),
        Some(Command::Export(args)) => export::run(args),
        Some(Command::Mesh(args)) => mesh::run(args.shape),
        Some(Command::Strike(args)) => strike::run(args),
        Some(Command::Render(args)) => render::run(args),
        Some(Command::Bench(command)) => bench::run(command),
        Some(Command::Radiation(args)) => radiation::run(args),
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
    let name = path.file_name().ok_or_else(|| anyhow::anyhow!("{} is not a file name", path.display()))?;
    if !dir.is_dir() {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("cannot create directory {}: {e}", dir.display()))?;
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
    let dir = directory_of(path);
    let name = path.file_name().ok_or_else(|| anyhow::anyhow!("{} is not a file name", path.display()))?;
    let tmp = dir.join(format!(".{}.{}.tmp", name.to_string_lossy(), std::process::id()));
    interrupt::guarded(|| {
        let result = write(&tmp).and_then(|()| std::fs::rename(&tmp, path).map_err(Into::into));
        if result.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        result
    })
}
