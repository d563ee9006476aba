//! `--material` and the explicit `--youngs/--poisson/--density/--alpha/--beta` flags.

use anyhow::Result;
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
    let resolved = Material::resolve(args.material.as_deref(), &overrides).map_err(|e| match e {
        // Only a missing value needs the usage; an impossible one says all (once).
        modal_fem::MaterialError::Missing(_) => {
            anyhow::anyhow!("{e} (use --material NAME, or all of --youngs PA --poisson NU --density KG_M3)")
        }
        other => anyhow::Error::new(other),
    })?;
    let mut warnings = Vec::new();
    if resolved.damping_defaulted_to_zero {
        warnings.push("no damping given (--alpha/--beta): Rayleigh damping is 0, modes ring forever".into());
    }
    Ok((resolved.material, warnings))
}
