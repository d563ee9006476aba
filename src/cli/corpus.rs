//! `modal mesh corpus --out DIR`: write the generated corpus of real-world-like
//! surface assets (see `modal_tetra::corpus`) as OBJ files, one per asset.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;

use super::output::print_json;

/// Arguments of `modal mesh corpus`.
#[derive(Debug, Args)]
pub struct CorpusArgs {
    /// Directory to write `<name>.obj` files into (created if missing).
    #[arg(short, long)]
    pub out: PathBuf,
    /// Write only this asset (default: all of them).
    #[arg(long, value_name = "NAME")]
    pub name: Option<String>,
    /// Print a JSON list of the files written on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Writes the corpus (or one asset of it).
pub fn run(args: CorpusArgs) -> Result<()> {
    use modal_tetra::corpus::{asset, ASSETS};
    let selected: Vec<_> =
        ASSETS.iter().filter(|a| args.name.as_deref().is_none_or(|n| n == a.name)).collect();
    if selected.is_empty() {
        let names: Vec<&str> = ASSETS.iter().map(|a| a.name).collect();
        bail!(
            "no corpus asset named {:?}; the corpus has: {}",
            args.name.unwrap_or_default(),
            names.join(", ")
        );
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut written = Vec::new();
    for info in selected {
        let surface = asset(info.name).with_context(|| format!("corpus asset {} is missing", info.name))?;
        let path = args.out.join(format!("{}.obj", info.name));
        super::write_buffered(&path, |file| modal_tetra::write_obj(&surface, file))?;
        if !args.json {
            println!(
                "wrote {} ({} triangles): {}",
                path.display(),
                surface.triangles.len(),
                info.description
            );
        }
        written.push(serde_json::json!({
            "name": info.name,
            "path": path.display().to_string(),
            "triangles": surface.triangles.len(),
            "description": info.description,
            "odd": info.odd,
        }));
    }
    if args.json {
        print_json(&written)?;
    }
    Ok(())
}
