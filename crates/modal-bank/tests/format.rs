//! The bank file: round trips, determinism, and every way a file can be bad.

mod common;

use common::{linear_bank, quadratic_bank};
use modal_bank::{BankError, ModeBank, SolveInfo};
use safetensors::{tensor::TensorView, Dtype, SafeTensors};
use sha2::{Digest, Sha256};
use std::collections::HashMap;

/// Independent implementation of the checksum as `docs/bank-format.md`
/// specifies it, over a parsed file.
fn spec_checksum(bytes: &[u8]) -> String {
    let st = SafeTensors::deserialize(bytes).expect("valid safetensors");
    let (_, header) = SafeTensors::read_metadata(bytes).expect("valid header");
    let meta = header.metadata().clone().unwrap_or_default();
    spec_checksum_of(&st.tensors(), &meta)
}

fn spec_checksum_of(tensors: &[(String, TensorView<'_>)], meta: &HashMap<String, String>) -> String {
    fn string(h: &mut Sha256, s: &[u8]) {
        h.update((s.len() as u64).to_le_bytes());
        h.update(s);
    }
    let mut h = Sha256::new();
    string(&mut h, b"modal-bank-checksum-v1");
    let mut tensors: Vec<_> = tensors.iter().collect();
    tensors.sort_by(|a, b| a.0.cmp(&b.0));
    for (name, t) in tensors {
        string(&mut h, name.as_bytes());
        string(&mut h, t.dtype().to_string().as_bytes());
        h.update((t.shape().len() as u64).to_le_bytes());
        for &d in t.shape() {
            h.update((d as u64).to_le_bytes());
        }
        string(&mut h, t.data());
    }
    let mut entries: Vec<_> = meta.iter().filter(|(k, _)| *k != "checksum").collect();
    entries.sort();
    for (k, v) in entries {
        string(&mut h, k.as_bytes());
        string(&mut h, v.as_bytes());
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// Re-frames `bytes` with `edit` applied to its tensors and metadata; the
/// checksum is recomputed unless `edit` sets one itself.
fn rewrite(
    bytes: &[u8],
    edit: impl FnOnce(&mut Vec<(String, Dtype, Vec<usize>, Vec<u8>)>, &mut HashMap<String, String>),
) -> Vec<u8> {
    let st = SafeTensors::deserialize(bytes).expect("valid safetensors");
    let (_, header) = SafeTensors::read_metadata(bytes).expect("valid header");
    let mut meta = header.metadata().clone().unwrap_or_default();
    let mut tensors: Vec<_> = st
        .tensors()
        .into_iter()
        .map(|(n, t)| (n, t.dtype(), t.shape().to_vec(), t.data().to_vec()))
        .collect();
    let old_sum = meta.get("checksum").cloned();
    edit(&mut tensors, &mut meta);
    let views: Vec<(String, TensorView<'_>)> = tensors
        .iter()
        .map(|(n, d, s, b)| (n.clone(), TensorView::new(*d, s.clone(), b).expect("consistent tensor")))
        .collect();
    if meta.get("checksum") == old_sum.as_ref() {
        let sum = spec_checksum_of(&views, &meta);
        meta.insert("checksum".into(), sum);
    }
    safetensors::serialize(views, Some(meta)).expect("serializable")
}

fn assert_bit_identical(a: &ModeBank, b: &ModeBank) {
    assert_eq!(a, b);
    let bits64 = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits64(&a.frequencies_hz), bits64(&b.frequencies_hz));
    assert_eq!(bits64(&a.damping_ratios), bits64(&b.damping_ratios));
    assert_eq!(
        a.shapes.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
        b.shapes.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
    );
    assert_eq!(a.material.youngs_pa.to_bits(), b.material.youngs_pa.to_bits());
    assert_eq!(a.info.assemble_s.to_bits(), b.info.assemble_s.to_bits());
}

#[test]
fn linear_bank_round_trips_bit_identical() {
    let mut bank = linear_bank(5);
    // Values that need care: -0.0, a subnormal, the largest f32.
    bank.shapes[0] = -0.0;
    bank.shapes[1] = f32::from_bits(1);
    bank.shapes[2] = f32::MAX;
    bank.material.alpha = 0.1 + 0.2; // not exactly representable in few digits
    bank.recompute_damping();
    let back = ModeBank::from_bytes(&bank.to_bytes().unwrap()).unwrap();
    assert_bit_identical(&bank, &back);
    assert_eq!(back.shapes[0].to_bits(), (-0.0f32).to_bits());
}

#[test]
fn quadratic_bank_round_trips_with_edge_nodes() {
    let bank = quadratic_bank(3);
    let back = ModeBank::from_bytes(&bank.to_bytes().unwrap()).unwrap();
    assert_bit_identical(&bank, &back);
    assert_eq!(back.surface.triangle_edge_nodes.as_ref().map(Vec::len), Some(4));
}

#[test]
fn empty_banks_round_trip() {
    let no_modes = linear_bank(0);
    assert_eq!(ModeBank::from_bytes(&no_modes.to_bytes().unwrap()).unwrap(), no_modes);
    let mut nothing = linear_bank(0);
    nothing.surface = Default::default();
    nothing.mass = common::cube_mass(0.0, 1.0);
    assert_eq!(ModeBank::from_bytes(&nothing.to_bytes().unwrap()).unwrap(), nothing);
}

#[test]
fn writer_is_deterministic_and_checksum_matches_spec() {
    let bank = quadratic_bank(4);
    let a = bank.to_bytes().unwrap();
    assert_eq!(a, bank.clone().to_bytes().unwrap());
    let (_, header) = SafeTensors::read_metadata(&a).unwrap();
    let meta = header.metadata().clone().unwrap();
    assert_eq!(meta["checksum"], spec_checksum(&a));
    assert_eq!(meta["format"], "modal-bank");
    assert_eq!(meta["format_version"], "2");
    assert_eq!(meta["input_hash"], bank.info.input_hash);
    // Every tensor starts aligned to its element size (zero-copy readers).
    for (name, t) in SafeTensors::deserialize(&a).unwrap().tensors() {
        let offset = t.data().as_ptr() as usize - a.as_ptr() as usize;
        assert_eq!(offset % (t.dtype().bitsize() / 8), 0, "{name} misaligned");
    }
}

#[test]
fn file_round_trip_leaves_no_temporary_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bar.bank");
    let bank = linear_bank(4);
    bank.save(&path).unwrap();
    bank.save(&path).unwrap(); // overwrite
    assert_eq!(ModeBank::load(&path).unwrap(), bank);
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, vec![std::ffi::OsString::from("bar.bank")]);
}

#[test]
fn failed_save_leaves_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("is_a_dir");
    std::fs::create_dir(&target).unwrap();
    let err = linear_bank(2).save(&target).unwrap_err();
    assert!(matches!(err, BankError::Write { .. }), "{err}");
    let mut bad = linear_bank(2);
    bad.frequencies_hz[1] = f64::NAN;
    let err = bad.save(dir.path().join("bad.bank")).unwrap_err();
    assert!(matches!(err, BankError::NonFinite { .. }), "{err}");
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, vec![std::ffi::OsString::from("is_a_dir")]);
}

