//! `modal precompute` and `modal export-matrices`.

use std::path::Path;

use anyhow::{Context, Result};
use modal_bank::BankCache;
use modal_precompute::{MeshSource, Request, Stage, SurfaceMeshing};

use super::args::{ExportMatricesArgs, MaterialArgs, MeshInputArgs, PrecomputeArgs};
use super::bank_report::BankJson;
use super::interrupt;
use super::output::{print_json, warn};
use super::progress::Spinner;
use super::{buffered, material, write_atomic_all};

/// Builds a pipeline request from the shared mesh and material flags.
fn request(mesh: &Path, material_args: &MaterialArgs, input: &MeshInputArgs) -> Result<Request> {
    let (material, warnings) = material::resolve(material_args)?;
    warnings.iter().for_each(|w| warn(w));
    let mut request = Request::new(MeshSource::File(mesh.to_path_buf()), material);
    request.scale = input.scale.unwrap_or(1.0);
    request.scale_stated = input.scale.is_some();
    request.order = input.order;
    request.surface = SurfaceMeshing {
        cell: input.cell,
        part: input.part.clone(),
        sheet_thickness: input.sheet_thickness,
        ..Default::default()
    };
    Ok(request)
}

fn describe(stage: &Stage) -> String {
    match stage {
        Stage::Load => "reading and checking the mesh".into(),
        Stage::Assemble { dofs } => format!("assembling K and M ({dofs} DOF)"),
        Stage::Solve(what) => format!("eigen solve: {what}"),
        Stage::Store => "storing the bank in the cache".into(),
        Stage::Warning(w) => format!("warning: {w}"),
        Stage::Level { index: 0, size_factor } if *size_factor == 1.0 => {
            "level 0 (requested element size)".into()
        }
        Stage::Level { index: 0, size_factor } => {
            format!("level 0 (element sizes x {size_factor:.2}, to fit the memory limit)")
        }
        Stage::Level { index: 1, size_factor } => {
            format!("level 1 (element sizes x {size_factor:.2}) for the error estimate")
        }
        Stage::Level { index, size_factor } => {
            format!("level {index} (element sizes x {size_factor:.2}) to reach the --accuracy target")
        }
    }
}

/// Environment variable that replaces the solver's memory guard (75 % of the available
/// memory) by this many GB: for reference solves on a machine known to have the room.
pub const MEMORY_LIMIT_ENV: &str = "MODAL_MEMORY_LIMIT_GB";

/// The memory limit [bytes] set by [`MEMORY_LIMIT_ENV`], if any.
pub fn memory_limit_from_env() -> Result<Option<u64>> {
    let Some(text) = std::env::var_os(MEMORY_LIMIT_ENV) else { return Ok(None) };
    let text = text.to_string_lossy();
    match text.trim().parse::<f64>() {
        Ok(gb) if gb.is_finite() && gb > 0.0 => Ok(Some((gb * 1e9) as u64)),
        _ => anyhow::bail!("{MEMORY_LIMIT_ENV} must be a positive number of GB, got {text:?}"),
    }
}

/// The memory guard [bytes]: [`MEMORY_LIMIT_ENV`] if set, else 75 % of the
/// available memory (`None` where that is unknown).
pub fn memory_guard_bytes() -> Result<Option<u64>> {
    Ok(memory_limit_from_env()?.or_else(modal_eigen::default_memory_limit))
}

/// Refuses an input mesh that cannot be opened, as the solve would say it,
/// before the output's directory is made for a command that then fails.
fn openable(command: &str, mesh: &Path) -> Result<()> {
    std::fs::File::open(mesh)
        .map_err(|e| anyhow::anyhow!("{command} {0}: cannot read {0}: {e}", mesh.display()))?;
    Ok(())
}

