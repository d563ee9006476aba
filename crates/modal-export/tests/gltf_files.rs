//! glTF export and import: exact round trips, what a plain glTF reader sees,
//! the KHR data alone, edited and older files, and malformed models.

use std::collections::HashMap;

use modal_bank::{ModeBank, ModeTransfer, RadiationTable};
use modal_export::gltf::{export_glb, import_glb, EXTENSION};
use modal_export::ExportError;
use modal_synth::synthetic::{SplitMix64, SyntheticBank};
use serde_json::Value;

/// A bank with awkward f64 values (not f32-representable) everywhere.
fn linear_bank() -> ModeBank {
    let mut bank = SyntheticBank::preset("steel", 7).build();
    let mut rng = SplitMix64::new(7);
    for p in &mut bank.surface.positions {
        p.iter_mut().for_each(|x| *x += rng.range(-1e-3, 1e-3));
    }
    bank.mass.inertia_kg_m2[0][1] = 1.1e-5;
    bank.mass.inertia_kg_m2[1][0] = 1.1e-5;
    bank.info.input_hash = "ab".repeat(32);
    bank.info.order = 1;
    bank.residuals = (0..7).map(|i| 1e-11 * (i + 1) as f64).collect();
    bank
}

/// The linear bank's surface made quadratic: a mid-edge node on every edge.
fn quadratic_bank() -> ModeBank {
    let mut bank = linear_bank();
    let s = &mut bank.surface;
    let mut mids: HashMap<(usize, usize), usize> = HashMap::new();
    let mut edges = Vec::new();
    for t in s.triangles.clone() {
        let mut e = [0; 3];
        for (k, (a, b)) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])].into_iter().enumerate() {
            e[k] = *mids.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (pa, pb) = (s.positions[a], s.positions[b]);
                s.positions.push([0, 1, 2].map(|c| 0.5 * (pa[c] + pb[c])));
                s.node_ids.push(1000 + s.node_ids.len());
                s.positions.len() - 1
            });
        }
        edges.push(e);
    }
    s.triangle_edge_nodes = Some(edges);
    let nodes = s.positions.len();
    let mut rng = SplitMix64::new(3);
    bank.shapes = (0..bank.frequencies_hz.len() * nodes * 3).map(|_| rng.range(-1.0, 1.0) as f32).collect();
    bank.info.order = 2;
    bank.validate().unwrap();
    bank
}

#[test]
fn export_then_import_gives_the_same_bank_bit_for_bit() {
    for bank in [linear_bank(), quadratic_bank()] {
        let bytes = export_glb(&bank, None, "box", true).unwrap().bytes;
        let imported = import_glb(&bytes).unwrap();
        assert!(imported.exact);
        assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
        assert_eq!(imported.name.as_deref(), Some("box"));
        assert_eq!(imported.bank, bank);
    }
}

/// An acoustic transfer for modes 1, 3 and 4 of `bank`, with awkward f64 values.
fn radiation(bank: &ModeBank) -> RadiationTable {
    let mut rng = SplitMix64::new(11);
    let modes = [(1, 2), (3, 0), (4, 5)]
        .map(|(mode, order)| ModeTransfer {
            mode,
            wavenumber: 2.0 * std::f64::consts::PI * bank.frequencies_hz[mode] / 343.0,
            order,
            coefficients: (0..(order + 1) * (order + 1))
                .map(|_| [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)])
                .collect(),
            power_w: rng.range(0.0, 1e-3),
            efficiency: rng.range(0.0, 1.0),
        })
        .to_vec();
    let c = bank.mass.center_of_mass_m;
    let radius =
        bank.surface.positions.iter().map(|p| (0..3).map(|q| (p[q] - c[q]).powi(2)).sum::<f64>().sqrt());
    RadiationTable {
        centre_m: c,
        // Twice the body's radius, as the solver fits (the table must fit its bank).
        fit_radius_m: 2.0 * radius.fold(0.0, f64::max) + rng.range(0.0, 1e-3),
        air_density_kg_m3: 1.21,
        sound_speed_m_s: 343.0,
        tolerance: 1e-3,
        modes,
    }
}

