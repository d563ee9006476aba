//! safetensors bytes → validated bank. Checks run cheapest-first: framing,
//! `format`/`format_version`, checksum, dtypes and shapes, then
//! [`ModeBank::validate`]. Nothing is indexed without a bounds check and no
//! allocation exceeds the input's size.

use super::*;
use crate::checksum::{checksum, TensorBytes};
use crate::SolveInfo;
use modal_fem::{MassProperties, Material};
use modal_mesh::Surface;
use safetensors::{tensor::Metadata, Dtype, SafeTensors};
use std::collections::HashMap;

/// Largest header the safetensors crate accepts.
const MAX_HEADER_BYTES: u64 = 100_000_000;

/// A tensor of the file: dtype, shape, little-endian bytes.
struct Raw<'a> {
    dtype: Dtype,
    shape: &'a [usize],
    data: &'a [u8],
}

/// The framing: header length `n`, parsed header, tensor data region.
fn read_header(bytes: &[u8]) -> Result<(Metadata, &[u8]), BankError> {
    let actual = bytes.len() as u64;
    let mut prefix = [0u8; 8];
    match bytes.get(..8) {
        Some(p) => prefix.copy_from_slice(p),
        None => return Err(BankError::Truncated { expected: 8, actual }),
    }
    let n = u64::from_le_bytes(prefix);
    if n > MAX_HEADER_BYTES {
        return Err(BankError::NotSafetensors(format!("header length {n} is implausible")));
    }
    if 8 + n > actual {
        return Err(BankError::Truncated { expected: 8 + n, actual });
    }
    check_extent(bytes, n as usize)?;
    match SafeTensors::read_metadata(bytes) {
        Ok((n, meta)) => Ok((meta, bytes.get(8 + n..).unwrap_or_default())),
        Err(e) => Err(BankError::NotSafetensors(e.to_string())),
    }
}

/// Checks that the tensor data announced by the header (`n` bytes after the
/// length prefix) ends exactly at the end of the file. Done here, in u128,
/// because safetensors 0.8 overflows (panics in debug builds) on headers
/// whose offsets end near `u64::MAX`.
fn check_extent(bytes: &[u8], n: usize) -> Result<(), BankError> {
    let actual = bytes.len() as u64;
    let header: serde_json::Map<String, serde_json::Value> = bytes
        .get(8..8 + n)
        .and_then(|h| serde_json::from_slice(h).ok())
        .ok_or_else(|| BankError::NotSafetensors("the header is not a JSON object".into()))?;
    let data_end = header
        .iter()
        .filter(|(k, _)| *k != "__metadata__")
        .filter_map(|(_, v)| v.get("data_offsets")?.get(1)?.as_u64())
        .max()
        .unwrap_or(0);
    let needed = 8 + n as u128 + u128::from(data_end);
    if needed > u128::from(actual) {
        Err(BankError::Truncated { expected: u64::try_from(needed).unwrap_or(u64::MAX), actual })
    } else if needed < u128::from(actual) {
        Err(BankError::NotSafetensors(format!(
            "{} bytes of trailing data after the last tensor",
            u128::from(actual) - needed
        )))
    } else {
        Ok(())
    }
}

fn check_format(meta: Option<&HashMap<String, String>>) -> Result<&HashMap<String, String>, BankError> {
    let Some(meta) = meta else {
        return Err(BankError::WrongFormat { found: None });
    };
    match meta.get(KEY_FORMAT) {
        Some(f) if f == FORMAT_NAME => {}
        other => return Err(BankError::WrongFormat { found: other.cloned() }),
    }
    match meta.get(KEY_VERSION) {
        Some(v) if *v == FORMAT_VERSION.to_string() => Ok(meta),
        Some(v) => Err(BankError::UnsupportedVersion { found: v.clone(), supported: FORMAT_VERSION }),
        None => Err(BankError::MissingMetadata(KEY_VERSION.into())),
    }
}