#[test]
fn load_reports_missing_path_and_directory() {
    let dir = tempfile::tempdir().unwrap();
    let err = ModeBank::load(dir.path().join("nope.bank")).unwrap_err();
    assert!(matches!(err, BankError::Read { .. }) && err.to_string().contains("nope.bank"), "{err}");
    let err = ModeBank::load(dir.path()).unwrap_err();
    assert!(matches!(err, BankError::NotAFile { .. }), "{err}");
}

/// A mesh, a surface, a WAV or a scene given where a bank goes says what
/// it is ("header length 8245886857165229348 is implausible" did not).
#[test]
fn files_mixed_up_with_a_bank_are_named() {
    let cases: [(&[u8], &str); 6] = [
        (b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n", "a Gmsh mesh"),
        (b"# Blender\nv 0 0 0\nv 1 0 0\nf 1 2 3\n", "an OBJ surface"),
        (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "an OBJ surface"),
        (b"solid bar\n  facet normal 0 0 1\n", "an ASCII STL surface"),
        (b"RIFF\x24\x00\x00\x00WAVEfmt ", "a WAV file"),
        (b"duration = 1.0\nsample_rate = 48000\n", "a text file"),
    ];
    for (bytes, kind) in cases {
        let err = ModeBank::from_bytes(bytes).unwrap_err();
        assert!(matches!(err, BankError::OtherFile(_)), "{err:?}");
        assert!(err.to_string().starts_with(&format!("this is {kind}")), "{err}");
    }
    // Unknown bytes keep the plain framing error.
    let err = ModeBank::from_bytes(&[0xff; 64]).unwrap_err();
    assert!(matches!(err, BankError::NotSafetensors(_)), "{err:?}");
}

#[test]
fn bit_flip_in_tensor_data_is_a_checksum_mismatch() {
    let bytes = linear_bank(3).to_bytes().unwrap();
    let header_len = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    for pos in [8 + header_len, 8 + header_len + 100, bytes.len() - 1] {
        let mut bad = bytes.clone();
        bad[pos] ^= 0x10;
        let err = ModeBank::from_bytes(&bad).unwrap_err();
        assert!(matches!(err, BankError::ChecksumMismatch { .. }), "byte {pos}: {err}");
        assert_eq!(err.to_string(), "bank is corrupted: checksum mismatch");
    }
}

#[test]
fn bit_flip_in_header_is_a_parse_error() {
    let mut bad = linear_bank(3).to_bytes().unwrap();
    bad[8] ^= 0x01; // the opening '{' of the JSON header
    let err = ModeBank::from_bytes(&bad).unwrap_err();
    assert!(matches!(err, BankError::NotSafetensors(_)), "{err}");
}

#[test]
fn metadata_edit_is_a_checksum_mismatch() {
    let bytes = linear_bank(3).to_bytes().unwrap();
    // Same length so the framing stays valid: change a digit of E.
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let at = text.find("200000000000").expect("E in header");
    let mut bad = bytes.clone();
    bad[at] = b'3';
    let err = ModeBank::from_bytes(&bad).unwrap_err();
    assert!(matches!(err, BankError::ChecksumMismatch { .. }), "{err}");
}

#[test]
fn every_truncation_is_reported_as_truncated() {
    let bytes = quadratic_bank(2).to_bytes().unwrap();
    for len in 0..bytes.len() {
        match ModeBank::from_bytes(&bytes[..len]) {
            Err(BankError::Truncated { expected, actual }) => {
                assert_eq!(actual, len as u64);
                assert!(expected > actual, "len {len}");
            }
            other => panic!("length {len}: expected Truncated, got {other:?}"),
        }
    }
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(matches!(ModeBank::from_bytes(&longer), Err(BankError::NotSafetensors(_))));
}

#[test]
fn every_single_bit_flip_is_rejected_or_harmless() {
    let bank = linear_bank(1);
    let bytes = bank.to_bytes().unwrap();
    for pos in 0..bytes.len() {
        for bit in 0..8 {
            let mut bad = bytes.clone();
            bad[pos] ^= 1 << bit;
            if let Ok(back) = ModeBank::from_bytes(&bad) {
                assert_eq!(back, bank, "flip of bit {bit} at byte {pos} changed the bank silently");
            }
        }
    }
}

#[test]
fn random_garbage_never_panics() {
    let noise = common::pseudo_random(99, 4096);
    let garbage: Vec<u8> = noise.iter().map(|v| (v * 127.0 + 128.0) as u8).collect();
    for len in [0, 1, 7, 8, 9, 64, 4096] {
        assert!(ModeBank::from_bytes(&garbage[..len]).is_err());
    }
    // A plausible length prefix followed by garbage.
    let mut framed = 100u64.to_le_bytes().to_vec();
    framed.extend(&garbage[..200]);
    assert!(matches!(ModeBank::from_bytes(&framed), Err(BankError::NotSafetensors(_))));
    let text = b"this is not a bank, just text\n";
    assert!(matches!(ModeBank::from_bytes(text), Err(BankError::NotSafetensors(_))));
}

#[test]
fn plain_safetensors_file_is_not_a_bank() {
    let data = [0u8; 8];
    let view = TensorView::new(Dtype::F64, vec![1], &data).unwrap();
    let bytes = safetensors::serialize([("x", view)], None).unwrap();
    let err = ModeBank::from_bytes(&bytes).unwrap_err();
    assert!(matches!(err, BankError::WrongFormat { found: None }), "{err}");
    assert!(err.to_string().contains("not a modal bank"), "{err}");
}

#[test]
fn other_format_version_names_the_supported_one() {
    let bytes = rewrite(&linear_bank(2).to_bytes().unwrap(), |_, meta| {
        meta.insert("format_version".into(), "3".into());
    });
    let err = ModeBank::from_bytes(&bytes).unwrap_err();
    assert!(matches!(err, BankError::UnsupportedVersion { supported: 2, .. }), "{err}");
    assert_eq!(err.to_string(), "unsupported bank format version \"3\" (this build reads versions 1 to 2)");
}

#[test]
fn version_1_banks_still_load_without_radiation() {
    let bank = linear_bank(2);
    let bytes = rewrite(&bank.to_bytes().unwrap(), |_, meta| {
        meta.insert("format_version".into(), "1".into());
    });
    let (loaded, table) = ModeBank::from_bytes_with_radiation(&bytes).unwrap();
    assert_bit_identical(&bank, &loaded);
    assert!(table.is_none());
}

/// A table that fits `bank` (`RadiationTable::validate_for`): centred in its
/// surface's box, fitted at twice its radius, each mode's own wavenumber.
fn radiation_table(bank: &ModeBank) -> modal_bank::RadiationTable {
    let p = &bank.surface.positions;
    let centre = [0, 1, 2].map(|q| p.iter().map(|x| x[q]).sum::<f64>() / p.len() as f64);
    let radius =
        p.iter().map(|x| (0..3).map(|q| (x[q] - centre[q]).powi(2)).sum::<f64>().sqrt()).fold(0.0, f64::max);
    let c = 343.0;
    let modes = (0..bank.mode_count())
        .map(|i| modal_bank::ModeTransfer {
            mode: i,
            wavenumber: 2.0 * std::f64::consts::PI * bank.frequencies_hz[i] / c,
            order: i,
            coefficients: (0..(i + 1) * (i + 1)).map(|j| [j as f64 * 0.5, -(j as f64) / 3.0]).collect(),
            power_w: 1e-3 / (1.0 + i as f64),
            efficiency: 0.1 * i as f64,
        })
        .collect();
    modal_bank::RadiationTable {
        centre_m: centre,
        fit_radius_m: 2.0 * radius,
        air_density_kg_m3: 1.21,
        sound_speed_m_s: c,
        tolerance: 0.01,
        modes,
    }
}

#[test]
fn radiation_table_round_trips_bit_identical_under_the_checksum() {
    let bank = linear_bank(3);
    let table = radiation_table(&bank);
    let bytes = bank.to_bytes_with_radiation(&table).unwrap();
    let (loaded, got) = ModeBank::from_bytes_with_radiation(&bytes).unwrap();
    assert_bit_identical(&bank, &loaded);
    assert_eq!(got.as_ref(), Some(&table));
    assert_eq!(got.unwrap().mode(2).unwrap().coefficients.len(), 9);
    // Plain readers see the same bank; the spec checksum covers the new tensors.
    assert_bit_identical(&bank, &ModeBank::from_bytes(&bytes).unwrap());
    assert_eq!(
        spec_checksum(&bytes),
        SafeTensors::read_metadata(&bytes).unwrap().1.metadata().as_ref().unwrap()["checksum"]
    );
    let mut flipped = bytes.clone();
    let n = flipped.len();
    flipped[n - 3] ^= 0x10; // inside radiation_coefficients or another tensor: caught
    assert!(ModeBank::from_bytes_with_radiation(&flipped).is_err());
    // A table naming a mode the bank lacks is refused when writing.
    let mut bad = table.clone();
    bad.modes[0].mode = 99;
    assert!(bank.to_bytes_with_radiation(&bad).is_err());
    let mut bad = table.clone();
    bad.modes[1].coefficients.pop();
    assert!(bank.to_bytes_with_radiation(&bad).is_err());
    // Finite but not this bank's: a centre far away, a fit sphere inside the
    // body, a wavenumber of another frequency (each gave NaN or wrong gains).
    let mut far = table.clone();
    far.centre_m[1] = 1e300;
    let mut inside = table.clone();
    inside.fit_radius_m *= 0.25;
    let mut detuned = table.clone();
    detuned.modes[2].wavenumber *= 1.5;
    for (bad, field) in [(far, "centre_m"), (inside, "fit_radius_m"), (detuned, "radiation_wavenumbers[2]")] {
        let err = bank.to_bytes_with_radiation(&bad).unwrap_err().to_string();
        assert!(err.contains(field), "{err}");
    }
}

#[test]
fn rewritten_file_with_valid_checksum_loads() {
    // The test's own checksum (written from the spec) is accepted by the reader.
    let bank = quadratic_bank(2);
    let bytes = rewrite(&bank.to_bytes().unwrap(), |_, _| {});
    assert_eq!(ModeBank::from_bytes(&bytes).unwrap(), bank);
}

#[test]
fn missing_tensor_wrong_dtype_and_wrong_shape_are_named() {
    let bytes = linear_bank(2).to_bytes().unwrap();
    let missing = rewrite(&bytes, |t, _| t.retain(|(n, ..)| n != "residuals"));
    let err = ModeBank::from_bytes(&missing).unwrap_err();
    assert!(matches!(&err, BankError::MissingTensor(n) if n == "residuals"), "{err}");

    let as_f32 = rewrite(&bytes, |t, _| {
        let r = t.iter_mut().find(|(n, ..)| n == "residuals").unwrap();
        let vals: Vec<u8> =
            r.3.chunks(8)
                .flat_map(|c| (f64::from_le_bytes(c.try_into().unwrap()) as f32).to_le_bytes())
                .collect();
        *r = (r.0.clone(), Dtype::F32, r.2.clone(), vals);
    });
    let err = ModeBank::from_bytes(&as_f32).unwrap_err();
    assert_eq!(err.to_string(), "tensor 'residuals' has dtype F32, expected F64");

    let reshaped = rewrite(&bytes, |t, _| {
        let p = t.iter_mut().find(|(n, ..)| n == "surface_positions").unwrap();
        p.2 = vec![12, 2];
    });
    let err = ModeBank::from_bytes(&reshaped).unwrap_err();
    assert!(matches!(&err, BankError::WrongShape { name, .. } if name == "surface_positions"), "{err}");

    let fewer_modes = rewrite(&bytes, |t, _| {
        let r = t.iter_mut().find(|(n, ..)| n == "residuals").unwrap();
        r.2 = vec![1];
        r.3.truncate(8);
    });
    let err = ModeBank::from_bytes(&fewer_modes).unwrap_err();
    assert_eq!(err.to_string(), "tensor 'residuals' has shape [1], expected [2]");
}

#[test]
fn hostile_values_are_rejected_after_a_valid_checksum() {
    let bytes = linear_bank(3).to_bytes().unwrap();
    let set_f64 = |name: &'static str, index: usize, value: f64| {
        rewrite(&bytes, move |t, _| {
            let r = t.iter_mut().find(|(n, ..)| n == name).unwrap();
            r.3[8 * index..8 * index + 8].copy_from_slice(&value.to_le_bytes());
        })
    };
    let err = ModeBank::from_bytes(&set_f64("frequencies_hz", 1, f64::NAN)).unwrap_err();
    assert!(matches!(&err, BankError::NonFinite { field, .. } if field == "frequencies_hz[1]"), "{err}");
    let err = ModeBank::from_bytes(&set_f64("frequencies_hz", 1, 1.0)).unwrap_err();
    assert!(matches!(err, BankError::NotAscending { index: 1, .. }), "{err}");
    let err = ModeBank::from_bytes(&set_f64("mass_kg", 0, f64::INFINITY)).unwrap_err();
    assert!(matches!(err, BankError::NonFinite { .. }), "{err}");

    let negative_index = rewrite(&bytes, |t, _| {
        let r = t.iter_mut().find(|(n, ..)| n == "surface_triangles").unwrap();
        r.3[8..16].copy_from_slice(&(-1i64).to_le_bytes());
    });
    let err = ModeBank::from_bytes(&negative_index).unwrap_err();
    assert!(
        matches!(&err, BankError::BadIndex { field, value: -1, .. } if field == "surface_triangles[0][1]"),
        "{err}"
    );
    let big_index = rewrite(&bytes, |t, _| {
        let r = t.iter_mut().find(|(n, ..)| n == "surface_triangles").unwrap();
        r.3[8..16].copy_from_slice(&8i64.to_le_bytes());
    });
    let err = ModeBank::from_bytes(&big_index).unwrap_err();
    assert_eq!(
        err.to_string(),
        "surface_triangles[0][1] = 8 is not a surface node index (the surface has 8 nodes)"
    );

    let bad_material = rewrite(&bytes, |_, meta| {
        meta.insert("material".into(), "{\"youngs_pa\": 1}".into());
    });
    let err = ModeBank::from_bytes(&bad_material).unwrap_err();
    assert!(matches!(&err, BankError::BadMetadata { key, .. } if key == "material"), "{err}");
    let bad_hash = rewrite(&bytes, |_, meta| {
        meta.insert("input_hash".into(), "other".into());
    });
    assert!(matches!(ModeBank::from_bytes(&bad_hash), Err(BankError::Inconsistent(_))));
}

