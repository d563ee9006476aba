//! Reading a glTF modal model back into a [`ModeBank`].
//!
//! The document is parsed and validated by the `gltf` crate; the accessors
//! are checked against the draft's requirements (type, component type,
//! counts, finite values, indices in range) before use. A model's damped
//! frequency `f_d` and decay rate `d` give the bank's undamped frequency and
//! damping ratio by `ω = √((2π f_d)² + d²)`, `f = ω/2π`, `ξ = d/ω` (the
//! draft's Appendix A). Modes are sorted by frequency (the draft lets files
//! order them by importance; a bank is ascending). Without `indices` the
//! model cannot be struck at arbitrary points here, so it is refused.

use std::path::Path;

use modal_bank::{ModeBank, SolveInfo};
use modal_fem::{MassProperties, Material};
use modal_mesh::Surface;
use serde::Deserialize;
use serde_json::Value;

use super::{EXTENSION, EXTRAS_KEY, FLOAT, LEGACY_EXTENSION, UNSIGNED_INT, UNSIGNED_SHORT};
use crate::inertia;
use crate::ExportError;

/// A bank read from a glTF file.
#[derive(Clone, Debug)]
pub struct Imported {
    /// The bank.
    pub bank: ModeBank,
    /// True when the exact side data (`extras.modal`) was used.
    pub exact: bool,
    /// Index of the model read in the document's model array.
    pub model: usize,
    /// The model's name, if any.
    pub name: Option<String>,
    /// What the caller should tell the user (ignored data, missing values).
    pub warnings: Vec<String>,
}

/// Whether `path` names a glTF file (`.glb` or `.gltf`, any case).
pub fn is_gltf_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"))
}

/// Whether the glTF file at `path` carries a modal model (the
/// `KHR_audio_rigid_bodies` root extension, or its legacy name): then it is
/// a bank; without one it is only geometry, to be meshed and solved.
pub fn holds_modal_model(path: &Path) -> Result<bool, ExportError> {
    let bytes =
        std::fs::read(path).map_err(|source| ExportError::Read { path: path.to_path_buf(), source })?;
    let gltf = gltf::Gltf::from_slice(&bytes).map_err(|e| ExportError::Gltf(e.to_string()))?;
    Ok(gltf.extension_value(EXTENSION).is_some() || gltf.extension_value(LEGACY_EXTENSION).is_some())
}

/// Reads the modal model of a `.glb`, or of a `.gltf` whose buffers are
/// files next to it.
pub fn import_gltf_file(path: &Path) -> Result<Imported, ExportError> {
    let bytes =
        std::fs::read(path).map_err(|source| ExportError::Read { path: path.to_path_buf(), source })?;
    import(&bytes, path.parent())
}

/// Reads the modal model of GLB bytes (buffers inside the file only).
pub fn import_glb(bytes: &[u8]) -> Result<Imported, ExportError> {
    import(bytes, None)
}

