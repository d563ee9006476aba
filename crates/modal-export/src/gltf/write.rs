//! Writing a bank as a binary glTF (see the module doc of [`crate::gltf`]).
//!
//! GLB layout (glTF 2.0 §4.4): a 12-byte header (`glTF`, version 2, total
//! length), a JSON chunk padded with spaces and a BIN chunk padded with
//! zeros, each to a multiple of 4 bytes. Every buffer view starts at a
//! multiple of 8 bytes, so f64 side data is aligned too.

use std::borrow::Cow;

use modal_bank::{ModeBank, RadiationTable};
use serde_json::{json, Value};

use super::{EXTENSION, EXTRAS_KEY, FLOAT, UNSIGNED_INT};
use crate::inertia;
use crate::ExportError;

/// Buffer views and accessors being laid out in one binary buffer.
#[derive(Default)]
struct Layout {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Layout {
    /// Appends `bytes` as a buffer view (8-byte aligned); returns its index.
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(8) {
            self.bin.push(0);
        }
        let mut view = json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len() });
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(view);
        self.views.len() - 1
    }

    /// Adds an accessor over a whole view; returns its index.
    fn accessor(
        &mut self,
        view: usize,
        component: u32,
        count: usize,
        kind: &str,
        bounds: Option<Value>,
    ) -> usize {
        let mut a = json!({ "bufferView": view, "componentType": component, "count": count, "type": kind });
        if let Some(Value::Array(b)) = bounds {
            a["min"] = b[0].clone();
            a["max"] = b[1].clone();
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn floats(&mut self, values: impl IntoIterator<Item = f32>, kind: &str, target: Option<u32>) -> usize {
        let values: Vec<f32> = values.into_iter().collect();
        let width = if kind == "VEC3" { 3 } else { 1 };
        let bounds = (kind == "VEC3").then(|| {
            let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for p in values.chunks_exact(3) {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            json!([lo, hi])
        });
        let view = self.view(&le_bytes(&values, f32::to_le_bytes), target);
        self.accessor(view, FLOAT, values.len() / width, kind, bounds)
    }
}

fn le_bytes<T: Copy, const N: usize>(values: &[T], f: impl Fn(T) -> [u8; N]) -> Vec<u8> {
    values.iter().flat_map(|&v| f(v)).collect()
}

/// The render (and interpolation) triangles: the corner triangles of a
/// linear bank; each 6-node triangle of a quadratic bank split into four.
fn flat_triangles(bank: &ModeBank) -> Vec<[usize; 3]> {
    let s = &bank.surface;
    match &s.triangle_edge_nodes {
        None => s.triangles.clone(),
        Some(edges) => s
            .triangles
            .iter()
            .zip(edges)
            .flat_map(|(&[a, b, c], &[ab, bc, ca])| [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]])
            .collect(),
    }
}

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// A bank written as GLB bytes, and what could not be written.
#[derive(Clone, Debug)]
pub struct GlbExport {
    /// The file's bytes.
    pub bytes: Vec<u8>,
    /// Overdamped modes left out (ξ ≥ 1: glTF's frequencies are damped
    /// frequencies, which such a mode does not have).
    pub overdamped_left_out: usize,
    /// Modes whose acoustic transfer was written (in `extras.modal`).
    pub radiation_modes: usize,
}

/// The bank as a GLB file named `name` (mesh, node and model names), its
/// overdamped modes left out. `extras`: also write the exact side data (see
/// [`crate::gltf`]), with `radiation`, the bank's stored acoustic transfer,
/// if any (no KHR draft has a place for it).
pub fn export_glb(
    bank: &ModeBank,
    radiation: Option<&RadiationTable>,
    name: &str,
    extras: bool,
) -> Result<GlbExport, ExportError> {
    bank.validate().map_err(ExportError::InvalidBank)?;
    if let Some(table) = radiation {
        table.validate_for(bank).map_err(ExportError::InvalidBank)?;
    }
    let Underdamped { bank, radiation, left_out: overdamped_left_out } = underdamped_only(bank, radiation)?;
    let radiation = radiation.filter(|_| extras);
    let radiation_modes = radiation.as_ref().map_or(0, |t| t.modes.len());
    let bytes = write_glb(&bank, radiation.as_deref(), name, extras)?;
    Ok(GlbExport { bytes, overdamped_left_out, radiation_modes })
}

/// A bank and its transfer without their overdamped modes.
struct Underdamped<'a> {
    bank: Cow<'a, ModeBank>,
    radiation: Option<Cow<'a, RadiationTable>>,
    /// How many modes were left out.
    left_out: usize,
}