#[test]
fn validate_catches_inconsistent_banks() {
    let good = linear_bank(3);
    good.validate().unwrap();
    let check = |edit: &dyn Fn(&mut ModeBank)| {
        let mut b = good.clone();
        edit(&mut b);
        b.validate().unwrap_err()
    };
    assert!(matches!(
        check(&|b| {
            b.residuals.pop();
        }),
        BankError::Inconsistent(_)
    ));
    assert!(matches!(
        check(&|b| {
            b.shapes.pop();
        }),
        BankError::Inconsistent(_)
    ));
    assert!(matches!(check(&|b| b.frequencies_hz.swap(0, 2)), BankError::NotAscending { .. }));
    assert!(matches!(check(&|b| b.frequencies_hz[0] = 0.0), BankError::OutOfRange { .. }));
    assert!(matches!(check(&|b| b.shapes[5] = f32::INFINITY), BankError::NonFinite { .. }));
    assert!(matches!(check(&|b| b.decay_rates[1] *= 1.01), BankError::Inconsistent(_)));
    assert!(matches!(check(&|b| b.material.alpha = -1.0), BankError::InvalidMaterial(_)));
    assert!(matches!(check(&|b| b.material.poisson = 0.5), BankError::InvalidMaterial(_)));
    assert!(matches!(check(&|b| b.surface.node_ids.clear()), BankError::Inconsistent(_)));
    assert!(matches!(check(&|b| b.surface.triangles[3][2] = 99), BankError::BadIndex { .. }));
    assert!(matches!(check(&|b| b.mass.volume_m3 = -1.0), BankError::OutOfRange { .. }));
    let err = check(&|b| b.shapes[3 * 8 + 4] = f32::NAN);
    assert_eq!(err.to_string(), "shapes[mode 1, surface node 1, component 1] is not finite (NaN)");
}