#[derive(Deserialize)]
struct RootJson {
    #[serde(default, rename = "modalModels", alias = "models")]
    models: Vec<ModelJson>,
    #[serde(default, rename = "acousticMaterials", alias = "materials")]
    materials: Vec<MaterialJson>,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct ModelJson {
    name: Option<String>,
    frequencies: usize,
    decay_rates: usize,
    positions: usize,
    shapes: usize,
    indices: Option<usize>,
    material: Option<usize>,
    mass_properties: Option<MassJson>,
    #[serde(default)]
    extras: Option<Value>,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct MaterialJson {
    name: Option<String>,
    density: Option<f64>,
    youngs_modulus: Option<f64>,
    poisson_ratio: Option<f64>,
    alpha: Option<f64>,
    beta: Option<f64>,
}

fn identity() -> [f64; 4] {
    [0.0, 0.0, 0.0, 1.0]
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct MassJson {
    mass: f64,
    #[serde(default)]
    center_of_mass: [f64; 3],
    #[serde(default)]
    inertia_diagonal: [f64; 3],
    #[serde(default = "identity")]
    inertia_orientation: [f64; 4],
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct ExactJson {
    format: String,
    frequencies_hz: Vec<f64>,
    damping_ratios: Vec<f64>,
    decay_rates: Vec<f64>,
    residuals: Vec<f64>,
    positions_f64: usize,
    triangles_u64: usize,
    triangle_edge_nodes_u64: Option<usize>,
    node_ids_u64: usize,
    material: Material,
    mass_properties: MassProperties,
    solve_info: SolveInfo,
}

fn bad(message: impl Into<String>) -> ExportError {
    ExportError::Model(message.into())
}

/// The document and its buffers' bytes.
struct Doc {
    gltf: gltf::Gltf,
    buffers: Vec<Vec<u8>>,
}

impl Doc {
    fn open(bytes: &[u8], base: Option<&Path>) -> Result<Doc, ExportError> {
        let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| ExportError::Gltf(e.to_string()))?;
        // The geometry reader's loader, so a bank and a surface are read alike.
        let buffers = modal_tetra::gltf_buffers(&gltf, base, bytes).map_err(|e| match e {
            modal_tetra::TetraError::Io { path, source } => ExportError::Read { path, source },
            other => bad(other.to_string()),
        })?;
        Ok(Doc { gltf, buffers })
    }

    /// The elements of accessor `index` (`what` names it in errors), which
    /// must have `dims` and one of `components`.
    fn read<T: gltf::accessor::Item>(
        &self,
        index: usize,
        what: &str,
        dims: gltf::accessor::Dimensions,
        components: &[u32],
    ) -> Result<Vec<T>, ExportError> {
        let accessor =
            self.gltf.accessors().nth(index).ok_or_else(|| bad(format!("{what}: no accessor {index}")))?;
        let component = accessor.data_type().as_gl_enum();
        if accessor.dimensions() != dims || !components.contains(&component) {
            return Err(bad(format!(
                "{what}: accessor {index} is {:?} of component type {component}, expected {dims:?} of {components:?}",
                accessor.dimensions()
            )));
        }
        if accessor.count() == 0 {
            return Err(bad(format!("{what}: accessor {index} is empty")));
        }
        if accessor.sparse().is_some() {
            return Err(bad(format!("{what}: accessor {index} is sparse (not supported)")));
        }
        if accessor.view().and_then(|v| v.stride()).is_some_and(|s| s < accessor.size()) {
            return Err(bad(format!("{what}: accessor {index} has a stride below its element size")));
        }
        let get = |b: gltf::Buffer| self.buffers.get(b.index()).map(Vec::as_slice);
        let iter = gltf::accessor::Iter::<T>::new(accessor, get)
            .ok_or_else(|| bad(format!("{what}: accessor {index} reaches past its buffer")))?;
        Ok(iter.collect())
    }

    /// The bytes of buffer view `index`.
    fn view(&self, index: usize) -> Result<&[u8], ExportError> {
        let view = self.gltf.views().nth(index).ok_or_else(|| bad(format!("no buffer view {index}")))?;
        let data = &self.buffers[view.buffer().index()];
        data.get(view.offset()..view.offset().saturating_add(view.length()))
            .ok_or_else(|| bad(format!("buffer view {index} reaches past its buffer")))
    }
}

fn f32_list(doc: &Doc, index: usize, what: &str) -> Result<Vec<f32>, ExportError> {
    let values: Vec<f32> = doc.read(index, what, gltf::accessor::Dimensions::Scalar, &[FLOAT])?;
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(bad(format!("{what}[{i}] = {} is not finite", values[i]))),
        None => Ok(values),
    }
}

fn vec3_list(doc: &Doc, index: usize, what: &str) -> Result<Vec<[f32; 3]>, ExportError> {
    let values: Vec<[f32; 3]> = doc.read(index, what, gltf::accessor::Dimensions::Vec3, &[FLOAT])?;
    match values.iter().position(|v| !v.iter().all(|x| x.is_finite())) {
        Some(i) => Err(bad(format!("{what}[{i}] is not finite"))),
        None => Ok(values),
    }
}

fn index_list(doc: &Doc, index: usize) -> Result<Vec<u32>, ExportError> {
    let scalar = gltf::accessor::Dimensions::Scalar;
    let accessor =
        doc.gltf.accessors().nth(index).ok_or_else(|| bad(format!("indices: no accessor {index}")))?;
    if accessor.data_type().as_gl_enum() == UNSIGNED_SHORT {
        let short: Vec<u16> = doc.read(index, "indices", scalar, &[UNSIGNED_SHORT])?;
        Ok(short.into_iter().map(u32::from).collect())
    } else {
        doc.read(index, "indices", scalar, &[UNSIGNED_INT])
    }
}

/// The root extension object and the node key naming a model.
fn root_extension(doc: &Doc) -> Result<(&'static str, &'static str, &Value), ExportError> {
    if let Some(v) = doc.gltf.extension_value(EXTENSION) {
        return Ok((EXTENSION, "modalModel", v));
    }
    if let Some(v) = doc.gltf.extension_value(LEGACY_EXTENSION) {
        return Ok((LEGACY_EXTENSION, "model", v));
    }
    Err(ExportError::NoExtension)
}

/// The model the first node instancing one names (else the only model),
/// with that node's gain.
fn pick_model(doc: &Doc, ext: &str, key: &str, count: usize) -> Result<(usize, f64), ExportError> {
    for node in doc.gltf.nodes() {
        if let Some(model) = node.extension_value(ext).and_then(|v| v.get(key)).and_then(Value::as_u64) {
            let gain =
                node.extension_value(ext).and_then(|v| v.get("gain")).and_then(Value::as_f64).unwrap_or(1.0);
            let model = model as usize;
            if model >= count {
                return Err(bad(format!("node {} names model {model}, the file has {count}", node.index())));
            }
            return Ok((model, gain));
        }
    }
    match count {
        1 => Ok((0, 1.0)),
        0 => Err(bad("the file defines no modal model")),
        n => Err(bad(format!("the file defines {n} modal models and no node instances one"))),
    }
}

fn material(root: &RootJson, model: &ModelJson) -> Result<Material, ExportError> {
    let index =
        model.material.ok_or_else(|| bad("the model names no acoustic material (modal needs ρ, E, ν)"))?;
    let m =
        root.materials.get(index).ok_or_else(|| bad(format!("acoustic material {index} does not exist")))?;
    let need =
        |v: Option<f64>, what: &str| v.ok_or_else(|| bad(format!("acoustic material {index} has no {what}")));
    let material = Material {
        name: m.name.clone(),
        youngs_pa: need(m.youngs_modulus, "youngsModulus")?,
        poisson: need(m.poisson_ratio, "poissonRatio")?,
        density_kg_m3: need(m.density, "density")?,
        alpha: m.alpha.unwrap_or(0.0),
        beta: m.beta.unwrap_or(0.0),
    };
    material.validate().map_err(|e| bad(format!("acoustic material {index}: {e}")))?;
    Ok(material)
}

fn mass_properties(model: &ModelJson, density: f64, warnings: &mut Vec<String>) -> MassProperties {
    match &model.mass_properties {
        Some(m) => MassProperties {
            volume_m3: m.mass / density,
            mass_kg: m.mass,
            center_of_mass_m: m.center_of_mass,
            inertia_kg_m2: inertia::tensor(m.inertia_diagonal, m.inertia_orientation),
        },
        None => {
            warnings
                .push("the model has no massProperties: mass, centre of mass and inertia read as 0".into());
            MassProperties {
                volume_m3: 0.0,
                mass_kg: 0.0,
                center_of_mass_m: [0.0; 3],
                inertia_kg_m2: [[0.0; 3]; 3],
            }
        }
    }
}

fn import(bytes: &[u8], base: Option<&Path>) -> Result<Imported, ExportError> {
    let doc = Doc::open(bytes, base)?;
    let (ext, key, root) = root_extension(&doc)?;
    let root: RootJson = serde_json::from_value(root.clone()).map_err(|e| bad(format!("{ext}: {e}")))?;
    let (index, gain) = pick_model(&doc, ext, key, root.models.len())?;
    let model = &root.models[index];
    let mut warnings = Vec::new();
    if gain != 1.0 {
        warnings.push(format!("the node's gain {gain} is not part of a bank and is ignored"));
    }
    let freqs = f32_list(&doc, model.frequencies, "frequencies")?;
    let decays = f32_list(&doc, model.decay_rates, "decayRates")?;
    let positions = vec3_list(&doc, model.positions, "positions")?;
    let shapes = vec3_list(&doc, model.shapes, "shapes")?;
    let (n, s) = (freqs.len(), positions.len());
    if decays.len() != n {
        return Err(bad(format!("decayRates has {} values for {n} frequencies", decays.len())));
    }
    if n.checked_mul(s) != Some(shapes.len()) {
        return Err(bad(format!("shapes has {} vectors, expected {n} modes × {s} positions", shapes.len())));
    }
    if let Some(i) = freqs.iter().position(|&f| f <= 0.0) {
        return Err(bad(format!("frequencies[{i}] = {} Hz is not positive", freqs[i])));
    }
    if let Some(i) = decays.iter().position(|&d| d < 0.0) {
        return Err(bad(format!("decayRates[{i}] = {} 1/s is negative", decays[i])));
    }
    let indices = index_list(
        &doc,
        model
            .indices
            .ok_or_else(|| bad("the model has no indices (modal strikes a triangulated surface)"))?,
    )?;
    if indices.len() % 3 != 0 {
        return Err(bad(format!("indices has {} values, not a multiple of 3", indices.len())));
    }
    if let Some(i) = indices.iter().position(|&k| k as usize >= s) {
        return Err(bad(format!("indices[{i}] = {} is not below the {s} positions", indices[i])));
    }
    let material = material(&root, model)?;
    if let Some(exact) = model.extras.as_ref().and_then(|e| e.get(EXTRAS_KEY)) {
        match exact_bank(&doc, exact, &freqs, &decays, &positions, &shapes) {
            Ok(bank) => {
                return Ok(Imported { bank, exact: true, model: index, name: model.name.clone(), warnings })
            }
            Err(why) => warnings.push(format!("extras.{EXTRAS_KEY} is ignored: {why}")),
        }
    }
    let mass = mass_properties(model, material.density_kg_m3, &mut warnings);
    // Undamped ω and ξ from the damped frequency and the decay rate, in ascending order.
    let mut modes: Vec<(f64, f64, usize)> = (0..n)
        .map(|i| {
            let (wd, d) = (2.0 * std::f64::consts::PI * freqs[i] as f64, decays[i] as f64);
            let w = (wd * wd + d * d).sqrt();
            (w, d, i)
        })
        .collect();
    modes.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut bank_shapes = Vec::with_capacity(n * s * 3);
    for &(_, _, i) in &modes {
        bank_shapes.extend(shapes[i * s..(i + 1) * s].iter().flatten());
    }
    let bank = ModeBank {
        frequencies_hz: modes.iter().map(|m| m.0 / (2.0 * std::f64::consts::PI)).collect(),
        damping_ratios: modes.iter().map(|m| m.1 / m.0).collect(),
        decay_rates: modes.iter().map(|m| m.1).collect(),
        residuals: vec![0.0; n],
        shapes: bank_shapes,
        surface: Surface {
            node_ids: (0..s).collect(),
            positions: positions.iter().map(|p| p.map(f64::from)).collect(),
            triangles: indices
                .chunks_exact(3)
                .map(|t| [t[0] as usize, t[1] as usize, t[2] as usize])
                .collect(),
            triangle_edge_nodes: None,
        },
        material,
        mass,
        info: SolveInfo::default(),
    };
    bank.validate().map_err(ExportError::InvalidBank)?;
    Ok(Imported { bank, exact: false, model: index, name: model.name.clone(), warnings })
}

fn le_words<const N: usize>(bytes: &[u8], count: usize, what: &str) -> Result<Vec<[u8; N]>, String> {
    if bytes.len() != count * N {
        return Err(format!("{what} has {} bytes, expected {}", bytes.len(), count * N));
    }
    Ok(bytes.chunks_exact(N).map(|c| c.try_into().unwrap_or([0; N])).collect())
}

fn triples(bytes: &[u8], rows: usize, bound: usize, what: &str) -> Result<Vec<[usize; 3]>, String> {
    let words = le_words::<8>(bytes, rows * 3, what)?;
    let flat: Vec<usize> = words.iter().map(|w| u64::from_le_bytes(*w) as usize).collect();
    if flat.iter().any(|&k| k >= bound) {
        return Err(format!("{what} names a node beyond the {bound} positions"));
    }
    Ok(flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect())
}

/// The exact bank of `extras.modal`, if it agrees with the KHR data.
fn exact_bank(
    doc: &Doc,
    extras: &Value,
    freqs: &[f32],
    decays: &[f32],
    positions: &[[f32; 3]],
    shapes: &[[f32; 3]],
) -> Result<ModeBank, String> {
    let exact: ExactJson = serde_json::from_value(extras.clone()).map_err(|e| e.to_string())?;
    if exact.format != "modal-bank" {
        return Err(format!("format '{}' is not modal-bank", exact.format));
    }
    let (n, s) = (freqs.len(), positions.len());
    let err = |e: ExportError| e.to_string();
    let pos = le_words::<8>(doc.view(exact.positions_f64).map_err(err)?, s * 3, "positionsF64")?;
    let pos: Vec<f64> = pos.into_iter().map(f64::from_le_bytes).collect();
    let view_bytes = doc.view(exact.triangles_u64).map_err(err)?;
    let rows = view_bytes.len() / 24;
    let triangles = triples(view_bytes, rows, s, "trianglesU64")?;
    let edges = match exact.triangle_edge_nodes_u64 {
        Some(v) => Some(triples(doc.view(v).map_err(err)?, rows, s, "triangleEdgeNodesU64")?),
        None => None,
    };
    let ids = le_words::<8>(doc.view(exact.node_ids_u64).map_err(err)?, s, "nodeIdsU64")?;
    let mut bank = ModeBank {
        frequencies_hz: exact.frequencies_hz,
        damping_ratios: exact.damping_ratios,
        decay_rates: exact.decay_rates,
        residuals: exact.residuals,
        shapes: shapes.iter().flatten().copied().collect(),
        surface: Surface {
            node_ids: ids.into_iter().map(|w| u64::from_le_bytes(w) as usize).collect(),
            positions: pos.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect(),
            triangles,
            triangle_edge_nodes: edges,
        },
        material: exact.material,
        mass: exact.mass_properties,
        info: exact.solve_info,
    };
    if bank.frequencies_hz.len() != n || bank.decay_rates.len() != n {
        return Err(format!("it has {} modes, the model {n}", bank.frequencies_hz.len()));
    }
    for i in 0..n {
        if bank.damped_frequency_hz(i) as f32 != freqs[i] || bank.decay_rates[i] as f32 != decays[i] {
            return Err(format!("mode {i} differs from the model's accessors"));
        }
    }
    for (k, p) in bank.surface.positions.iter().enumerate() {
        if p.map(|x| x as f32) != positions[k] {
            return Err(format!("position {k} differs from the model's accessor"));
        }
    }
    bank.validate().map_err(|e| e.to_string())?;
    bank.shapes.shrink_to_fit();
    Ok(bank)
}
