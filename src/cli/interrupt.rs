//! Ctrl-C never leaves a temporary or partial output file behind.
//!
//! Outputs are written atomically (temporary file + rename) by the library
//! crates. An interrupt that arrives while no file is being written ends the
//! process at once (exit code 130); one that arrives during a write lets
//! that short write finish (so its temporary file is renamed or removed) and
//! ends the process right after it.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering::SeqCst};

static WRITES_IN_PROGRESS: AtomicUsize = AtomicUsize::new(0);
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

fn exit_interrupted() -> ! {
    eprintln!("error: interrupted");
    std::process::exit(130)
}

/// Installs the SIGINT/SIGTERM handler (once, at start-up).
pub fn install() {
    // If a handler cannot be installed, Ctrl-C keeps its default behaviour.
    let _ = ctrlc::set_handler(|| {
        INTERRUPTED.store(true, SeqCst);
        if WRITES_IN_PROGRESS.load(SeqCst) == 0 {
            exit_interrupted();
        }
    });
}

/// Runs `write` (which creates an output file atomically) so that an
/// interrupt cannot cut it short.
pub fn guarded<T>(write: impl FnOnce() -> T) -> T {
    WRITES_IN_PROGRESS.fetch_add(1, SeqCst);
    if INTERRUPTED.load(SeqCst) {
        exit_interrupted();
    }
    let result = write();
    WRITES_IN_PROGRESS.fetch_sub(1, SeqCst);
    if INTERRUPTED.load(SeqCst) {
        exit_interrupted();
    }
    result
}
