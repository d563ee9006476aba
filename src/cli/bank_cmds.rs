//! `modal info`, `modal retune`: commands on an existing bank (`modal export`: export.rs).

use anyhow::{Context, Result};
use modal_bank::{ModeBank, RadiationTable, RetuneSpec};

use super::args::{InfoArgs, RetuneArgs};
use super::bank_report::BankJson;
use super::interrupt;
use super::output::{print_json, warn};

/// Loads a bank and its stored acoustic transfer from one read of the file
/// (so the two always come from the same version of it), naming the file in
/// the error. A `.glb`/`.gltf` file is read as the bank of its modal model
/// (KHR_audio_rigid_bodies), warnings on stderr.
pub fn load_bank_with_radiation(path: &std::path::Path) -> Result<(ModeBank, Option<RadiationTable>)> {
    if modal_export::gltf::is_gltf_path(path) {
        let imported = modal_export::gltf::import_gltf_file(path)
            .with_context(|| format!("cannot load bank {}", path.display()))?;
        imported.warnings.iter().for_each(|w| super::output::warn(&format!("{}: {w}", path.display())));
        return Ok((imported.bank, imported.radiation));
    }
    ModeBank::load_with_radiation(path).with_context(|| format!("cannot load bank {}", path.display()))
}

fn show_with(bank: &ModeBank, radiation: Option<&RadiationTable>, json: bool) -> Result<()> {
    let report = BankJson::new(bank, false).with_radiation(radiation);
    if json {
        print_json(&report)
    } else {
        report.write_table(&mut std::io::stdout().lock())?;
        Ok(())
    }
}

pub fn info(args: InfoArgs) -> Result<()> {
    let (bank, radiation) = load_bank_with_radiation(&args.bank)?;
    show_with(&bank, radiation.as_ref(), args.json)
}

pub fn retune(args: RetuneArgs) -> Result<()> {
    let (bank, stored) = load_bank_with_radiation(&args.bank)?;
    let material_given = args.material.material.is_some()
        || args.material.youngs.is_some()
        || args.material.density.is_some()
        || args.material.poisson.is_some()
        || args.material.alpha.is_some()
        || args.material.beta.is_some();
    anyhow::ensure!(
        material_given || args.scale.is_some(),
        "nothing to retune: give --material NAME, --youngs/--density, and/or --scale S"
    );
    if let Some(gamma) = args.scale {
        let range = modal_mesh::SCALE_RANGE;
        anyhow::ensure!(
            range.contains(&gamma),
            "--scale must be a factor on every length from {:e} to {:e} (got {gamma})",
            range.start(),
            range.end()
        );
    }
    let material = material_given.then(|| retuned_material(&bank, &args)).transpose()?;
    let spec = RetuneSpec { material, scale: args.scale };
    let new = modal_bank::retune(&bank, spec.clone())?;
    if let Some(said) = emptied_band_warning(&bank, &new) {
        warn(&said);
    }
    super::prepare_output(&args.out).with_context(|| format!("cannot write bank {}", args.out.display()))?;
    let transfer = match stored {
        Some(table) => {
            let carried = modal_bank::retune_radiation(&bank, &table, &spec);
            if carried.is_none() {
                warn(&format!(
                    "the stored acoustic transfer does not carry over: E/ρ changed, so every mode sits at a new \
                     ka. Solve it again: modal radiation {0} --store {0}",
                    args.out.display()
                ));
            }
            carried
        }
        None => None,
    };
    interrupt::guarded(|| match &transfer {
        Some(table) => new.save_with_radiation(&args.out, table),
        None => new.save(&args.out),
    })
    .with_context(|| format!("cannot write bank {}", args.out.display()))?;
    show_with(&new, transfer.as_ref(), args.json)?;
    if !args.json {
        println!("wrote {}", args.out.display());
    }
    Ok(())
}

/// When a retune lowers every mode (a larger size, a softer or denser
/// material), the top of the band the bank was solved to is left empty: the
/// modes above its highest were never solved. Said when the new highest mode
/// falls below the default band's 20 kHz (a bar retuned × 2: 21 modes ending
/// at 9.83 kHz, where a new solve fills the band to 15.6 kHz and beyond).
fn emptied_band_warning(old: &ModeBank, new: &ModeBank) -> Option<String> {
    let (&was, &now) = (old.frequencies_hz.last()?, new.frequencies_hz.last()?);
    if !(now < was && now < modal_precompute::DEFAULT_MAX_FREQ_HZ) {
        return None;
    }
    Some(format!(
        "every mode moved down × {:.3}: the bank now ends at {} (was {}); modes the solve left above {} were \
         never solved, so nothing rings above {} — precompute the retuned object to fill the band",
        now / was,
        hz(now),
        hz(was),
        hz(was),
        hz(now)
    ))
}

/// A frequency in Hz or kHz, 3 significant figures.
fn hz(f: f64) -> String {
    if f >= 1000.0 {
        format!("{:.3} kHz", f / 1000.0)
    } else {
        format!("{f:.1} Hz")
    }
}

/// The new material: a preset, or the bank's own with the given values replaced.
fn retuned_material(bank: &ModeBank, args: &RetuneArgs) -> Result<modal_fem::Material> {
    let m = &args.material;
    let mut material = match &m.material {
        Some(name) => modal_fem::Material::preset(name)?,
        None => modal_fem::Material { name: None, ..bank.material.clone() },
    };
    material.youngs_pa = m.youngs.unwrap_or(material.youngs_pa);
    material.poisson = m.poisson.unwrap_or(material.poisson);
    material.density_kg_m3 = m.density.unwrap_or(material.density_kg_m3);
    material.alpha = m.alpha.unwrap_or(material.alpha);
    material.beta = m.beta.unwrap_or(material.beta);
    material.validate()?;
    if m.poisson.is_some() {
        // Asked for by name: a ν the bank does not have is the library's error.
        return Ok(material);
    }
    // A preset's ν (README: "new E, rho (same nu)"): the bank's is kept, and said.
    let (material, asked) = modal_bank::keeping_poisson(bank, material);
    if let Some(asked) = asked {
        warn(&poisson_kept_warning(bank, &material, asked));
    }
    Ok(material)
}

/// The warning when a retune to `material` kept `bank`'s Poisson's ratio
/// instead of the `asked` one: what a new solve would change, at most.
pub fn poisson_kept_warning(bank: &ModeBank, material: &modal_fem::Material, asked: f64) -> String {
    let kept = bank.material.poisson;
    let name = material.name.as_deref().map_or("the material", |n| n.trim_end_matches("+custom"));
    format!(
        "{name}'s Poisson's ratio {asked} is not the bank's {kept}: kept {kept} (a retune scales E and ρ; \
         a new ν changes the mode shapes and needs a new solve, which would move the frequencies by up to \
         {:.1} %)",
        100.0 * modal_bank::poisson_shift(kept, asked)
    )
}