#[test]
fn t60_and_damped_frequency_follow_the_convention() {
    let mut bank = linear_bank(2);
    let w = 2.0 * std::f64::consts::PI * bank.frequencies_hz[0];
    let d = 0.5 * (5.0 + 3e-8 * w * w);
    assert!((bank.decay_rates[0] - d).abs() <= 1e-15 * d);
    assert!((bank.t60_s(0) - 1000f64.ln() / d).abs() <= 1e-12);
    let xi = 0.5 * (5.0 / w + 3e-8 * w);
    let fd = bank.frequencies_hz[0] * (1.0 - xi * xi).sqrt();
    assert!((bank.damped_frequency_hz(0) - fd).abs() <= 1e-12 * fd);
    bank.material.alpha = 0.0;
    bank.material.beta = 0.0;
    bank.recompute_damping();
    assert_eq!(bank.t60_s(1), f64::INFINITY);
    assert_eq!(bank.damped_frequency_hz(1), bank.frequencies_hz[1]);
    bank.material.alpha = 1e6; // overdamped
    bank.recompute_damping();
    assert!(bank.damping_ratios[0] > 1.0);
    assert_eq!(bank.damped_frequency_hz(0), 0.0);
}

#[test]
fn solve_info_json_tolerates_missing_fields() {
    let info: SolveInfo = serde_json::from_str("{\"order\": 2}").unwrap();
    assert_eq!(info.order, 2);
    assert_eq!(info.input_hash, "");
}