/// The bank and its transfer without the overdamped modes (whose damped
/// frequency rounds to 0 in f32).
fn underdamped_only<'a>(
    bank: &'a ModeBank,
    radiation: Option<&'a RadiationTable>,
) -> Result<Underdamped<'a>, ExportError> {
    let keep: Vec<usize> =
        (0..bank.mode_count()).filter(|&i| bank.damped_frequency_hz(i) as f32 > 0.0).collect();
    if keep.is_empty() {
        return Err(ExportError::NoModes);
    }
    let left_out = bank.mode_count() - keep.len();
    if left_out == 0 {
        return Ok(Underdamped {
            bank: Cow::Borrowed(bank),
            radiation: radiation.map(Cow::Borrowed),
            left_out,
        });
    }
    let s3 = 3 * bank.surface_node_count();
    let pick = |values: &[f64]| keep.iter().map(|&i| values[i]).collect::<Vec<f64>>();
    let mut info = bank.info.clone();
    if info.error_estimate_pct.len() == bank.mode_count() {
        info.error_estimate_pct = keep.iter().map(|&i| bank.info.error_estimate_pct[i]).collect();
    }
    let kept = ModeBank {
        frequencies_hz: pick(&bank.frequencies_hz),
        damping_ratios: pick(&bank.damping_ratios),
        decay_rates: pick(&bank.decay_rates),
        residuals: pick(&bank.residuals),
        shapes: keep.iter().flat_map(|&i| bank.shapes[i * s3..(i + 1) * s3].iter().copied()).collect(),
        surface: bank.surface.clone(),
        material: bank.material.clone(),
        mass: bank.mass,
        info,
    };
    let radiation = radiation.map(|table| {
        let modes = table
            .modes
            .iter()
            .filter_map(|m| {
                let new_index = keep.binary_search(&m.mode).ok()?;
                Some(modal_bank::ModeTransfer { mode: new_index, ..m.clone() })
            })
            .collect();
        Cow::Owned(RadiationTable {
            centre_m: table.centre_m,
            fit_radius_m: table.fit_radius_m,
            air_density_kg_m3: table.air_density_kg_m3,
            sound_speed_m_s: table.sound_speed_m_s,
            tolerance: table.tolerance,
            modes,
        })
    });
    Ok(Underdamped { bank: Cow::Owned(kept), radiation, left_out })
}

fn write_glb(
    bank: &ModeBank,
    radiation: Option<&RadiationTable>,
    name: &str,
    extras: bool,
) -> Result<Vec<u8>, ExportError> {
    let n = bank.mode_count();
    let s = bank.surface_node_count();
    let triangles = flat_triangles(bank);
    if s == 0 || triangles.is_empty() {
        return Err(ExportError::NoSurface);
    }
    let too_big = |what: &str| ExportError::TooLarge(what.to_string());
    if s > u32::MAX as usize || n.checked_mul(s).is_none_or(|v| v > u32::MAX as usize) {
        return Err(too_big("surface nodes × modes"));
    }
    let mut layout = Layout::default();
    let positions =
        layout.floats(bank.surface.positions.iter().flatten().map(|&x| x as f32), "VEC3", Some(ARRAY_BUFFER));
    let indices: Vec<u32> = triangles.iter().flatten().map(|&i| i as u32).collect();
    let index_view = layout.view(&le_bytes(&indices, u32::to_le_bytes), Some(ELEMENT_ARRAY_BUFFER));
    let indices = layout.accessor(index_view, UNSIGNED_INT, triangles.len() * 3, "SCALAR", None);
    debug_assert!((0..n).all(|i| bank.damped_frequency_hz(i) as f32 > 0.0));
    let frequencies = layout.floats((0..n).map(|i| bank.damped_frequency_hz(i) as f32), "SCALAR", None);
    let decay_rates = layout.floats(bank.decay_rates.iter().map(|&d| d as f32), "SCALAR", None);
    let shapes = layout.floats(bank.shapes.iter().copied(), "VEC3", None);

    let m = &bank.material;
    let mut material = json!({
        "density": m.density_kg_m3, "youngsModulus": m.youngs_pa, "poissonRatio": m.poisson,
        "alpha": m.alpha, "beta": m.beta,
    });
    if let Some(material_name) = &m.name {
        material["name"] = json!(material_name);
    }
    let (moments, axes) = inertia::principal(&bank.mass.inertia_kg_m2);
    let mut model = json!({
        "name": name,
        "frequencies": frequencies,
        "decayRates": decay_rates,
        "positions": positions,
        "shapes": shapes,
        "indices": indices,
        "material": 0,
    });
    if bank.mass.mass_kg > 0.0 {
        model["massProperties"] = json!({
            "mass": bank.mass.mass_kg,
            "centerOfMass": bank.mass.center_of_mass_m,
            "inertiaDiagonal": moments.map(|x| x.max(0.0)),
            "inertiaOrientation": axes,
        });
    }
    if extras {
        model["extras"] = json!({ EXTRAS_KEY: exact_side_data(bank, radiation, &mut layout) });
    }
    let document = json!({
        "asset": { "version": "2.0", "generator": format!("modal {}", env!("CARGO_PKG_VERSION")) },
        "extensionsUsed": [EXTENSION],
        "extensions": { EXTENSION: { "acousticMaterials": [material], "modalModels": [model] } },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{
            "name": name,
            "mesh": 0,
            "extensions": { EXTENSION: { "modalModel": 0, "gain": 1.0 } },
        }],
        "meshes": [{
            "name": name,
            "primitives": [{ "attributes": { "POSITION": positions }, "indices": indices, "mode": 4 }],
        }],
        "accessors": layout.accessors,
        "bufferViews": layout.views,
        "buffers": [{ "byteLength": layout.bin.len() }],
    });
    glb_container(&document, layout.bin)
}