#[test]
fn the_acoustic_transfer_travels_in_the_side_data_bit_for_bit() {
    for bank in [linear_bank(), quadratic_bank()] {
        let table = radiation(&bank);
        let glb = export_glb(&bank, Some(&table), "box", true).unwrap();
        assert_eq!((glb.radiation_modes, glb.overdamped_left_out), (3, 0));
        let imported = import_glb(&glb.bytes).unwrap();
        assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
        assert_eq!(imported.bank, bank);
        assert_eq!(imported.radiation.as_ref(), Some(&table));
        // Without the side data there is no place for it.
        let plain = export_glb(&bank, Some(&table), "box", false).unwrap();
        assert_eq!(plain.radiation_modes, 0);
        assert_eq!(import_glb(&plain.bytes).unwrap().radiation, None);
    }
    // A damaged table is dropped with a warning; the bank itself still reads exactly.
    let bank = linear_bank();
    let (mut json, bin) = split_glb(&export_glb(&bank, Some(&radiation(&bank)), "box", true).unwrap().bytes);
    json["extensions"][EXTENSION]["modalModels"][0]["extras"]["modal"]["radiation"]["modes"][2] = 99.into();
    let imported = import_glb(&join_glb(&json, &bin)).unwrap();
    assert!(imported.exact && imported.radiation.is_none());
    assert!(imported.warnings.iter().any(|w| w.contains("radiation is ignored")), "{:?}", imported.warnings);
}

#[test]
fn overdamped_modes_are_left_out_with_their_transfer() {
    let mut bank = linear_bank();
    // Mode 3 overdamped (ξ = 1.5: no damped frequency).
    bank.damping_ratios[3] = 1.5;
    bank.decay_rates[3] = 1.5 * 2.0 * std::f64::consts::PI * bank.frequencies_hz[3];
    bank.info.error_estimate_pct = (0..bank.mode_count()).map(|i| Some(0.1 * i as f64)).collect();
    let table = radiation(&bank);
    let glb = export_glb(&bank, Some(&table), "box", true).unwrap();
    assert_eq!(glb.overdamped_left_out, 1);
    let imported = import_glb(&glb.bytes).unwrap();
    let got = &imported.bank;
    assert_eq!(got.mode_count(), bank.mode_count() - 1);
    let kept: Vec<usize> = (0..bank.mode_count()).filter(|&i| i != 3).collect();
    let s = 3 * bank.surface_node_count();
    for (new, &old) in kept.iter().enumerate() {
        assert_eq!(got.frequencies_hz[new], bank.frequencies_hz[old]);
        assert_eq!(got.info.error_estimate_pct[new], bank.info.error_estimate_pct[old]);
        assert_eq!(got.shapes[new * s..(new + 1) * s], bank.shapes[old * s..(old + 1) * s]);
    }
    // Transfer of modes 1, 3, 4: mode 3 is gone, mode 4 is now mode 3.
    let got = imported.radiation.unwrap();
    assert_eq!(got.modes.iter().map(|m| m.mode).collect::<Vec<_>>(), vec![1, 3]);
    assert_eq!(got.modes[1].coefficients, table.modes[2].coefficients);
    // Nothing underdamped: nothing to export.
    bank.damping_ratios.iter_mut().for_each(|z| *z = 2.0);
    for i in 0..bank.mode_count() {
        bank.decay_rates[i] = 2.0 * 2.0 * std::f64::consts::PI * bank.frequencies_hz[i];
    }
    assert!(matches!(export_glb(&bank, None, "box", true), Err(ExportError::NoModes)));
}

#[test]
fn a_material_or_mass_edited_by_another_tool_wins_over_the_side_data() {
    let bank = linear_bank();
    let (json, bin) = split_glb(&export_glb(&bank, None, "box", true).unwrap().bytes);
    let mut softer = json.clone();
    softer["extensions"][EXTENSION]["acousticMaterials"][0]["density"] = 1000.0.into();
    let imported = import_glb(&join_glb(&softer, &bin)).unwrap();
    assert!(!imported.exact);
    assert_eq!(imported.bank.material.density_kg_m3, 1000.0);
    assert!(imported.warnings.iter().any(|w| w.contains("density is 1000")), "{:?}", imported.warnings);
    let mut heavier = json.clone();
    heavier["extensions"][EXTENSION]["modalModels"][0]["massProperties"]["mass"] = 10.0.into();
    let imported = import_glb(&join_glb(&heavier, &bin)).unwrap();
    assert!(!imported.exact);
    assert_eq!(imported.bank.mass.mass_kg, 10.0);
    for mass in [0.0, -1.0] {
        let mut bad = json.clone();
        bad["extensions"][EXTENSION]["modalModels"][0]["massProperties"]["mass"] = mass.into();
        let message = import_glb(&join_glb(&bad, &bin)).unwrap_err().to_string();
        assert!(message.contains("massProperties.mass") && message.contains("must be positive"), "{message}");
    }
}

