//! safetensors bytes → validated bank. Checks run cheapest-first: framing,
//! `format`/`format_version`, checksum, dtypes and shapes, then
//! [`ModeBank::validate`]. Nothing is indexed without a bounds check and no
//! allocation exceeds the input's size.

use super::*;
use crate::checksum::{checksum, Hasher, TensorBytes};
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
        if let Some(kind) = known_other_file(bytes) {
            return Err(BankError::OtherFile(kind));
        }
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

/// What a file that is not a bank most likely is, from its first bytes: the
/// inputs and outputs users mix up with a bank (`info bar.msh` said "header
/// length 8245886857165229348 is implausible").
fn known_other_file(bytes: &[u8]) -> Option<&'static str> {
    if bytes.starts_with(b"RIFF") {
        return Some("a WAV file");
    }
    // Up to 512 bytes, cut back to whole UTF-8 characters.
    let start = &bytes[..bytes.len().min(512)];
    let text = match std::str::from_utf8(start) {
        Ok(text) => text,
        Err(e) => std::str::from_utf8(&start[..e.valid_up_to()]).ok()?,
    };
    let text = text.trim_start();
    let first = text.split_whitespace().next().unwrap_or_default();
    // An OBJ may open with comments (an exporter's name): any vertex line tells.
    let obj = text.lines().any(|l| l.starts_with("v ") || l.starts_with("mtllib "));
    Some(match first {
        "$MeshFormat" => "a Gmsh mesh (`modal precompute` makes a bank of it)",
        "solid" => "an ASCII STL surface (`modal precompute` makes a bank of it)",
        "ply" => "a PLY surface (`modal precompute` makes a bank of it)",
        "OFF" => "an OFF surface (`modal precompute` makes a bank of it)",
        _ if obj => "an OBJ surface (`modal precompute` makes a bank of it)",
        _ if text.starts_with('#') || text.starts_with('[') || text.contains(" = ") => {
            "a text file (a scene for `modal render`, or a manifest for `modal precompute-batch`?)"
        }
        _ => return None,
    })
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
        Some(v) if (OLDEST_READABLE_VERSION..=FORMAT_VERSION).any(|n| *v == n.to_string()) => Ok(meta),
        Some(v) => Err(BankError::UnsupportedVersion { found: v.clone(), supported: FORMAT_VERSION }),
        None => Err(BankError::MissingMetadata(KEY_VERSION.into())),
    }
}

/// The tensor data region (offsets relative to its start), held in one
/// piece, or in three when one tensor was read into its own buffer: the
/// bytes before it, its bytes (starting at `split.0`), the bytes after it
/// (starting at `split.1`). Tensors never straddle pieces (safetensors
/// tensors are contiguous and disjoint).
#[derive(Clone, Copy)]
struct Region<'a> {
    pieces: [&'a [u8]; 3],
    split: (usize, usize),
}

impl<'a> Region<'a> {
    fn whole(data: &'a [u8]) -> Region<'a> {
        Region { pieces: [data, &[], &[]], split: (usize::MAX, usize::MAX) }
    }

    /// Bytes `a..b` of the region, if they lie inside one piece.
    fn get(&self, a: usize, b: usize) -> Option<&'a [u8]> {
        let (s0, s1) = self.split;
        let (piece, base) = if a < s0 || (a == s0 && b == s0) {
            (self.pieces[0], 0)
        } else if a < s1 || (a == s1 && b == s1) {
            (self.pieces[1], s0)
        } else {
            (self.pieces[2], s1)
        };
        piece.get(a.checked_sub(base)?..b.checked_sub(base)?)
    }
}

fn raw_tensors<'a>(meta: &'a Metadata, data: Region<'a>) -> Result<HashMap<String, Raw<'a>>, BankError> {
    raw_tensors_except(meta, data, None)
}

