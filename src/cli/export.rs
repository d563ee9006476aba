//! `modal export`: a bank out to other tools — ParaView (`--vtk`), glTF
//! (`--gltf`, docs/gltf-extension.md) and Faust (`--faust` with `--at`). Every file is written atomically; with several
//! formats, each is written in turn and the summary lists what was written.

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};
use modal_bank::{ModeBank, RadiationTable};
use modal_export::faust::{check_name, FaustModel, DEFAULT_NAME};
use serde_json::{json, Value};

use super::args::ExportArgs;
use super::bank_cmds::load_bank_with_radiation;
use super::output::print_json;
use super::write_atomic;

/// Writes a file through `write`, atomically, naming it in the error.
fn write_file(path: &Path, write: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    write_atomic(path, |tmp| {
        let mut file = std::io::BufWriter::new(std::fs::File::create(tmp)?);
        write(&mut file)?;
        file.flush()?;
        Ok(())
    })
    .with_context(|| format!("cannot write {}", path.display()))
}

fn vtk(bank: &ModeBank, path: &Path) -> Result<Value> {
    write_file(path, |w| Ok(modal_bank::export_vtu(bank, w)?))?;
    let line = format!(
        "wrote {} ({} modes on {} surface nodes)",
        path.display(),
        bank.mode_count(),
        bank.surface_node_count()
    );
    Ok(json!({ "path": path.display().to_string(), "summary": line }))
}

fn faust(bank: &ModeBank, args: &ExportArgs, path: &Path) -> Result<Value> {
    let name = args.faust_name.as_deref().unwrap_or(DEFAULT_NAME);
    check_name(name).context("--faust-name")?;
    let model = FaustModel::new(bank, &args.at, name).context("--faust")?;
    let source = args.bank.file_name().map_or_else(|| "a bank".into(), |n| n.to_string_lossy().into_owned());
    write_file(path, |w| Ok(model.write(w, &source)?))?;
    let mut line = format!(
        "wrote {} (Faust {}(exPos,t60Scale): {} modes, {} excitation positions",
        path.display(),
        model.name,
        model.mode_count(),
        model.positions.len()
    );
    if model.skipped_modes > 0 {
        line.push_str(&format!(", {} overdamped modes left out", model.skipped_modes));
    }
    line.push(')');
    for (k, e) in model.positions.iter().enumerate() {
        let [x, y, z] = e.surface_point;
        line.push_str(&format!(
            "\n  exPos {k}: surface point ({x:.6}, {y:.6}, {z:.6}) m, {:.3} mm from the requested point",
            e.distance_m * 1e3
        ));
    }
    let positions: Vec<Value> = model
        .positions
        .iter()
        .map(|e| {
            json!({
                "requested": e.requested,
                "surface_point": e.surface_point,
                "distance_m": e.distance_m,
                "normal": e.normal,
                "gain_scale": e.scale,
            })
        })
        .collect();
    Ok(json!({
        "path": path.display().to_string(),
        "name": model.name,
        "modes": model.mode_count(),
        "skipped_modes": model.skipped_modes,
        "positions": positions,
        "summary": line,
    }))
}

fn gltf(
    bank: &ModeBank,
    radiation: Option<&RadiationTable>,
    args: &ExportArgs,
    path: &Path,
) -> Result<Value> {
    // Binary glTF only: a `.gltf` name promises JSON, and any other name
    // (`x.bank`) would be read back as something else.
    let glb = path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    anyhow::ensure!(glb, "--gltf {}: the file is binary glTF; give it a .glb name", path.display());
    let name = args.bank.file_stem().map_or_else(|| "model".into(), |n| n.to_string_lossy().into_owned());
    let glb = modal_export::gltf::export_glb(bank, radiation, &name, true).context("--gltf")?;
    write_file(path, |w| Ok(w.write_all(&glb.bytes)?))?;
    let modes = bank.mode_count() - glb.overdamped_left_out;
    let mut line = format!(
        "wrote {} (glTF, {}: {modes} modes on {} surface points",
        path.display(),
        modal_export::gltf::EXTENSION,
        bank.surface_node_count(),
    );
    if glb.radiation_modes > 0 {
        line.push_str(&format!(", the acoustic transfer of {} in extras.modal", glb.radiation_modes));
    }
    if glb.overdamped_left_out > 0 {
        line.push_str(&format!(", {} overdamped modes left out", glb.overdamped_left_out));
    }
    line.push_str(&format!(", {} bytes)", glb.bytes.len()));
    Ok(json!({
        "path": path.display().to_string(),
        "bytes": glb.bytes.len(),
        "modes": modes,
        "skipped_modes": glb.overdamped_left_out,
        "radiation_modes": glb.radiation_modes,
        "summary": line,
    }))
}

pub fn run(args: ExportArgs) -> Result<()> {
    let outputs = [("--vtk", &args.vtk), ("--gltf", &args.gltf), ("--faust", &args.faust)];
    let outputs: Vec<(&str, &std::path::PathBuf)> =
        outputs.into_iter().filter_map(|(flag, path)| Some((flag, path.as_ref()?))).collect();
    for (flag, path) in &outputs {
        super::check_not_input(path, &args.bank, flag)?;
    }
    if let Some(path) = &args.vtk {
        // ParaView picks its reader by the extension: x.txt opened as text.
        let vtu = path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("vtu"));
        anyhow::ensure!(
            vtu,
            "--vtk {}: the file is a VTK XML unstructured grid; give it a .vtu name",
            path.display()
        );
    }
    let (bank, radiation) = load_bank_with_radiation(&args.bank)?;
    for (flag, path) in &outputs {
        super::prepare_output(path).with_context(|| format!("cannot write {flag} {}", path.display()))?;
    }
    let mut report = serde_json::Map::new();
    report.insert("bank".into(), json!(args.bank.display().to_string()));
    if let Some(path) = &args.vtk {
        report.insert("vtk".into(), vtk(&bank, path)?);
    }
    if let Some(path) = &args.gltf {
        report.insert("gltf".into(), gltf(&bank, radiation.as_ref(), &args, path)?);
    }
    if let Some(path) = &args.faust {
        report.insert("faust".into(), faust(&bank, &args, path)?);
    }
    if args.json {
        return print_json(&report);
    }
    for value in report.values() {
        if let Some(line) = value.get("summary").and_then(Value::as_str) {
            println!("{line}");
        }
    }
    Ok(())
}
