//! Progress display on stderr (hidden automatically when stderr is not a terminal).

use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

/// A spinner with a message that commands update as stages advance.
pub struct Spinner {
    bar: ProgressBar,
}

impl Spinner {
    /// Starts a spinner; it only appears after the work has run for a moment.
    pub fn new(message: &str) -> Self {
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.set_message(message.to_string());
        bar.enable_steady_tick(Duration::from_millis(120));
        Spinner { bar }
    }

    /// Replaces the message.
    pub fn set(&self, message: impl Into<String>) {
        self.bar.set_message(message.into());
    }

    /// Replaces the message and, when stderr is not a terminal (a log,
    /// where the spinner is hidden), also prints it as a line: a stage that
    /// may take minutes stays visible there.
    pub fn milestone(&self, message: impl Into<String>) {
        let message = message.into();
        if !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
            self.bar.suspend(|| eprintln!("{message}"));
        }
        self.bar.set_message(message);
    }

    /// Prints a line on stderr above the spinner (progress that should
    /// stay visible, also when stderr is not a terminal).
    pub fn note(&self, line: &str) {
        self.bar.suspend(|| eprintln!("{line}"));
    }

    /// Removes the spinner from the terminal.
    pub fn finish(self) {
        self.bar.finish_and_clear();
    }
}
