//! Shared output helpers: error lines, warnings, JSON, progress.

/// Prints an error and its cause chain as one line on stderr.
pub fn print_error(err: &anyhow::Error, json: bool) {
    let mut line = err.to_string();
    for cause in err.chain().skip(1) {
        let text = cause.to_string();
        // Contexts often repeat their cause; print each distinct part once.
        if text.starts_with(&line) {
            line = text; // the cause already opens with the context (a file name)
        } else if !line.contains(&text) {
            line.push_str(": ");
            line.push_str(&text);
        }
    }
    let line = line.replace('\n', " ");
    eprintln!("error: {line}");
    if json && !json_printed() {
        // A script reading the JSON on stdout gets the failure there too.
        println!("{}", serde_json::json!({ "error": line }));
    }
}

/// Prints a warning on stderr (never on stdout, which may hold JSON).
pub fn warn(message: &str) {
    eprintln!("warning: {message}");
}

/// True when the error is a closed stdout (e.g. `modal info … | head`).
pub fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|cause| {
        cause.downcast_ref::<std::io::Error>().is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// Whether a JSON document went to stdout (a batch's report precedes its
/// failure exit): the error is then not printed as a second document.
static JSON_PRINTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// True once a JSON document went to stdout.
pub fn json_printed() -> bool {
    JSON_PRINTED.load(std::sync::atomic::Ordering::SeqCst)
}

/// Prints `value` as one JSON document on stdout.
pub fn print_json(value: &impl serde::Serialize) -> anyhow::Result<()> {
    use std::io::Write;
    JSON_PRINTED.store(true, std::sync::atomic::Ordering::SeqCst);
    let mut out = std::io::stdout().lock();
    serde_json::to_writer_pretty(&mut out, value)?;
    writeln!(out)?;
    Ok(())
}