fn raw_tensors<'a>(meta: &'a Metadata, data: &'a [u8]) -> Result<HashMap<String, Raw<'a>>, BankError> {
    let mut out = HashMap::new();
    for (name, info) in meta.tensors() {
        let (a, b) = info.data_offsets;
        let Some(bytes) = data.get(a..b) else {
            return Err(BankError::NotSafetensors(format!("tensor '{name}' lies outside the file")));
        };
        out.insert(name, Raw { dtype: info.dtype, shape: &info.shape, data: bytes });
    }
    Ok(out)
}

fn verify_checksum(
    tensors: &HashMap<String, Raw<'_>>,
    meta: &HashMap<String, String>,
) -> Result<(), BankError> {
    let stored = meta.get(KEY_CHECKSUM).ok_or_else(|| BankError::MissingMetadata(KEY_CHECKSUM.into()))?;
    let views = tensors
        .iter()
        .map(|(name, t)| TensorBytes { name, dtype: t.dtype.to_string(), shape: t.shape, data: t.data })
        .collect();
    let computed = checksum(views, meta.iter().map(|(k, v)| (k.as_str(), v.as_str())));
    if *stored == computed {
        Ok(())
    } else {
        Err(BankError::ChecksumMismatch { stored: stored.clone(), computed })
    }
}

/// Typed, shape-checked access to the tensors.
struct Tensors<'a>(HashMap<String, Raw<'a>>);

impl<'a> Tensors<'a> {
    /// The tensor `name` with dtype `dtype` and shape `expected` (`None` =
    /// any size along that axis).
    fn get(&self, name: &str, dtype: Dtype, expected: &[Option<usize>]) -> Result<&Raw<'a>, BankError> {
        let t = self.0.get(name).ok_or_else(|| BankError::MissingTensor(name.into()))?;
        if t.dtype != dtype {
            return Err(BankError::WrongDtype {
                name: name.into(),
                found: t.dtype.to_string(),
                expected: dtype.to_string(),
            });
        }
        let fits = t.shape.len() == expected.len()
            && t.shape.iter().zip(expected).all(|(&d, e)| e.is_none_or(|e| e == d));
        if !fits {
            let dims: Vec<String> =
                expected.iter().map(|e| e.map_or("*".into(), |d| d.to_string())).collect();
            return Err(BankError::WrongShape {
                name: name.into(),
                found: t.shape.to_vec(),
                expected: format!("[{}]", dims.join(", ")),
            });
        }
        Ok(t)
    }

    fn f64s(&self, name: &str, shape: &[Option<usize>]) -> Result<Vec<f64>, BankError> {
        let t = self.get(name, Dtype::F64, shape)?;
        Ok(t.data.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap_or_default())).collect())
    }

    fn f32s(&self, name: &str, shape: &[Option<usize>]) -> Result<Vec<f32>, BankError> {
        let t = self.get(name, Dtype::F32, shape)?;
        Ok(t.data.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap_or_default())).collect())
    }

    /// Non-negative I64 values as `usize`.
    fn indices(&self, name: &str, shape: &[Option<usize>]) -> Result<Vec<usize>, BankError> {
        let t = self.get(name, Dtype::I64, shape)?;
        let cols = shape.last().copied().flatten().unwrap_or(1).max(1);
        t.data
            .chunks_exact(8)
            .enumerate()
            .map(|(i, c)| {
                let v = i64::from_le_bytes(c.try_into().unwrap_or_default());
                usize::try_from(v).map_err(|_| BankError::BadIndex {
                    field: if shape.len() == 2 {
                        format!("{name}[{}][{}]", i / cols, i % cols)
                    } else {
                        format!("{name}[{i}]")
                    },
                    value: i128::from(v),
                    count: 0,
                })
            })
            .collect()
    }

    /// Length of axis 0 of `name`, requiring the other axes to match `rest`.
    fn len(&self, name: &str, dtype: Dtype, rest: &[usize]) -> Result<usize, BankError> {
        let mut expected = vec![None];
        expected.extend(rest.iter().map(|&d| Some(d)));
        Ok(self.get(name, dtype, &expected)?.shape.first().copied().unwrap_or(0))
    }
}

