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

use modal_bank::{ModeBank, ModeTransfer, RadiationTable, SolveInfo};
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
    /// Its acoustic transfer, when the exact side data carries one.
    pub radiation: Option<RadiationTable>,
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

/// Whether the glTF file at `path` carries a modal model (a non-empty
/// model array in the `KHR_audio_rigid_bodies` root extension, or its
/// legacy name): then it is a bank; without one it is only geometry, to be
/// meshed and solved (the draft lets a file hold acoustic materials and
/// surfaces alone).
pub fn holds_modal_model(path: &Path) -> Result<bool, ExportError> {
    let bytes =
        std::fs::read(path).map_err(|source| ExportError::Read { path: path.to_path_buf(), source })?;
    let gltf = gltf::Gltf::from_slice(&bytes).map_err(|e| ExportError::Gltf(e.to_string()))?;
    let has_models = |root: Option<&Value>| {
        root.and_then(|r| r.get("modalModels").or_else(|| r.get("models")))
            .and_then(Value::as_array)
            .is_some_and(|models| !models.is_empty())
    };
    Ok(has_models(gltf.extension_value(EXTENSION)) || has_models(gltf.extension_value(LEGACY_EXTENSION)))
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
    #[serde(default)]
    radiation: Option<Value>,
}

/// `extras.modal.radiation`, written by `radiation_side_data` (write.rs).
#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct RadiationJson {
    centre_m: [f64; 3],
    fit_radius_m: f64,
    air_density_kg_m3: f64,
    #[serde(rename = "soundSpeedMS")]
    sound_speed_m_s: f64,
    tolerance: f64,
    modes: Vec<usize>,
    wavenumbers: Vec<f64>,
    orders: Vec<usize>,
    power_w: Vec<f64>,
    efficiency: Vec<f64>,
    coefficients_f64: usize,
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

fn mass_properties(
    model: &ModelJson,
    density: f64,
    warnings: &mut Vec<String>,
) -> Result<MassProperties, ExportError> {
    let Some(m) = &model.mass_properties else {
        warnings.push("the model has no massProperties: mass, centre of mass and inertia read as 0".into());
        return Ok(MassProperties {
            volume_m3: 0.0,
            mass_kg: 0.0,
            center_of_mass_m: [0.0; 3],
            inertia_kg_m2: [[0.0; 3]; 3],
        });
    };
    // The draft's schema: mass > 0, principal moments ≥ 0.
    if !(m.mass.is_finite() && m.mass > 0.0) {
        return Err(bad(format!("massProperties.mass = {} kg must be positive", m.mass)));
    }
    if let Some(i) = m.inertia_diagonal.iter().position(|&j| !(j.is_finite() && j >= 0.0)) {
        return Err(bad(format!(
            "massProperties.inertiaDiagonal[{i}] = {} kg·m² must be ≥ 0",
            m.inertia_diagonal[i]
        )));
    }
    Ok(MassProperties {
        volume_m3: m.mass / density,
        mass_kg: m.mass,
        center_of_mass_m: m.center_of_mass,
        inertia_kg_m2: inertia::tensor(m.inertia_diagonal, m.inertia_orientation),
    })
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
    let mass = mass_properties(model, material.density_kg_m3, &mut warnings)?;
    if let Some(exact) = model.extras.as_ref().and_then(|e| e.get(EXTRAS_KEY)) {
        let khr = Khr { freqs: &freqs, decays: &decays, positions: &positions, shapes: &shapes };
        match exact_bank(&doc, exact, &khr).and_then(|(bank, radiation)| {
            agrees_with_khr(&bank, &material, model).map(|()| (bank, radiation))
        }) {
            Ok((bank, radiation)) => {
                let radiation = radiation.unwrap_or_else(|why| {
                    warnings.push(format!("extras.{EXTRAS_KEY}.radiation is ignored: {why}"));
                    None
                });
                let name = model.name.clone();
                return Ok(Imported { bank, radiation, exact: true, model: index, name, warnings });
            }
            Err(why) => warnings.push(format!("extras.{EXTRAS_KEY} is ignored: {why}")),
        }
    }
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
    Ok(Imported { bank, radiation: None, exact: false, model: index, name: model.name.clone(), warnings })
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

/// The model's KHR accessors, against which the exact side data is checked.
struct Khr<'a> {
    freqs: &'a [f32],
    decays: &'a [f32],
    positions: &'a [[f32; 3]],
    shapes: &'a [[f32; 3]],
}

/// The acoustic transfer of the side data: `Ok(None)` when none is stored,
/// `Err` when it cannot be used (the bank still can).
type SideRadiation = Result<Option<RadiationTable>, String>;

