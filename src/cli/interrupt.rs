//! Ctrl-C never leaves a temporary or partial output file behind.
//!
//! Outputs are written atomically (temporary file + rename) by the library
//! crates. An interrupt that arrives while no file is being written ends the
//! process at once (exit code 130); one that arrives during a write lets
//! that short write finish (so its temporary file is renamed or removed) and
//! ends the process right after it. The writes counted are the CLI's own
//! ([`guarded`]) and every library write through
//! `modal_bank::write_file_atomically` (banks, cache entries, catalogues,
//! written by a batch between its own steps), which refuses to start once
//! the interrupt came.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering::SeqCst};

static WRITES_IN_PROGRESS: AtomicUsize = AtomicUsize::new(0);
static INTERRUPTED: AtomicBool = AtomicBool::new(false);
/// The command was given `--json`: its stdout holds one object, an error too.
static JSON: AtomicBool = AtomicBool::new(false);

fn exit_interrupted() -> ! {
    super::files::remove_made_directories();
    eprintln!("error: interrupted");
    if JSON.load(SeqCst) && !super::output::json_printed() {
        println!("{}", serde_json::json!({ "error": "interrupted" }));
    }
    std::process::exit(130)
}

/// How long the handler waits for writes under way before it ends the
/// process anyway (a write stuck on a dead network file system).
const WRITE_WAIT: std::time::Duration = std::time::Duration::from_secs(30);

/// Installs the SIGINT/SIGTERM handler (once, at start-up); `json`: the
/// command prints JSON, so an interrupt is `{"error": "interrupted"}` there.
pub fn install(json: bool) {
    JSON.store(json, SeqCst);
    // If a handler cannot be installed, Ctrl-C keeps its default behaviour.
    // The handler runs on its own thread, so it can wait for the writes.
    let _ = ctrlc::set_handler(|| {
        INTERRUPTED.store(true, SeqCst);
        modal_bank::request_stop();
        let start = std::time::Instant::now();
        while modal_bank::writes_in_progress() > 0 && start.elapsed() < WRITE_WAIT {
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        if WRITES_IN_PROGRESS.load(SeqCst) == 0 {
            exit_interrupted();
        }
    });
}

/// True once an interrupt came: a write under way keeps its output only
/// if it was renamed into place before.
pub fn stopping() -> bool {
    INTERRUPTED.load(SeqCst)
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