#[test]
fn a_file_with_acoustic_data_but_no_modal_model_is_geometry() {
    let bank = linear_bank();
    let dir = tempfile::tempdir().unwrap();
    let (json, bin) = split_glb(&export_glb(&bank, None, "box", true).unwrap().bytes);
    let path = dir.path().join("model.glb");
    std::fs::write(&path, join_glb(&json, &bin)).unwrap();
    assert!(modal_export::gltf::holds_modal_model(&path).unwrap());
    // The draft lets a file hold acoustic materials and surfaces alone.
    let mut surfaces = json.clone();
    let root = &mut surfaces["extensions"][EXTENSION];
    root.as_object_mut().unwrap().remove("modalModels");
    root["acousticSurfaces"] = serde_json::json!([{ "roughness": 2e-6, "material": 0 }]);
    surfaces["nodes"][0]["extensions"][EXTENSION] = serde_json::json!({ "acousticSurface": 0 });
    std::fs::write(&path, join_glb(&surfaces, &bin)).unwrap();
    assert!(!modal_export::gltf::holds_modal_model(&path).unwrap());
}

/// The JSON chunk and the binary chunk of GLB bytes.
fn split_glb(bytes: &[u8]) -> (Value, Vec<u8>) {
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(u32::from_le_bytes(bytes[4..8].try_into().unwrap()), 2);
    assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize, bytes.len());
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    assert_eq!(&bytes[16..20], b"JSON");
    let json = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin = &bytes[20 + json_len..];
    assert_eq!(&bin[4..8], b"BIN\0");
    (json, bin[8..].to_vec())
}

/// GLB bytes of a JSON document and a binary chunk.
fn join_glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    modal_export::gltf::glb_container(json, bin.to_vec()).unwrap()
}

#[test]
fn the_gltf_crate_reads_the_mesh_and_the_documented_accessors() {
    let bank = quadratic_bank();
    let bytes = export_glb(&bank, None, "box", true).unwrap().bytes;
    let gltf = gltf::Gltf::from_slice(&bytes).expect("a valid glTF document");
    let blob = gltf.blob.clone().unwrap();
    let buffers = |_: gltf::Buffer| Some(blob.as_slice());
    let mesh = gltf.meshes().next().unwrap();
    let primitive = mesh.primitives().next().unwrap();
    assert_eq!(primitive.mode(), gltf::mesh::Mode::Triangles);
    let reader = primitive.reader(buffers);
    let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    let expected: Vec<[f32; 3]> = bank.surface.positions.iter().map(|p| p.map(|x| x as f32)).collect();
    assert_eq!(positions, expected);
    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    // Each 6-node triangle as 4 flat ones, every surface node used.
    assert_eq!(indices.len(), 4 * 3 * bank.surface.triangles.len());
    let mut used = vec![false; positions.len()];
    indices.iter().for_each(|&i| used[i as usize] = true);
    assert!(used.iter().all(|&u| u));
    let node = gltf.nodes().next().unwrap();
    assert_eq!(node.mesh().unwrap().index(), 0);
    assert_eq!(
        node.extension_value(EXTENSION).unwrap(),
        &serde_json::json!({ "modalModel": 0, "gain": 1.0 })
    );
    assert_eq!(gltf.extensions_used().collect::<Vec<_>>(), vec![EXTENSION]);
    assert_eq!(gltf.extensions_required().count(), 0);
    let root = gltf.extension_value(EXTENSION).unwrap();
    let model = &root["modalModels"][0];
    let read_floats = |key: &str| -> Vec<f32> {
        let accessor = gltf.accessors().nth(model[key].as_u64().unwrap() as usize).unwrap();
        assert_eq!(accessor.data_type(), gltf::accessor::DataType::F32);
        gltf::accessor::Iter::<f32>::new(accessor, buffers).unwrap().collect()
    };
    let freqs = read_floats("frequencies");
    let decays = read_floats("decayRates");
    for i in 0..bank.mode_count() {
        assert_eq!(freqs[i], bank.damped_frequency_hz(i) as f32, "damped frequency {i}");
        assert_eq!(decays[i], bank.decay_rates[i] as f32);
    }
    let shapes = gltf.accessors().nth(model["shapes"].as_u64().unwrap() as usize).unwrap();
    assert_eq!(shapes.dimensions(), gltf::accessor::Dimensions::Vec3);
    let shapes: Vec<[f32; 3]> = gltf::accessor::Iter::new(shapes, buffers).unwrap().collect();
    assert_eq!(shapes.concat(), bank.shapes, "mode-major, as the bank");
    assert_eq!(model["positions"], primitive.get(&gltf::Semantic::Positions).unwrap().index());
    let material = &root["acousticMaterials"][0];
    assert_eq!(material["youngsModulus"], bank.material.youngs_pa);
    assert_eq!(material["poissonRatio"], bank.material.poisson);
    assert_eq!(material["density"], bank.material.density_kg_m3);
    assert_eq!(model["massProperties"]["mass"], bank.mass.mass_kg);
}