/// The cache the flags ask for (none with `--no-cache`). A path that exists
/// and is not a directory is refused at once: every asset of a batch would
/// otherwise report it as "a damaged cache entry".
pub fn open_cache(dir: Option<&Path>, disabled: bool) -> Result<Option<BankCache>> {
    if disabled {
        return Ok(None);
    }
    let Some(dir) = dir.map(Path::to_path_buf).or_else(|| BankCache::default_dir().ok()) else {
        return Ok(None);
    };
    anyhow::ensure!(
        !dir.exists() || dir.is_dir(),
        "the cache directory {} is not a directory (--cache-dir or MODAL_CACHE_DIR)",
        dir.display()
    );
    Ok(Some(BankCache::new(dir)))
}

pub fn run(args: PrecomputeArgs) -> Result<()> {
    super::check_not_input(&args.out, &args.mesh, "-o")?;
    // A glTF with a modal model is a bank; one without is geometry, meshed like an OBJ.
    if modal_export::gltf::is_gltf_path(&args.mesh)
        && modal_export::gltf::holds_modal_model(&args.mesh)
            .with_context(|| format!("precompute {}", args.mesh.display()))?
    {
        return import_gltf(&args);
    }
    let mut request = request(&args.mesh, &args.material, &args.input)?;
    request.max_modes = args.modes;
    request.min_freq_hz = args.min_freq;
    request.max_freq_hz = args.max_freq;
    request.fix_box = args.fix_box;
    request.threads = args.threads;
    request.memory_limit_bytes = memory_limit_from_env()?;
    request.accuracy = args
        .accuracy
        .0
        .map(|target_pct| modal_precompute::AccuracyTarget { target_pct, modes: args.accuracy_modes });
    super::args::check_transfer_max_freq(args.transfer_max_freq)?;
    let cache = open_cache(args.cache_dir.as_deref(), args.no_cache)?;
    openable("precompute", &args.mesh)?;
    super::prepare_output(&args.out).with_context(|| format!("cannot write bank {}", args.out.display()))?;
    let spinner = Spinner::new("starting");
    // Warnings about the input are said when the mesh is read, once each, not after the solve.
    let mut said = std::collections::HashSet::new();
    let outcome = modal_precompute::precompute(&request, cache.as_ref(), args.force, &mut |s| match s {
        Stage::Assemble { .. } | Stage::Level { .. } => {
            spinner.milestone(format!("precompute: {}", describe(&s)))
        }
        Stage::Warning(w) if said.insert(w.clone()) => spinner.note(&describe(&Stage::Warning(w))),
        Stage::Warning(_) => {}
        _ => spinner.set(describe(&s)),
    });
    spinner.finish();
    let outcome = outcome.with_context(|| format!("precompute {}", args.mesh.display()))?;
    outcome.warnings.iter().filter(|w| !said.contains(*w)).for_each(|w| warn(w));
    let table = match args.transfer_max_freq {
        Some(f) => transfer(&outcome.bank, f)?,
        None => None,
    };
    let bank = &outcome.bank;
    interrupt::guarded(|| match &table {
        Some(t) => bank.save_with_radiation(&args.out, t),
        None => bank.save(&args.out),
    })
    .with_context(|| format!("cannot write bank {}", args.out.display()))?;
    let report = BankJson::new(bank, outcome.cached).with_radiation(table.as_ref());
    if args.json {
        print_json(&report)
    } else {
        report.write_table(&mut std::io::stdout().lock())?;
        println!("wrote {}", args.out.display());
        Ok(())
    }
}

/// The transfer table of `bank`'s audible modes up to `max_hz`
/// (`--transfer-max-freq`), with progress on stderr; `None` (and a warning)
/// when no mode is audible there.
fn transfer(bank: &modal_bank::ModeBank, max_hz: f64) -> Result<Option<modal_bank::RadiationTable>> {
    let opts = modal_radiation::RadiationOptions::default();
    let table = modal_radiation::modes::transfer_table(bank, max_hz, &opts, &mut |p| eprintln!("{p}"))
        .context("acoustic transfer (--transfer-max-freq)")?;
    if table.is_none() {
        warn(&format!("no audible mode at or below {max_hz} Hz: the bank stores no transfer"));
    }
    Ok(table)
}