#[test]
fn header_announcing_exabytes_is_rejected_without_panic() {
    // Offsets whose end is close to u64::MAX: adding the header length must
    // not overflow anywhere.
    let big = 1u64 << 60;
    let mut entries = Vec::new();
    let mut start = 0u64;
    for i in 0..16 {
        let len = if i == 15 { big - 16 } else { big };
        entries.push(format!(
            "\"t{i}\":{{\"dtype\":\"U8\",\"shape\":[{len}],\"data_offsets\":[{start},{}]}}",
            start + len
        ));
        start += len;
    }
    let header = format!("{{{}}}", entries.join(","));
    let mut bytes = (header.len() as u64).to_le_bytes().to_vec();
    bytes.extend(header.as_bytes());
    let err = ModeBank::from_bytes(&bytes).unwrap_err();
    assert!(matches!(err, BankError::Truncated { .. } | BankError::NotSafetensors(_)), "{err}");
}

#[test]
fn random_multi_byte_mutations_never_panic_or_pass_silently() {
    let bank = quadratic_bank(2);
    let bytes = bank.to_bytes().unwrap();
    let header_end = 8 + u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    let r = common::pseudo_random(2024, 3 * 4 * 3000);
    let pick = |v: f64, n: usize| (((v + 1.0) / 2.0) * n as f64) as usize % n;
    // Digits and JSON punctuation are the interesting replacements in a header.
    let alphabet = b"0123456789[]{},:\"-.eE ";
    for trial in r.chunks_exact(12) {
        let mut bad = bytes.clone();
        for m in trial.chunks_exact(3) {
            let pos = pick(m[0], header_end);
            bad[pos] = if m[2] > 0.0 { alphabet[pick(m[1], alphabet.len())] } else { pick(m[1], 256) as u8 };
        }
        if let Ok(back) = ModeBank::from_bytes(&bad) {
            assert_eq!(back, bank);
        }
    }
}