fn triples(flat: Vec<usize>) -> Vec<[usize; 3]> {
    flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

fn surface(t: &Tensors<'_>) -> Result<Surface, BankError> {
    let s = t.len(T_POSITIONS, Dtype::F64, &[3])?;
    let tris = t.len(T_TRIANGLES, Dtype::I64, &[3])?;
    let positions =
        t.f64s(T_POSITIONS, &[Some(s), Some(3)])?.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let triangle_edge_nodes = match t.0.contains_key(T_EDGE_NODES) {
        true => Some(triples(t.indices(T_EDGE_NODES, &[Some(tris), Some(3)])?)),
        false => None,
    };
    Ok(Surface {
        node_ids: t.indices(T_NODE_IDS, &[Some(s)])?,
        positions,
        triangles: triples(t.indices(T_TRIANGLES, &[Some(tris), Some(3)])?),
        triangle_edge_nodes,
    })
}

fn mass(t: &Tensors<'_>) -> Result<MassProperties, BankError> {
    let c = t.f64s(T_CENTER_OF_MASS, &[Some(3)])?;
    let i = t.f64s(T_INERTIA, &[Some(3), Some(3)])?;
    let scalar = |name| t.f64s(name, &[]).map(|v| v.first().copied().unwrap_or(f64::NAN));
    let row = |r: usize| [i[3 * r], i[3 * r + 1], i[3 * r + 2]];
    Ok(MassProperties {
        volume_m3: scalar(T_VOLUME)?,
        mass_kg: scalar(T_MASS)?,
        center_of_mass_m: [c[0], c[1], c[2]],
        inertia_kg_m2: [row(0), row(1), row(2)],
    })
}

fn json<T: serde::de::DeserializeOwned>(meta: &HashMap<String, String>, key: &str) -> Result<T, BankError> {
    let text = meta.get(key).ok_or_else(|| BankError::MissingMetadata(key.into()))?;
    serde_json::from_str(text).map_err(|e| BankError::BadMetadata { key: key.into(), detail: e.to_string() })
}

fn bank(t: &Tensors<'_>, meta: &HashMap<String, String>) -> Result<ModeBank, BankError> {
    let material: Material = json(meta, KEY_MATERIAL)?;
    let info: SolveInfo = json(meta, KEY_SOLVE_INFO)?;
    let hash = meta.get(KEY_INPUT_HASH).ok_or_else(|| BankError::MissingMetadata(KEY_INPUT_HASH.into()))?;
    if *hash != info.input_hash {
        return Err(BankError::Inconsistent(format!(
            "metadata input_hash '{hash}' differs from solve_info.input_hash '{}'",
            info.input_hash
        )));
    }
    let n = t.len(T_FREQUENCIES, Dtype::F64, &[])?;
    let surface = surface(t)?;
    let s = surface.positions.len();
    let per_mode = [Some(n)];
    let bank = ModeBank {
        frequencies_hz: t.f64s(T_FREQUENCIES, &per_mode)?,
        damping_ratios: t.f64s(T_DAMPING_RATIOS, &per_mode)?,
        decay_rates: t.f64s(T_DECAY_RATES, &per_mode)?,
        residuals: t.f64s(T_RESIDUALS, &per_mode)?,
        shapes: t.f32s(T_SHAPES, &[Some(n), Some(s), Some(3)])?,
        surface,
        material,
        mass: mass(t)?,
        info,
    };
    bank.validate()?;
    Ok(bank)
}

pub(super) fn from_bytes(bytes: &[u8]) -> Result<ModeBank, BankError> {
    let (header, data) = read_header(bytes)?;
    let meta = check_format(header.metadata().as_ref())?;
    let raw = raw_tensors(&header, data)?;
    verify_checksum(&raw, meta)?;
    bank(&Tensors(raw), meta)
}