pub fn export_matrices(args: ExportMatricesArgs) -> Result<()> {
    let request = request(&args.mesh, &args.material, &args.input)?;
    openable("export-matrices", &args.mesh)?;
    // Made and probed before the assembly, which can take minutes.
    let [k_path, m_path, nodes_path] = ["K.mtx", "M.mtx", "nodes.csv"].map(|name| args.out.join(name));
    for path in [&k_path, &m_path, &nodes_path] {
        super::prepare_output(path).with_context(|| format!("cannot write {}", path.display()))?;
    }
    let spinner = Spinner::new("starting");
    let assembled = modal_precompute::assemble_matrices(&request, &mut |s| spinner.set(describe(&s)));
    spinner.finish();
    let assembled = assembled.with_context(|| format!("export-matrices {}", args.mesh.display()))?;
    assembled.warnings.iter().for_each(|w| warn(w));
    // The entries the files hold (the lower triangle without exact zeros), beside
    // `nnz_k`, the assembled matrix's stored entries (both triangles).
    let (mut entries_k, mut entries_m) = (0, 0);
    // One output: all three files, or none (an interrupt between them left K.mtx alone).
    write_atomic_all(vec![
        (&k_path, buffered(|w| modal_fem::write_matrix_market(&assembled.k, w).map(|n| entries_k = n))),
        (&m_path, buffered(|w| modal_fem::write_matrix_market(&assembled.m, w).map(|n| entries_m = n))),
        (&nodes_path, buffered(|w| modal_fem::write_nodes_csv(&assembled.mesh.nodes, w))),
    ])
    .with_context(|| format!("cannot write the matrices into {}", args.out.display()))?;
    let summary = serde_json::json!({
        "dir": args.out.display().to_string(),
        "nodes": assembled.mesh.nodes.len(),
        "dofs": 3 * assembled.mesh.nodes.len(),
        "tets": assembled.mesh.cells.len(),
        "order": assembled.mesh.order(),
        "parts": assembled.parts,
        "nnz_k": assembled.k.compute_nnz(),
        "entries_k": entries_k,
        "entries_m": entries_m,
        "assemble_s": assembled.assemble_s,
    });
    if args.json {
        print_json(&summary)
    } else {
        println!(
            "wrote K.mtx, M.mtx, nodes.csv to {} ({} nodes, {} DOF, {} tets, order {})",
            args.out.display(),
            assembled.mesh.nodes.len(),
            3 * assembled.mesh.nodes.len(),
            assembled.mesh.cells.len(),
            assembled.mesh.order()
        );
        Ok(())
    }
}

/// `modal precompute MODEL.glb -o X.bank`: a glTF with a modal model is an
/// existing bank; it is read and stored, nothing is solved.
fn import_gltf(args: &PrecomputeArgs) -> Result<()> {
    let m = &args.material;
    let flags = [m.material.is_some(), m.youngs.is_some(), m.poisson.is_some(), m.density.is_some()];
    if flags.into_iter().any(|given| given) || m.alpha.is_some() || m.beta.is_some() {
        warn("the glTF already holds modes: material flags are ignored (use `modal retune` to change them)");
    }
    let (bank, radiation) = super::bank_cmds::load_bank_with_radiation(&args.mesh)?;
    super::prepare_output(&args.out).with_context(|| format!("cannot write bank {}", args.out.display()))?;
    interrupt::guarded(|| match &radiation {
        Some(table) => bank.save_with_radiation(&args.out, table),
        None => bank.save(&args.out),
    })
    .with_context(|| format!("cannot write bank {}", args.out.display()))?;
    let report = BankJson::new(&bank, false);
    if args.json {
        print_json(&report)
    } else {
        report.write_table(&mut std::io::stdout().lock())?;
        println!("wrote {} (modes read from {}, no solve)", args.out.display(), args.mesh.display());
        Ok(())
    }
}