#[test]
fn measured_non_rayleigh_damping_is_legal_if_consistent() {
    let mut bank = linear_bank(3);
    bank.damping_ratios = vec![0.01, 0.002, 0.03];
    bank.decay_rates = bank
        .frequencies_hz
        .iter()
        .zip(&bank.damping_ratios)
        .map(|(f, xi)| xi * 2.0 * std::f64::consts::PI * f)
        .collect();
    assert_eq!(ModeBank::from_bytes(&bank.to_bytes().unwrap()).unwrap(), bank);
    bank.decay_rates[2] *= 1.0 + 1e-6;
    let err = bank.validate().unwrap_err();
    assert!(err.to_string().starts_with("inconsistent bank: decay_rates[2]"), "{err}");
}

/// `ModeBank::load` reads the shapes straight into the bank (its own path);
/// it must agree with `from_bytes` on the same bytes: the same bank, bit for
/// bit, or the same error.
#[test]
fn load_agrees_with_from_bytes_on_good_and_bad_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("b.bank");
    let mut nothing = linear_bank(0);
    nothing.surface = Default::default();
    nothing.mass = common::cube_mass(0.0, 1.0);
    let mut variants: Vec<Vec<u8>> = [linear_bank(5), quadratic_bank(3), linear_bank(0), nothing]
        .iter()
        .map(|b| b.to_bytes().unwrap())
        .collect();
    let bytes = quadratic_bank(2).to_bytes().unwrap();
    variants.extend((0..bytes.len()).step_by(7).map(|len| bytes[..len].to_vec()));
    variants.extend((0..bytes.len()).step_by(5).map(|pos| {
        let mut bad = bytes.clone();
        bad[pos] ^= 1 << (pos % 8);
        bad
    }));
    let mut longer = bytes.clone();
    longer.push(0);
    variants.push(longer);
    let mut loaded = 0;
    for (i, v) in variants.iter().enumerate() {
        std::fs::write(&path, v).unwrap();
        match (ModeBank::load(&path), ModeBank::from_bytes(v)) {
            (Ok(a), Ok(b)) => {
                assert_bit_identical(&a, &b);
                loaded += 1;
            }
            (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string(), "variant {i}"),
            (a, b) => panic!("variant {i}: load gave {a:?}, from_bytes {b:?}"),
        }
    }
    assert!(loaded >= 4, "{loaded} variants loaded");
}

