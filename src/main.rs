//! `modal`: turn a 3D object into its sound. The binary only parses arguments
//! and reports; all work happens in the library crates under `crates/`.

mod alloc;
mod cli;

#[global_allocator]
static ALLOCATOR: alloc::HugePageAlloc = alloc::HugePageAlloc;

fn main() -> std::process::ExitCode {
    cli::run()
}
