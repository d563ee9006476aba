//! Writing a bank as a binary glTF (see the module doc of [`crate::gltf`]).
//!
//! GLB layout (glTF 2.0 §4.4): a 12-byte header (`glTF`, version 2, total
//! length), a JSON chunk padded with spaces and a BIN chunk padded with
//! zeros, each to a multiple of 4 bytes. Every buffer view starts at a
//! multiple of 8 bytes, so f64 side data is aligned too.

use modal_bank::ModeBank;
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

/// The bank as a GLB file named `name` (mesh, node and model names).
/// `extras`: also write the exact side data (see [`crate::gltf`]).
pub fn export_glb(bank: &ModeBank, name: &str, extras: bool) -> Result<Vec<u8>, ExportError> {
    bank.validate().map_err(ExportError::InvalidBank)?;
    let n = bank.mode_count();
    let s = bank.surface_node_count();
    let triangles = flat_triangles(bank);
    if n == 0 {
        return Err(ExportError::NoModes);
    }
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
    if let Some(i) = (0..n).find(|&i| bank.damped_frequency_hz(i) as f32 <= 0.0) {
        return Err(ExportError::Overdamped(i));
    }
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
        model["extras"] = json!({ EXTRAS_KEY: exact_side_data(bank, &mut layout) });
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
fn exact_side_data(bank: &ModeBank, layout: &mut Layout) -> Value {
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
    json!({
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