/// [`raw_tensors`] leaving out the tensor `skip` (whose bytes need not be in `data`).
fn raw_tensors_except<'a>(
    meta: &'a Metadata,
    data: Region<'a>,
    skip: Option<&str>,
) -> Result<HashMap<String, Raw<'a>>, BankError> {
    let mut out = HashMap::new();
    for (name, info) in meta.tensors().into_iter().filter(|(name, _)| Some(name.as_str()) != skip) {
        let (a, b) = info.data_offsets;
        let Some(bytes) = data.get(a, b) else {
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

/// Every field of the bank but `shapes` (left empty), whose dtype and shape
/// are checked here; the caller fills it and validates.
fn bank_without_shapes(t: &Tensors<'_>, meta: &HashMap<String, String>) -> Result<ModeBank, BankError> {
    let bank = bank_fields(t, meta)?;
    t.get(T_SHAPES, Dtype::F32, &shapes_shape(bank.mode_count(), bank.surface_node_count()))?;
    Ok(bank)
}

/// Every field of the bank but `shapes` (left empty and not looked at).
fn bank_fields(t: &Tensors<'_>, meta: &HashMap<String, String>) -> Result<ModeBank, BankError> {
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
    let per_mode = [Some(n)];
    let frequencies_hz = t.f64s(T_FREQUENCIES, &per_mode)?;
    let damping_ratios = t.f64s(T_DAMPING_RATIOS, &per_mode)?;
    let decay_rates = t.f64s(T_DECAY_RATES, &per_mode)?;
    let residuals = t.f64s(T_RESIDUALS, &per_mode)?;
    Ok(ModeBank {
        frequencies_hz,
        damping_ratios,
        decay_rates,
        residuals,
        shapes: Vec::new(),
        surface,
        material,
        mass: mass(t)?,
        info,
    })
}

/// The shape of the `shapes` tensor: modes × surface nodes × 3.
fn shapes_shape(modes: usize, nodes: usize) -> [Option<usize>; 3] {
    [Some(modes), Some(nodes), Some(3)]
}

pub(super) fn from_bytes(bytes: &[u8]) -> Result<ModeBank, BankError> {
    let (header, data) = read_header(bytes)?;
    let meta = check_format(header.metadata().as_ref())?;
    let raw = raw_tensors(&header, Region::whole(data))?;
    checked_bank(Tensors(raw), meta, |t, mut bank| {
        bank.shapes = t.f32s(T_SHAPES, &shapes_shape(bank.mode_count(), bank.surface_node_count()))?;
        bank.validate()?;
        Ok(bank)
    })
}

/// Every field but `shapes` (left empty) of a bank file held in memory, checked for
/// framing, format, dtypes and tensor shapes but **not** for the checksum nor by
/// [`ModeBank::validate`]: for a caller that starts work on the surface and mass while
/// [`from_bytes`] verifies the whole file (`crate::DeferredBank`).
pub(super) fn light_from_bytes(bytes: &[u8]) -> Result<ModeBank, BankError> {
    let (header, data) = read_header(bytes)?;
    let meta = check_format(header.metadata().as_ref())?;
    let raw = raw_tensors(&header, Region::whole(data))?;
    bank_without_shapes(&Tensors(raw), meta)
}

/// The safetensors header of a file read from its current position (the start),
/// and the header's length `n`; `None` unless the tensor data announced ends
/// exactly at the end of the file. The file is left at the start of the data.
fn file_header(file: &mut std::fs::File) -> Option<(Metadata, u64)> {
    use std::io::Read;
    let len = file.metadata().ok()?.len();
    let mut prefix = [0u8; 8];
    file.read_exact(&mut prefix).ok()?;
    let n = u64::from_le_bytes(prefix);
    if n > MAX_HEADER_BYTES || 8 + n > len {
        return None;
    }
    let mut head = vec![0u8; n as usize];
    file.read_exact(&mut head).ok()?;
    let header: Metadata = serde_json::from_slice(&head).ok()?;
    (8 + n + header.data_len() as u64 == len).then_some((header, n))
}

/// [`light_from_bytes`] for a file, reading only the header and the tensors
/// other than `shapes` (≈ 5 % of a TET10 bank's bytes). `None` for anything
/// unusual (the caller then reads the whole file for the exact error).
pub(super) fn light_from_file(file: &mut std::fs::File) -> Option<ModeBank> {
    use std::io::{Read, Seek, SeekFrom};
    file.seek(SeekFrom::Start(0)).ok()?;
    let (header, n) = file_header(file)?;
    let meta = check_format(header.metadata().as_ref()).ok()?;
    let shapes = header.info(T_SHAPES).filter(|i| i.dtype == Dtype::F32)?;
    let (a, b) = shapes.data_offsets;
    let mut before = vec![0u8; a];
    file.read_exact(&mut before).ok()?;
    let mut after = vec![0u8; header.data_len().checked_sub(b)?];
    file.seek(SeekFrom::Start(8 + n + b as u64)).ok()?;
    file.read_exact(&mut after).ok()?;
    let region = Region { pieces: [&before, &[], &after], split: (a, b) };
    let t = Tensors(raw_tensors_except(&header, region, Some(T_SHAPES)).ok()?);
    let bank = bank_fields(&t, meta).ok()?;
    (shapes.shape == [bank.mode_count(), bank.surface_node_count(), 3]).then_some(bank)
}

/// Verifies the checksum on one thread while the other decodes the bank's
/// fields but `shapes` and hands them to `finish`; a checksum mismatch is
/// reported before any other error.
fn checked_bank(
    t: Tensors<'_>,
    meta: &HashMap<String, String>,
    finish: impl FnOnce(&Tensors<'_>, ModeBank) -> Result<ModeBank, BankError> + Send,
) -> Result<ModeBank, BankError> {
    let (sum, bank) =
        rayon::join(|| verify_checksum(&t.0, meta), || finish(&t, bank_without_shapes(&t, meta)?));
    sum?;
    bank
}

/// Bytes read per piece of the `shapes` tensor by [`from_file`].
const READ_PIECE: usize = 1 << 20;

/// [`from_bytes`] for a file, reading the `shapes` tensor (most of a bank's
/// bytes) straight into the bank's own buffer instead of reading the whole
/// file into memory and converting it, in pieces on a second thread while
/// this one hashes the pieces already read. Same checks, same result as
/// [`from_bytes`] on the file's bytes; `None` for anything unusual — any
/// error, an I/O failure, a file that changes length while read, a layout
/// where a tensor hashed before `shapes` is stored after it — so the caller
/// falls back to [`from_bytes`] for the exact error.
pub(super) fn from_file(file: &mut std::fs::File) -> Option<ModeBank> {
    use std::io::Read;
    let (header, _) = file_header(file)?;
    let meta = check_format(header.metadata().as_ref()).ok()?;
    let stored = meta.get(KEY_CHECKSUM)?;
    let shapes = header.info(T_SHAPES).filter(|i| i.dtype == Dtype::F32)?;
    let (a, b) = shapes.data_offsets;
    // The tensors in checksum (name) order, before and after `shapes`.
    let mut named: Vec<(String, &safetensors::tensor::TensorInfo)> = header.tensors().into_iter().collect();
    named.sort_by(|x, y| x.0.cmp(&y.0));
    let (pre, post): (Vec<_>, Vec<_>) = named
        .into_iter()
        .filter(|(name, _)| name != T_SHAPES)
        .partition(|(name, _)| name.as_str() < T_SHAPES);
    let mut before = vec![0u8; a];
    file.read_exact(&mut before).ok()?;
    let mut hasher = Hasher::new();
    for (name, info) in &pre {
        let (x, y) = info.data_offsets;
        let data = before.get(x..y)?;
        hasher.tensor(&TensorBytes { name, dtype: info.dtype.to_string(), shape: &info.shape, data });
    }
    hasher.tensor_header(T_SHAPES, &shapes.dtype.to_string(), &shapes.shape, b - a);
    let mut values = vec![0f32; (b - a) / 4];
    let mut after = vec![0u8; header.data_len() - b];
    let (bytes, rest, source) = (bytemuck::cast_slice_mut::<f32, u8>(&mut values), &mut after, &mut *file);
    let read = std::thread::scope(|scope| {
        let (tx, rx) = std::sync::mpsc::sync_channel::<&[u8]>(4);
        let reader = scope.spawn(move || -> std::io::Result<()> {
            for piece in bytes.chunks_mut(READ_PIECE) {
                source.read_exact(piece)?;
                let piece: &[u8] = piece;
                if tx.send(piece).is_err() {
                    break;
                }
            }
            source.read_exact(rest)
        });
        rx.into_iter().for_each(|piece| hasher.data(piece));
        reader.join()
    });
    read.ok()?.ok()?;
    if file.read(&mut [0u8]).ok()? != 0 {
        return None;
    }
    let region = Region { pieces: [&before, bytemuck::cast_slice(&values), &after], split: (a, b) };
    let t = Tensors(raw_tensors(&header, region).ok()?);
    let (sum, fields) = rayon::join(
        || {
            for (name, _) in &post {
                let r = t.0.get(name)?;
                hasher.tensor(&TensorBytes {
                    name,
                    dtype: r.dtype.to_string(),
                    shape: r.shape,
                    data: r.data,
                });
            }
            Some(hasher.finish(meta.iter().map(|(k, v)| (k.as_str(), v.as_str()))))
        },
        || bank_without_shapes(&t, meta),
    );
    if sum.as_ref() != Some(stored) {
        return None;
    }
    let mut bank = fields.ok()?;
    drop(t);
    // The buffer holds the file's little-endian bytes: native order now.
    values.iter_mut().for_each(|x| *x = f32::from_bits(u32::from_le(x.to_bits())));
    bank.shapes = values;
    bank.validate().ok()?;
    Some(bank)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SolveInfo;
    use modal_fem::{MassProperties, Material};

    fn bank(modes: usize) -> ModeBank {
        let surface = Surface {
            node_ids: vec![10, 11, 12, 13],
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            triangle_edge_nodes: None,
        };
        let mut bank = ModeBank {
            frequencies_hz: (0..modes).map(|i| 100.0 * (i + 1) as f64).collect(),
            damping_ratios: Vec::new(),
            decay_rates: Vec::new(),
            residuals: vec![1e-10; modes],
            shapes: (0..modes * 12).map(|k| (k as f32 * 0.37).sin()).collect(),
            surface,
            material: Material::preset("steel").expect("steel"),
            mass: MassProperties {
                volume_m3: 1.0 / 6.0,
                mass_kg: 1300.0,
                center_of_mass_m: [0.25; 3],
                inertia_kg_m2: [[10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 0.0, 10.0]],
            },
            info: SolveInfo::default(),
        };
        bank.recompute_damping();
        bank
    }

    #[test]
    fn a_good_file_takes_the_direct_path() {
        let dir = tempfile::tempdir().expect("temp dir");
        // 30 000 modes: 1.4 MB of shapes, read in two pieces.
        for modes in [0, 1, 6, 30_000] {
            let original = bank(modes);
            let path = dir.path().join("b.bank");
            original.save(&path).expect("save");
            let mut file = std::fs::File::open(&path).expect("open");
            assert!(from_file(&mut file) == Some(original), "{modes} modes");
        }
    }

    #[test]
    fn region_pieces_serve_the_tensors_inside_them() {
        let data: Vec<u8> = (0..20).collect();
        let r = Region { pieces: [&data[..8], &data[8..16], &data[16..]], split: (8, 16) };
        assert_eq!(r.get(0, 8), Some(&data[..8]));
        assert_eq!(r.get(8, 16), Some(&data[8..16]));
        assert_eq!(r.get(16, 20), Some(&data[16..]));
        assert_eq!(r.get(8, 8), Some(&[][..]));
        assert_eq!(r.get(4, 12), None, "straddles two pieces");
        assert_eq!(r.get(18, 24), None, "beyond the end");
        assert_eq!(Region::whole(&data).get(3, 19), Some(&data[3..19]));
    }
}
