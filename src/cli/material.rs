//! `--material` and the explicit `--youngs/--poisson/--density/--alpha/--beta` flags.

use anyhow::{Context, Result};
use modal_fem::{Material, MaterialOverrides};

use super::args::MaterialArgs;

/// The material the flags describe, and warnings about it (e.g. no damping).
pub fn resolve(args: &MaterialArgs) -> Result<(Material, Vec<String>)> {
    let overrides = MaterialOverrides {
        youngs: args.youngs,
        poisson: args.poisson,
        density: args.density,
        alpha: args.alpha,
        beta: args.beta,
    };
    let resolved = Material::resolve(args.material.as_deref(), &overrides).context(
        "invalid material (use --material NAME, or all of --youngs PA --poisson NU --density KG_M3)",
    )?;
    let mut warnings = Vec::new();
    if resolved.damping_defaulted_to_zero {
        warnings.push("no damping given (--alpha/--beta): Rayleigh damping is 0, modes ring forever".into());
    }
    Ok((resolved.material, warnings))
}
