//! The optional radiation tensors of a version-2 bank (see
//! `crate::radiation` and docs/bank-format.md): written after the bank's
//! own tensors and covered by the same checksum; read only from a file
//! whose framing, version and checksum [`crate::ModeBank::from_bytes`]
//! already accepted.

use safetensors::{Dtype, SafeTensors};
use serde::{Deserialize, Serialize};

use crate::radiation::{ModeTransfer, RadiationTable};
use crate::BankError;

pub(crate) const T_RAD_MODES: &str = "radiation_modes";
pub(crate) const T_RAD_ORDERS: &str = "radiation_orders";
pub(crate) const T_RAD_WAVENUMBERS: &str = "radiation_wavenumbers";
pub(crate) const T_RAD_POWER: &str = "radiation_power_w";
pub(crate) const T_RAD_EFFICIENCY: &str = "radiation_efficiency";
pub(crate) const T_RAD_COEFFICIENTS: &str = "radiation_coefficients";
pub(crate) const KEY_RADIATION: &str = "radiation";
/// The time convention of every stored transfer (`crate::radiation`).
pub(crate) const CONVENTION: &str = "exp(-i omega t)";

/// The `radiation` metadata value.
#[derive(Serialize, Deserialize)]
pub(crate) struct RadiationMeta {
    pub centre_m: [f64; 3],
    pub fit_radius_m: f64,
    pub air_density_kg_m3: f64,
    pub sound_speed_m_s: f64,
    pub tolerance: f64,
    /// Always `"exp(-i omega t)"`.
    pub convention: String,
}

/// Tensors (name, dtype, shape, little-endian bytes) of `table`.
pub(crate) fn tensors(table: &RadiationTable) -> Vec<(&'static str, Dtype, Vec<usize>, Vec<u8>)> {
    let r = table.modes.len();
    let f64s = |v: &mut dyn Iterator<Item = f64>| v.flat_map(f64::to_le_bytes).collect::<Vec<u8>>();
    let i64s =
        |v: &mut dyn Iterator<Item = usize>| v.flat_map(|x| (x as i64).to_le_bytes()).collect::<Vec<u8>>();
    let c: usize = table.modes.iter().map(|m| m.coefficients.len()).sum();
    vec![
        (T_RAD_MODES, Dtype::I64, vec![r], i64s(&mut table.modes.iter().map(|m| m.mode))),
        (T_RAD_ORDERS, Dtype::I64, vec![r], i64s(&mut table.modes.iter().map(|m| m.order))),
        (T_RAD_WAVENUMBERS, Dtype::F64, vec![r], f64s(&mut table.modes.iter().map(|m| m.wavenumber))),
        (T_RAD_POWER, Dtype::F64, vec![r], f64s(&mut table.modes.iter().map(|m| m.power_w))),
        (T_RAD_EFFICIENCY, Dtype::F64, vec![r], f64s(&mut table.modes.iter().map(|m| m.efficiency))),
        (
            T_RAD_COEFFICIENTS,
            Dtype::F64,
            vec![c, 2],
            f64s(&mut table.modes.iter().flat_map(|m| m.coefficients.iter().flatten().copied())),
        ),
    ]
}

/// The `radiation` metadata JSON of `table`.
pub(crate) fn metadata(table: &RadiationTable) -> Result<String, BankError> {
    let meta = RadiationMeta {
        centre_m: table.centre_m,
        fit_radius_m: table.fit_radius_m,
        air_density_kg_m3: table.air_density_kg_m3,
        sound_speed_m_s: table.sound_speed_m_s,
        tolerance: table.tolerance,
        convention: CONVENTION.into(),
    };
    serde_json::to_string(&meta)
        .map_err(|e| BankError::BadMetadata { key: KEY_RADIATION.into(), detail: e.to_string() })
}

fn read_f64(st: &SafeTensors<'_>, name: &str, len: usize) -> Result<Vec<f64>, BankError> {
    let t = st.tensor(name).map_err(|_| BankError::MissingTensor(name.into()))?;
    if t.dtype() != Dtype::F64 {
        return Err(BankError::WrongDtype {
            name: name.into(),
            found: t.dtype().to_string(),
            expected: "F64".into(),
        });
    }
    if t.data().len() != 8 * len {
        return Err(BankError::WrongShape {
            name: name.into(),
            found: t.shape().to_vec(),
            expected: format!("{len} values"),
        });
    }
    Ok(t.data().chunks_exact(8).map(|b| f64::from_le_bytes(b.try_into().unwrap_or([0; 8]))).collect())
}