#[test]
fn without_the_side_data_the_khr_data_alone_makes_the_bank() {
    let bank = linear_bank();
    let imported = import_glb(&export_glb(&bank, None, "box", false).unwrap().bytes).unwrap();
    assert!(!imported.exact);
    let got = &imported.bank;
    assert_eq!(got.mode_count(), bank.mode_count());
    for i in 0..bank.mode_count() {
        // f32 accessors: about 6e-8 relative.
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
        assert!(rel(got.frequencies_hz[i], bank.frequencies_hz[i]) < 2e-7, "mode {i}");
        assert!(rel(got.damped_frequency_hz(i), bank.damped_frequency_hz(i)) < 2e-7);
        assert_eq!(got.decay_rates[i], bank.decay_rates[i] as f32 as f64);
        assert!(rel(got.damping_ratios[i], bank.damping_ratios[i]) < 4e-7);
    }
    assert_eq!(got.shapes, bank.shapes);
    assert_eq!(got.surface.triangles, bank.surface.triangles);
    for (a, b) in got.surface.positions.iter().zip(&bank.surface.positions) {
        assert_eq!(*a, b.map(|x| x as f32 as f64));
    }
    assert_eq!(got.material.youngs_pa, bank.material.youngs_pa);
    assert_eq!(got.mass.mass_kg, bank.mass.mass_kg);
    // The inertia tensor rebuilt from principal moments and their quaternion.
    for r in 0..3 {
        for c in 0..3 {
            let (a, b) = (got.mass.inertia_kg_m2[r][c], bank.mass.inertia_kg_m2[r][c]);
            assert!((a - b).abs() < 1e-12 * bank.mass.inertia_kg_m2[0][0].abs(), "I[{r}][{c}] {a} vs {b}");
        }
    }
    assert!((got.mass.volume_m3 - bank.mass.volume_m3).abs() < 1e-15);
}

#[test]
fn edited_side_data_is_ignored_with_a_warning() {
    let bank = linear_bank();
    let (mut json, bin) = split_glb(&export_glb(&bank, None, "box", true).unwrap().bytes);
    json["extensions"][EXTENSION]["modalModels"][0]["extras"]["modal"]["frequenciesHz"][2] = 1234.5.into();
    let imported = import_glb(&join_glb(&json, &bin)).unwrap();
    assert!(!imported.exact);
    assert!(
        imported.warnings.iter().any(|w| w.contains("extras.modal is ignored")),
        "{:?}",
        imported.warnings
    );
    assert!((imported.bank.frequencies_hz[2] / bank.frequencies_hz[2] - 1.0).abs() < 2e-7);
}

#[test]
fn the_older_khr_audio_modal_spelling_is_read() {
    let bank = linear_bank();
    let (mut json, bin) = split_glb(&export_glb(&bank, None, "box", false).unwrap().bytes);
    let root = json["extensions"].as_object_mut().unwrap().remove(EXTENSION).unwrap();
    json["extensions"]["KHR_audio_modal"] =
        serde_json::json!({ "models": root["modalModels"], "materials": root["acousticMaterials"] });
    json["extensionsUsed"] = serde_json::json!(["KHR_audio_modal"]);
    json["nodes"][0]["extensions"] = serde_json::json!({ "KHR_audio_modal": { "model": 0, "gain": 0.5 } });
    let imported = import_glb(&join_glb(&json, &bin)).unwrap();
    assert_eq!(imported.bank.shapes, bank.shapes);
    assert!(imported.warnings.iter().any(|w| w.contains("gain 0.5")), "{:?}", imported.warnings);
}