/// The `extras.modal` object: exact copies of what the accessors round.
fn exact_side_data(bank: &ModeBank, radiation: Option<&RadiationTable>, layout: &mut Layout) -> Value {
    let surface = &bank.surface;
    let positions: Vec<f64> = surface.positions.iter().flatten().copied().collect();
    let positions = layout.view(&le_bytes(&positions, f64::to_le_bytes), None);
    let index_view = |layout: &mut Layout, rows: &[[usize; 3]]| {
        let flat: Vec<u64> = rows.iter().flatten().map(|&i| i as u64).collect();
        layout.view(&le_bytes(&flat, u64::to_le_bytes), None)
    };
    let triangles = index_view(layout, &surface.triangles);
    let edge_nodes = surface.triangle_edge_nodes.as_ref().map(|e| index_view(layout, e));
    let node_ids: Vec<u64> = surface.node_ids.iter().map(|&i| i as u64).collect();
    let node_ids = layout.view(&le_bytes(&node_ids, u64::to_le_bytes), None);
    let mut side = json!({
        "format": "modal-bank",
        "formatVersion": modal_bank::FORMAT_VERSION,
        "frequenciesHz": bank.frequencies_hz,
        "dampingRatios": bank.damping_ratios,
        "decayRates": bank.decay_rates,
        "residuals": bank.residuals,
        "positionsF64": positions,
        "trianglesU64": triangles,
        "triangleEdgeNodesU64": edge_nodes,
        "nodeIdsU64": node_ids,
        "material": bank.material,
        "massProperties": bank.mass,
        "solveInfo": bank.info,
    });
    if let Some(table) = radiation {
        side["radiation"] = radiation_side_data(table, layout);
    }
    side
}

/// The acoustic transfer as `extras.modal.radiation`: per-mode values as
/// JSON numbers (exact, like the frequencies) and the multipole
/// coefficients as one buffer view of little-endian f64 (re, im) pairs,
/// mode after mode (crate `modal_bank`'s `RadiationTable`).
fn radiation_side_data(table: &RadiationTable, layout: &mut Layout) -> Value {
    let coefficients: Vec<f64> =
        table.modes.iter().flat_map(|m| m.coefficients.iter().flatten()).copied().collect();
    let coefficients = layout.view(&le_bytes(&coefficients, f64::to_le_bytes), None);
    let column =
        |f: fn(&modal_bank::ModeTransfer) -> Value| table.modes.iter().map(f).collect::<Vec<Value>>();
    json!({
        "centreM": table.centre_m,
        "fitRadiusM": table.fit_radius_m,
        "airDensityKgM3": table.air_density_kg_m3,
        "soundSpeedMS": table.sound_speed_m_s,
        "tolerance": table.tolerance,
        "modes": column(|m| json!(m.mode)),
        "wavenumbers": column(|m| json!(m.wavenumber)),
        "orders": column(|m| json!(m.order)),
        "powerW": column(|m| json!(m.power_w)),
        "efficiency": column(|m| json!(m.efficiency)),
        "coefficientsF64": coefficients,
    })
}

/// Packs a document and its binary buffer into GLB bytes (glTF §4.4: header, JSON
/// chunk padded with spaces, BIN chunk padded with zeros).
pub fn glb_container(document: &Value, mut bin: Vec<u8>) -> Result<Vec<u8>, ExportError> {
    let mut json = document.to_string().into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    if total > u32::MAX as usize {
        return Err(ExportError::TooLarge(format!("a {total}-byte GLB (the format's limit is 4 GiB)")));
    }
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    Ok(out)
}