fn read_usize(st: &SafeTensors<'_>, name: &str) -> Result<Vec<usize>, BankError> {
    let t = st.tensor(name).map_err(|_| BankError::MissingTensor(name.into()))?;
    if t.dtype() != Dtype::I64 || t.shape().len() != 1 {
        return Err(BankError::WrongDtype {
            name: name.into(),
            found: t.dtype().to_string(),
            expected: "I64".into(),
        });
    }
    t.data()
        .chunks_exact(8)
        .enumerate()
        .map(|(i, b)| {
            let v = i64::from_le_bytes(b.try_into().unwrap_or([0; 8]));
            usize::try_from(v).map_err(|_| BankError::OutOfRange {
                field: format!("{name}[{i}]"),
                value: v as f64,
                rule: "must be ≥ 0".into(),
            })
        })
        .collect()
}

/// The radiation table of the verified bytes of `bank`, checked against it
/// ([`RadiationTable::validate_for`]); `None` when the file has none.
pub(crate) fn read(bytes: &[u8], bank: &crate::ModeBank) -> Result<Option<RadiationTable>, BankError> {
    let st = SafeTensors::deserialize(bytes).map_err(|e| BankError::NotSafetensors(e.to_string()))?;
    let (_, header) =
        SafeTensors::read_metadata(bytes).map_err(|e| BankError::NotSafetensors(e.to_string()))?;
    let bad = |detail: String| BankError::BadMetadata { key: KEY_RADIATION.into(), detail };
    let Some(json) = header.metadata().as_ref().and_then(|m| m.get(KEY_RADIATION)) else {
        // Tensors without their metadata would be ignored in silence, and the
        // level estimated: the file was not written by us whole.
        if st.names().iter().any(|n| n.starts_with("radiation_")) {
            return Err(bad("missing, though the file holds radiation tensors".into()));
        }
        return Ok(None);
    };
    let meta: RadiationMeta = serde_json::from_str(json).map_err(|e| bad(e.to_string()))?;
    if meta.convention != CONVENTION {
        return Err(bad(format!("convention {:?}: only {CONVENTION:?} is read", meta.convention)));
    }
    let modes = read_usize(&st, T_RAD_MODES)?;
    let orders = read_usize(&st, T_RAD_ORDERS)?;
    let r = modes.len();
    if orders.len() != r {
        return Err(BankError::WrongShape {
            name: T_RAD_ORDERS.into(),
            found: vec![orders.len()],
            expected: format!("[{r}]"),
        });
    }
    let wavenumbers = read_f64(&st, T_RAD_WAVENUMBERS, r)?;
    let power = read_f64(&st, T_RAD_POWER, r)?;
    let efficiency = read_f64(&st, T_RAD_EFFICIENCY, r)?;
    // Each order bounded by the file size before multiplying.
    let mut total = 0usize;
    for (i, &l) in orders.iter().enumerate() {
        let n =
            l.checked_add(1).and_then(|n| n.checked_mul(n)).filter(|&n| n <= bytes.len() / 16).ok_or_else(
                || BankError::OutOfRange {
                    field: format!("{T_RAD_ORDERS}[{i}]"),
                    value: l as f64,
                    rule: "too large for the file".into(),
                },
            )?;
        total = total.saturating_add(n);
    }
    let flat = read_f64(&st, T_RAD_COEFFICIENTS, total.saturating_mul(2))?;
    let mut at = 0;
    let mut entries = Vec::with_capacity(r);
    for i in 0..r {
        let n = (orders[i] + 1) * (orders[i] + 1);
        let coefficients = flat[2 * at..2 * (at + n)].chunks_exact(2).map(|c| [c[0], c[1]]).collect();
        at += n;
        entries.push(ModeTransfer {
            mode: modes[i],
            wavenumber: wavenumbers[i],
            order: orders[i],
            coefficients,
            power_w: power[i],
            efficiency: efficiency[i],
        });
    }
    let table = RadiationTable {
        centre_m: meta.centre_m,
        fit_radius_m: meta.fit_radius_m,
        air_density_kg_m3: meta.air_density_kg_m3,
        sound_speed_m_s: meta.sound_speed_m_s,
        tolerance: meta.tolerance,
        modes: entries,
    };
    table.validate_for(bank)?;
    Ok(Some(table))
}