#[test]
fn forged_radiation_data_is_refused_naming_what_is_wrong() {
    let bank = linear_bank(3);
    let table = radiation_table(&bank);
    let bytes = bank.to_bytes_with_radiation(&table).unwrap();
    let load = |b: &[u8]| ModeBank::from_bytes_with_radiation(b).map(|_| ()).unwrap_err().to_string();
    // Tensors whose metadata key is gone were ignored, and the level estimated.
    let no_meta = rewrite(&bytes, |_, meta| {
        meta.remove("radiation");
    });
    assert!(
        load(&no_meta).contains("missing, though the file holds radiation tensors"),
        "{}",
        load(&no_meta)
    );
    // Another time convention was read as ours (every phase conjugated).
    let other_convention = rewrite(&bytes, |_, meta| {
        let json = meta["radiation"].replace("exp(-i omega t)", "exp(+i omega t)");
        meta.insert("radiation".into(), json);
    });
    assert!(load(&other_convention).contains("exp(+i omega t)"), "{}", load(&other_convention));
    // A NaN efficiency was reported as the power tensor with the power's value.
    let mut bad = table.clone();
    bad.modes[1].efficiency = f64::NAN;
    let err = bank.to_bytes_with_radiation(&bad).unwrap_err().to_string();
    assert!(err.contains("radiation_efficiency[1]") && err.contains("NaN"), "{err}");
}
