//! `modal`: turn a 3D object into its sound. The binary only parses arguments
//! and reports; all work happens in the library crates under `crates/`.

mod cli;

fn main() -> std::process::ExitCode {
    cli::run()
}
