//! Bank → safetensors bytes (deterministic).

use super::*;
use crate::checksum::{checksum, TensorBytes};
use safetensors::Dtype;
use serde_json::{json, Map, Value};
use std::collections::BTreeMap;

/// A tensor ready to be written.
struct Tensor {
    name: &'static str,
    dtype: Dtype,
    shape: Vec<usize>,
    data: Vec<u8>,
}

impl Tensor {
    fn f64(name: &'static str, shape: Vec<usize>, values: impl IntoIterator<Item = f64>) -> Self {
        let data = values.into_iter().flat_map(f64::to_le_bytes).collect();
        Tensor { name, dtype: Dtype::F64, shape, data }
    }

    fn f32(name: &'static str, shape: Vec<usize>, values: &[f32]) -> Self {
        let data = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        Tensor { name, dtype: Dtype::F32, shape, data }
    }

    fn i64(
        name: &'static str,
        shape: Vec<usize>,
        values: impl IntoIterator<Item = usize>,
    ) -> Result<Self, BankError> {
        let mut data = Vec::new();
        for (i, v) in values.into_iter().enumerate() {
            let v = i64::try_from(v).map_err(|_| BankError::OutOfRange {
                field: format!("{name}[{i}]"),
                value: v as f64,
                rule: "indices must fit in a signed 64-bit integer".into(),
            })?;
            data.extend(v.to_le_bytes());
        }
        Ok(Tensor { name, dtype: Dtype::I64, shape, data })
    }

    fn view(&self) -> TensorBytes<'_> {
        TensorBytes { name: self.name, dtype: self.dtype.to_string(), shape: &self.shape, data: &self.data }
    }
}

fn tensors(bank: &ModeBank) -> Result<Vec<Tensor>, BankError> {
    let n = bank.mode_count();
    let s = bank.surface_node_count();
    let surf = &bank.surface;
    let t = surf.triangles.len();
    let mass = &bank.mass;
    let mut out = vec![
        Tensor::f64(T_FREQUENCIES, vec![n], bank.frequencies_hz.iter().copied()),
        Tensor::f64(T_DAMPING_RATIOS, vec![n], bank.damping_ratios.iter().copied()),
        Tensor::f64(T_DECAY_RATES, vec![n], bank.decay_rates.iter().copied()),
        Tensor::f64(T_RESIDUALS, vec![n], bank.residuals.iter().copied()),
        Tensor::f32(T_SHAPES, vec![n, s, 3], &bank.shapes),
        Tensor::f64(T_POSITIONS, vec![s, 3], surf.positions.iter().flatten().copied()),
        Tensor::i64(T_TRIANGLES, vec![t, 3], surf.triangles.iter().flatten().copied())?,
        Tensor::i64(T_NODE_IDS, vec![s], surf.node_ids.iter().copied())?,
        Tensor::f64(T_CENTER_OF_MASS, vec![3], mass.center_of_mass_m),
        Tensor::f64(T_INERTIA, vec![3, 3], mass.inertia_kg_m2.iter().flatten().copied()),
        Tensor::f64(T_VOLUME, vec![], [mass.volume_m3]),
        Tensor::f64(T_MASS, vec![], [mass.mass_kg]),
    ];
    if let Some(edges) = &surf.triangle_edge_nodes {
        out.push(Tensor::i64(T_EDGE_NODES, vec![t, 3], edges.iter().flatten().copied())?);
    }
    Ok(out)
}

fn to_json<T: serde::Serialize>(key: &str, value: &T) -> Result<String, BankError> {
    serde_json::to_string(value)
        .map_err(|e| BankError::BadMetadata { key: key.into(), detail: e.to_string() })
}

fn metadata(bank: &ModeBank) -> Result<BTreeMap<String, String>, BankError> {
    let units: BTreeMap<&str, &str> = UNITS.into_iter().collect();
    Ok(BTreeMap::from([
        (KEY_FORMAT.to_string(), FORMAT_NAME.to_string()),
        (KEY_VERSION.to_string(), FORMAT_VERSION.to_string()),
        (KEY_UNITS.to_string(), to_json(KEY_UNITS, &units)?),
        (KEY_MATERIAL.to_string(), to_json(KEY_MATERIAL, &bank.material)?),
        (KEY_SOLVE_INFO.to_string(), to_json(KEY_SOLVE_INFO, &bank.info)?),
        (KEY_INPUT_HASH.to_string(), bank.info.input_hash.clone()),
        (KEY_GENERATOR.to_string(), format!("modal-bank {}", env!("CARGO_PKG_VERSION"))),
    ]))
}

/// Safetensors framing: tensors ordered by descending element size then
/// name (keeps every tensor aligned to its element size), header JSON padded
/// with spaces to a multiple of 8 bytes.
fn frame(mut tensors: Vec<Tensor>, metadata: BTreeMap<String, String>) -> Result<Vec<u8>, BankError> {
    tensors.sort_by(|a, b| b.dtype.bitsize().cmp(&a.dtype.bitsize()).then(a.name.cmp(b.name)));
    let mut header = Map::new();
    header.insert("__metadata__".into(), json!(metadata));
    let mut offset = 0usize;
    for t in &tensors {
        let end = offset + t.data.len();
        header.insert(
            t.name.into(),
            json!({ "dtype": t.dtype.to_string(), "shape": t.shape, "data_offsets": [offset, end] }),
        );
        offset = end;
    }
    let mut header = serde_json::to_vec(&Value::Object(header))
        .map_err(|e| BankError::BadMetadata { key: "__metadata__".into(), detail: e.to_string() })?;
    header.resize(header.len().next_multiple_of(8), b' ');
    let mut out = Vec::with_capacity(8 + header.len() + offset);
    out.extend((header.len() as u64).to_le_bytes());
    out.extend(header);
    for t in tensors {
        out.extend(t.data);
    }
    Ok(out)
}

pub(super) fn to_bytes(bank: &ModeBank) -> Result<Vec<u8>, BankError> {
    to_bytes_with_radiation(bank, None)
}

/// [`to_bytes`] plus an optional radiation table (tensors and metadata
/// key `radiation`, covered by the checksum).
pub(super) fn to_bytes_with_radiation(
    bank: &ModeBank,
    radiation: Option<&crate::RadiationTable>,
) -> Result<Vec<u8>, BankError> {
    bank.validate()?;
    let mut tensors = tensors(bank)?;
    let mut metadata = metadata(bank)?;
    if let Some(table) = radiation {
        table.validate_for(bank)?;
        for (name, dtype, shape, data) in super::radiation_io::tensors(table) {
            tensors.push(Tensor { name, dtype, shape, data });
        }
        metadata.insert(super::radiation_io::KEY_RADIATION.into(), super::radiation_io::metadata(table)?);
    }
    let sum = checksum(
        tensors.iter().map(Tensor::view).collect(),
        metadata.iter().map(|(k, v)| (k.as_str(), v.as_str())),
    );
    metadata.insert(KEY_CHECKSUM.into(), sum);
    frame(tensors, metadata)
}