/// The exact bank of `extras.modal`, if it agrees with the KHR accessors,
/// and its acoustic transfer.
fn exact_bank(doc: &Doc, extras: &Value, khr: &Khr) -> Result<(ModeBank, SideRadiation), String> {
    let Khr { freqs, decays, positions, shapes } = *khr;
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
    let radiation = match &exact.radiation {
        None => Ok(None),
        Some(value) => radiation_table(doc, value, &bank).map(Some),
    };
    Ok((bank, radiation))
}

/// Whether the exact bank's material and mass are the KHR ones: another
/// tool editing the file changes those and leaves our side data alone, so
/// a difference means the KHR data are the user's (compared exactly: both
/// were written from the same f64 values; the inertia to rounding, since
/// the KHR data hold it as principal moments and axes).
fn agrees_with_khr(bank: &ModeBank, material: &Material, model: &ModelJson) -> Result<(), String> {
    let ours = &bank.material;
    for (what, exact, khr) in [
        ("density", ours.density_kg_m3, material.density_kg_m3),
        ("youngsModulus", ours.youngs_pa, material.youngs_pa),
        ("poissonRatio", ours.poisson, material.poisson),
        ("alpha", ours.alpha, material.alpha),
        ("beta", ours.beta, material.beta),
    ] {
        if exact != khr {
            return Err(format!("the acoustic material's {what} is {khr}, the side data's {exact}"));
        }
    }
    let Some(m) = &model.mass_properties else { return Ok(()) };
    if m.mass != bank.mass.mass_kg || m.center_of_mass != bank.mass.center_of_mass_m {
        return Err(format!(
            "massProperties (mass {} kg, centre {:?}) differ from the side data's ({} kg, {:?})",
            m.mass, m.center_of_mass, bank.mass.mass_kg, bank.mass.center_of_mass_m
        ));
    }
    let khr_inertia = inertia::tensor(m.inertia_diagonal, m.inertia_orientation);
    let scale = bank.mass.inertia_kg_m2.iter().flatten().fold(0.0f64, |a, &x| a.max(x.abs()));
    let off = (0..9).map(|k| (khr_inertia[k / 3][k % 3] - bank.mass.inertia_kg_m2[k / 3][k % 3]).abs());
    if off.fold(0.0f64, f64::max) > 1e-9 * scale.max(f64::MIN_POSITIVE) {
        return Err("massProperties' inertia differs from the side data's".into());
    }
    Ok(())
}

/// The acoustic transfer of `extras.modal.radiation` for `bank`.
fn radiation_table(doc: &Doc, value: &Value, bank: &ModeBank) -> Result<RadiationTable, String> {
    let r: RadiationJson = serde_json::from_value(value.clone()).map_err(|e| e.to_string())?;
    let count = r.modes.len();
    if [r.wavenumbers.len(), r.orders.len(), r.power_w.len(), r.efficiency.len()].iter().any(|&l| l != count)
    {
        return Err(format!("its per-mode arrays differ in length from its {count} modes"));
    }
    // Each order's (L+1)² coefficients, bounded before any allocation.
    let sizes: Option<Vec<usize>> = r.orders.iter().map(|&l| l.checked_add(1)?.checked_mul(l + 1)).collect();
    let sizes = sizes.ok_or("an order is absurdly large")?;
    let total = sizes.iter().try_fold(0usize, |a, &n| a.checked_add(n)).ok_or("too many coefficients")?;
    let bytes = doc.view(r.coefficients_f64).map_err(|e| e.to_string())?;
    let words =
        le_words::<8>(bytes, total.checked_mul(2).ok_or("too many coefficients")?, "coefficientsF64")?;
    let values: Vec<f64> = words.into_iter().map(f64::from_le_bytes).collect();
    let mut pairs = values.chunks_exact(2).map(|c| [c[0], c[1]]);
    let modes = (0..count)
        .map(|i| ModeTransfer {
            mode: r.modes[i],
            wavenumber: r.wavenumbers[i],
            order: r.orders[i],
            coefficients: pairs.by_ref().take(sizes[i]).collect(),
            power_w: r.power_w[i],
            efficiency: r.efficiency[i],
        })
        .collect();
    let table = RadiationTable {
        centre_m: r.centre_m,
        fit_radius_m: r.fit_radius_m,
        air_density_kg_m3: r.air_density_kg_m3,
        sound_speed_m_s: r.sound_speed_m_s,
        tolerance: r.tolerance,
        modes,
    };
    table.validate_for(bank).map_err(|e| e.to_string())?;
    Ok(table)
}