#[test]
fn modes_out_of_order_are_sorted() {
    let bank = linear_bank();
    let (mut json, bin) = split_glb(&export_glb(&bank, None, "box", false).unwrap().bytes);
    // Point the frequencies and decay rates at reversed copies (appended views).
    let n = bank.mode_count();
    let mut bin = bin;
    let mut add = |values: Vec<f32>, json: &mut Value| -> usize {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let offset = bin.len();
        values.iter().for_each(|v| bin.extend(v.to_le_bytes()));
        let views = json["bufferViews"].as_array_mut().unwrap();
        views.push(serde_json::json!({ "buffer": 0, "byteOffset": offset, "byteLength": 4 * n }));
        let view = views.len() - 1;
        let accessors = json["accessors"].as_array_mut().unwrap();
        accessors.push(
            serde_json::json!({ "bufferView": view, "componentType": 5126, "count": n, "type": "SCALAR" }),
        );
        accessors.len() - 1
    };
    let f: Vec<f32> = (0..n).rev().map(|i| bank.damped_frequency_hz(i) as f32).collect();
    let d: Vec<f32> = (0..n).rev().map(|i| bank.decay_rates[i] as f32).collect();
    let fa = add(f, &mut json);
    let da = add(d, &mut json);
    json["buffers"][0]["byteLength"] = bin.len().into();
    let model = &mut json["extensions"][EXTENSION]["modalModels"][0];
    model["frequencies"] = fa.into();
    model["decayRates"] = da.into();
    let imported = import_glb(&join_glb(&json, &bin)).unwrap();
    // The shapes were left in the original order, so mode k now carries the
    // shape written for mode n-1-k: sorting must move it back with its frequency.
    let s = bank.surface_node_count() * 3;
    for k in 0..n {
        let j = n - 1 - k;
        assert_eq!(imported.bank.shapes[k * s..(k + 1) * s], bank.shapes[j * s..(j + 1) * s], "mode {k}");
    }
    assert!(imported.bank.frequencies_hz.windows(2).all(|w| w[0] <= w[1]));
}

#[test]
fn malformed_files_and_models_give_one_clear_error() {
    let bank = linear_bank();
    let (json, bin) = split_glb(&export_glb(&bank, None, "box", false).unwrap().bytes);
    let err = |json: &Value| import_glb(&join_glb(json, &bin)).unwrap_err().to_string();

    assert!(matches!(import_glb(b"not a gltf at all"), Err(ExportError::Gltf(_))));
    let mut no_ext = json.clone();
    no_ext.as_object_mut().unwrap().remove("extensions");
    assert!(matches!(import_glb(&join_glb(&no_ext, &bin)), Err(ExportError::NoExtension)));

    fn model(j: &mut Value) -> &mut Value {
        &mut j["extensions"][EXTENSION]["modalModels"][0]
    }
    let mut wrong_type = json.clone();
    let positions = model(&mut wrong_type)["positions"].clone();
    model(&mut wrong_type)["frequencies"] = positions;
    assert!(err(&wrong_type).contains("frequencies: accessor"), "{}", err(&wrong_type));

    let mut counts = json.clone();
    let decay = model(&mut counts)["decayRates"].as_u64().unwrap() as usize;
    counts["accessors"][decay]["count"] = 2.into();
    assert!(err(&counts).contains("decayRates has 2 values"), "{}", err(&counts));

    let mut no_indices = json.clone();
    model(&mut no_indices).as_object_mut().unwrap().remove("indices");
    assert!(err(&no_indices).contains("no indices"));

    let mut no_material = json.clone();
    model(&mut no_material).as_object_mut().unwrap().remove("material");
    assert!(err(&no_material).contains("no acoustic material"));

    let mut bad_nu = json.clone();
    bad_nu["extensions"][EXTENSION]["acousticMaterials"][0]["poissonRatio"] = 0.7.into();
    assert!(err(&bad_nu).contains("acoustic material 0"), "{}", err(&bad_nu));

    // A compressed file's fallback buffer has neither data nor a URI: it must not
    // be read as a second copy of the binary chunk.
    let mut fallback = json.clone();
    let length = fallback["buffers"][0]["byteLength"].clone();
    fallback["buffers"].as_array_mut().unwrap().push(serde_json::json!({ "byteLength": length }));
    fallback["bufferViews"][0]["buffer"] = 1.into();
    assert!(err(&fallback).contains("buffer 1 has no data"), "{}", err(&fallback));

    let mut far_view = json.clone();
    let shapes = model(&mut far_view)["shapes"].as_u64().unwrap() as usize;
    far_view["accessors"][shapes]["count"] = 10_000_000.into();
    let message = err(&far_view);
    assert!(message.contains("shapes") || message.contains("glTF"), "{message}");
}
