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
mod files;
mod interrupt;
mod listener;
mod material;
mod mesh;
mod output;
mod precompute;
mod progress;
mod radiation;
mod render;
mod scene_warnings;
mod strike;

use std::process::ExitCode;

use clap::Parser;

pub use args::{Cli, Command};
pub use files::{
    buffered, check_not_input, directory_of, prepare_output, write_atomic, write_atomic_all, write_buffered,
};

/// Parses the command line, runs the command and maps the outcome to an exit code.
pub fn run() -> ExitCode {
    // `--json` is a flag of every command that has it, never an option's value.
    let json = std::env::args_os().any(|a| a == "--json");
    let cli = Cli::try_parse().unwrap_or_else(|err| malformed(err, json));
    interrupt::install(json);
    match dispatch(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) if output::is_broken_pipe(&err) => ExitCode::SUCCESS,
        Err(err) => {
            files::remove_made_directories();
            output::print_error(&err, json);
            ExitCode::from(1)
        }
    }
}

/// A command line clap refuses (exit code 2), or `--help`/`--version`.
/// With `--json`, stdout also holds `{"error": "…"}` (the first line of
/// clap's message), as for every other error: a script reads one object.
fn malformed(err: clap::Error, json: bool) -> ! {
    use clap::error::ErrorKind;
    let shown = matches!(
        err.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    );
    if json && !shown {
        let text = err.render().to_string();
        let line = text.lines().next().unwrap_or_default().trim_start_matches("error: ").to_string();
        println!("{}", serde_json::json!({ "error": line }));
    }
    err.exit()
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
