//! End-to-end tests of `modal precompute`, `info`, `retune`, `export` and
//! `export-matrices` through the binary: the `--json` contract, the cache,
//! and retuning against a fresh solve.

mod common;
use common::*;
use serde_json::Value;

fn frequencies(json: &Value) -> Vec<f64> {
    json["modes"].as_array().unwrap().iter().map(|m| m["frequency_hz"].as_f64().unwrap()).collect()
}

fn precompute(dir: &std::path::Path, out: &str, extra: &[&str]) -> Value {
    let bar = example("bar_p1.msh");
    let mut args = vec!["precompute", bar.to_str().unwrap(), "-o", out, "--modes", "8", "--json"];
    args.extend(extra);
    modal(dir, &args).ok().json()
}

#[test]
fn json_contract_cache_and_info_agree() {
    let dir = temp_dir();
    let mut flags = STEEL.to_vec();
    flags.extend(["--alpha", "5", "--beta", "3e-8"]);
    let bar = example("bar_p1.msh");
    let mut args = vec!["precompute", bar.to_str().unwrap(), "-o", "a.bank", "--modes", "8", "--json"];
    args.extend(&flags);
    let run = modal(dir.path(), &args).ok();
    // In a log (stderr is not a terminal) the long stages are lines.
    assert!(run.stderr.contains("precompute: assembling K and M ("), "{}", run.stderr);
    assert!(!run.stderr.contains("surface meshes only"), "{}", run.stderr);
    let first = run.json();
    for key in
        ["modes", "dofs", "order", "mass_kg", "rigid_modes_removed", "inertia_check", "cached", "timings_s"]
    {
        assert!(first.get(key).is_some(), "missing key {key}");
    }
    for key in ["frequency_hz", "damped_frequency_hz", "damping_ratio", "decay_rate", "residual"] {
        assert!(first["modes"][0].get(key).is_some(), "missing mode key {key}");
    }
    assert_eq!(first["cached"], false);
    assert_eq!(first["order"], 2);
    assert_eq!(first["rigid_modes_removed"], 6);
    assert_eq!(first["inertia_check"]["expected"], first["inertia_check"]["found"]);
    assert!((first["mass_kg"].as_f64().unwrap() - 0.471).abs() < 1e-9);
    let f = frequencies(&first);
    assert_eq!(f.len(), 8);
    assert!(f.windows(2).all(|w| w[0] <= w[1]), "ascending");
    // First flat bending of the reference bar: 574.27 Hz (3D converged).
    assert!((f[0] / 574.27 - 1.0).abs() < 0.01, "first mode {} Hz", f[0]);
    // Rayleigh damping: d = (α + β ω²)/2.
    let w = 2.0 * std::f64::consts::PI * f[0];
    let d = first["modes"][0]["decay_rate"].as_f64().unwrap();
    assert!((d - (5.0 + 3e-8 * w * w) / 2.0).abs() < 1e-9 * d);
    for m in first["modes"].as_array().unwrap() {
        assert!(m["residual"].as_f64().unwrap() <= 1e-8);
    }

    // Same inputs again: a cache hit printing exactly the same values.
    let second = precompute(dir.path(), "b.bank", &flags);
    assert_eq!(second["cached"], true);
    let strip = |mut v: Value| {
        v["cached"] = Value::Null;
        v
    };
    assert_eq!(strip(first.clone()), strip(second));

    // info prints the same object for the bank.
    let info = modal(dir.path(), &["info", "a.bank", "--json"]).ok().json();
    assert_eq!(strip(first.clone()), strip(info));

    // Any change of input misses the cache (here: damping).
    let mut changed = STEEL.to_vec();
    changed.extend(["--alpha", "6", "--beta", "3e-8"]);
    assert_eq!(precompute(dir.path(), "c.bank", &changed)["cached"], false);
}

/// Every command writes into directories that do not exist yet, creating
/// them before its work: a precompute used to solve, then fail on "No such
/// file or directory" at the write. A directory that cannot be made (a file
/// in the way) is refused before the work, and a refused input leaves no
/// directory behind.
#[test]
fn outputs_go_into_new_directories_made_before_the_work() {
    let dir = temp_dir();
    let bar = example("bar_p1.msh");
    let bar = bar.to_str().unwrap();
    modal(dir.path(), &["mesh", "box", "--size", "0.2,0.02,0.01", "--h", "0.01", "-o", "m/a/box.msh"]).ok();
    let mut solve = vec!["precompute", bar, "-o", "banks/steel/bar.bank", "--modes", "4"];
    solve.extend(STEEL);
    modal(dir.path(), &solve).ok();
    let bank = "banks/steel/bar.bank";
    modal(dir.path(), &["retune", bank, "--scale", "2", "-o", "banks/big/bar.bank"]).ok();
    modal(dir.path(), &["export", bank, "--vtk", "vtk/bar.vtu", "--gltf", "gltf/bar.glb"]).ok();
    modal(dir.path(), &["strike", bank, "-o", "audio/hits/bar.wav"]).ok();
    for file in
        ["m/a/box.msh", bank, "banks/big/bar.bank", "vtk/bar.vtu", "gltf/bar.glb", "audio/hits/bar.wav"]
    {
        assert!(dir.path().join(file).is_file(), "{file} not written");
    }
    let mut blocked = vec!["precompute", bar, "-o", "m/a/box.msh/bar.bank", "--modes", "4"];
    blocked.extend(STEEL);
    let run = modal(dir.path(), &blocked).fails_with("cannot create directory m/a/box.msh");
    assert!(!run.stderr.contains("assembling"), "refused only after the work:\n{}", run.stderr);
    let missing = ["precompute", "none.obj", "-o", "nothing/x.bank", "--material", "steel"];
    modal(dir.path(), &missing).fails_with("none.obj");
    assert!(!dir.path().join("nothing").exists(), "a refused input made its output directory");
    // A pipe (or /dev/null) is no output: the rename would have replaced it with a file.
    assert!(std::process::Command::new("mkfifo").arg(dir.path().join("pipe")).status().unwrap().success());
    let to_pipe = ["mesh", "box", "--size", "0.2,0.02,0.01", "--h", "0.01", "-o", "pipe"];
    modal(dir.path(), &to_pipe).fails_with("is not a regular file");
    use std::os::unix::fs::FileTypeExt;
    assert!(
        std::fs::metadata(dir.path().join("pipe")).unwrap().file_type().is_fifo(),
        "the pipe was replaced"
    );
}

#[test]
fn retune_matches_a_fresh_solve() {
    let dir = temp_dir();
    let steel = precompute(dir.path(), "steel.bank", &STEEL);
    // Aluminium-like: same ν, new E and ρ; λ' = λ (E'/E)/(ρ'/ρ).
    let retuned = modal(
        dir.path(),
        &["retune", "steel.bank", "--youngs", "70e9", "--density", "2700", "-o", "al.bank", "--json"],
    )
    .ok()
    .json();
    let fresh =
        precompute(dir.path(), "fresh.bank", &["--youngs", "70e9", "--poisson", "0.3", "--density", "2700"]);
    let ratio = ((70e9_f64 / 200e9) / (2700.0 / 7850.0)).sqrt();
    for ((r, f), s) in frequencies(&retuned).iter().zip(frequencies(&fresh)).zip(frequencies(&steel)) {
        assert!((r / f - 1.0).abs() < 1e-7, "retuned {r} vs fresh {f}");
        assert!((r / (s * ratio) - 1.0).abs() < 1e-12);
    }
    assert_eq!(retuned["cached"], false);
    // A different ν needs a new solve.
    modal(dir.path(), &["retune", "steel.bank", "--poisson", "0.33", "-o", "x.bank"]).fails_with("poisson");
    // Absurd values are refused by name (they gave "not finite" of an internal field).
    modal(dir.path(), &["retune", "steel.bank", "--scale", "1e200", "-o", "x.bank"]).fails_with("--scale");
    modal(dir.path(), &["retune", "steel.bank", "--density", "1e-300", "-o", "x.bank"]).fails_with("density");
    assert!(!dir.path().join("x.bank").exists());
}

#[test]
fn clamped_bar_is_a_cantilever() {
    let dir = temp_dir();
    // Clamp the end x = 0 of the 0.3 m bar.
    let mut flags = STEEL.to_vec();
    flags.extend(["--fix-box", "-1,-1,-1,1e-9,1,1"]);
    let json = precompute(dir.path(), "c.bank", &flags);
    assert_eq!(json["rigid_modes_removed"], 0);
    assert_eq!(json["inertia_check"]["expected"], json["inertia_check"]["found"]);
    // Euler–Bernoulli clamped-free: f = (1.875104)² / (2π L²) √(EI/ρA), flat bending across h = 0.01.
    let (l, h) = (0.3, 0.01_f64);
    let eb =
        1.875104_f64.powi(2) / (2.0 * std::f64::consts::PI * l * l) * (200e9 * h * h / 12.0 / 7850.0).sqrt();
    let f0 = frequencies(&json)[0];
    assert!((f0 / eb - 1.0).abs() < 0.02, "cantilever {f0} Hz vs beam theory {eb} Hz");
}

#[test]
fn export_writes_a_vtu_and_matrices_are_lower_triangle() {
    let dir = temp_dir();
    precompute(dir.path(), "a.bank", &STEEL);
    modal(dir.path(), &["export", "a.bank", "--vtk", "a.vtu"]).ok();
    let vtu = std::fs::read_to_string(dir.path().join("a.vtu")).unwrap();
    assert!(vtu.contains("UnstructuredGrid") && vtu.matches("<DataArray").count() >= 8);

    let bar = example("bar_p1.msh");
    let mut args = vec!["export-matrices", bar.to_str().unwrap(), "--out", "m", "--json"];
    args.extend(STEEL);
    let summary = modal(dir.path(), &args).ok().json();
    let k = std::fs::read_to_string(dir.path().join("m/K.mtx")).unwrap();
    let mut lines = k.lines().filter(|l| !l.starts_with('%'));
    let header: Vec<usize> = lines.next().unwrap().split_whitespace().map(|t| t.parse().unwrap()).collect();
    assert_eq!(header[0], summary["dofs"].as_u64().unwrap() as usize);
    for line in lines.take(1000) {
        let mut it = line.split_whitespace();
        let (i, j): (usize, usize) =
            (it.next().unwrap().parse().unwrap(), it.next().unwrap().parse().unwrap());
        assert!(i >= j && j >= 1, "lower triangle, 1-based");
    }
    let nodes = std::fs::read_to_string(dir.path().join("m/nodes.csv")).unwrap();
    assert_eq!(nodes.lines().count() - 1, header[0] / 3);
    // `entries_k`/`entries_m` are the entries each file holds (exact zeros are left out).
    for (file, field) in [("m/K.mtx", "entries_k"), ("m/M.mtx", "entries_m")] {
        let text = std::fs::read_to_string(dir.path().join(file)).unwrap();
        let mut lines = text.lines().filter(|l| !l.starts_with('%'));
        let declared: usize = lines.next().unwrap().split_whitespace().nth(2).unwrap().parse().unwrap();
        let reported = summary[field].as_u64().unwrap() as usize;
        assert_eq!((reported, lines.count()), (declared, declared), "{field} against {file}");
    }
}

#[test]
fn thin_plates_and_long_tubes_get_default_sizes_near_the_budget_and_report_them() {
    // 15 × 10 cm, 4 mm: D_min/2 would give 45 000 tets; the budget ≈ 12 000.
    let dir = temp_dir();
    // No --order: the written mesh is quadratic, what precompute solves by default (at
    // order 1 the same command wrote 2.88 M linear tets sized for linear elements).
    let written =
        modal(dir.path(), &["mesh", "box", "--size", "0.15,0.004,0.1", "-o", "p.msh", "--json"]).ok().json();
    assert_eq!(written["order"], 2, "{written}");
    let h = written["element_size_m"].as_f64().unwrap();
    assert!(h > 0.002 && h < 0.0075, "h = {h}");
    assert!(written["tets"].as_u64().unwrap() <= 12_000, "{written}");
    assert_eq!(written["axial_element_size_m"].as_f64(), Some(h), "a box is uniform");
    // A disc 20 cm across and 2 mm thick is a plate too.
    let disc = modal(
        dir.path(),
        &["mesh", "cylinder", "--radius", "0.1", "--length", "0.002", "-o", "d.msh", "--json"],
    )
    .ok()
    .json();
    assert!(disc["tets"].as_u64().unwrap() <= 12_000, "{disc}");
    // Linear tets on request keep the linear rule (D_min/8).
    let linear = ["mesh", "box", "--size", "0.1,0.02,0.01", "--order", "1", "-o", "l.msh", "--json"];
    let linear = modal(dir.path(), &linear).ok().json();
    assert_eq!((linear["order"].as_u64(), linear["element_size_m"].as_f64()), (Some(1), Some(0.01 / 8.0)));
    // A 1 m chime tube, 1.5 mm wall: twice the wall around, 16 walls along the axis
    // (a little over the budget: the wall, not the budget, bounds the cells).
    let args = [
        "mesh",
        "tube",
        "--inner-radius",
        "0.0235",
        "--outer-radius",
        "0.025",
        "--length",
        "1",
        "--order",
        "2",
        "-o",
        "c.msh",
        "--json",
    ];
    let chime = modal(dir.path(), &args).ok().json();
    let (h, axial) =
        (chime["element_size_m"].as_f64().unwrap(), chime["axial_element_size_m"].as_f64().unwrap());
    assert!((h - 0.003).abs() < 1e-9 && (axial - 0.024).abs() < 1e-9, "{chime}");
    assert_eq!(chime["tets"].as_u64(), Some(6 * 51 * 42), "51 cells around, 42 along, 1 through: {chime}");
}

#[test]
fn generated_meshes_are_written_and_read_back() {
    let dir = temp_dir();
    let shapes: [&[&str]; 5] = [
        &["box", "--size", "0.1,0.02,0.01", "--h", "0.01"],
        &["cylinder", "--radius", "0.02", "--length", "0.1", "--h", "0.01"],
        &["tube", "--inner-radius", "0.015", "--outer-radius", "0.02", "--length", "0.1", "--h", "0.005"],
        &["sphere", "--radius", "0.05", "--h", "0.02", "--order", "2"],
        &["bowl", "--radius", "0.06", "--thickness", "0.005", "--h", "0.01"],
    ];
    for shape in shapes {
        let mut args = vec!["mesh"];
        args.extend(shape);
        args.extend(["-o", "shape.msh", "--json"]);
        let written = modal(dir.path(), &args).ok().json();
        assert!(written["tets"].as_u64().unwrap() > 0);
        let h: f64 = shape[shape.iter().position(|&a| a == "--h").unwrap() + 1].parse().unwrap();
        assert_eq!(written["element_size_m"].as_f64(), Some(h), "the size used is reported");
        let mut solve = vec![
            "precompute",
            "shape.msh",
            "-o",
            "shape.bank",
            "--modes",
            "3",
            "--max-freq",
            "1e6",
            "--no-cache",
            "--json",
        ];
        solve.extend(STEEL);
        let json = modal(dir.path(), &solve).ok().json();
        assert_eq!(json["rigid_modes_removed"], 6, "{shape:?}");
        assert_eq!(json["modes"].as_array().unwrap().len(), 3, "{shape:?}");
    }
    modal(dir.path(), &["mesh", "sphere", "--radius", "-1", "-o", "bad.msh"]).fails_with("radius");
    assert!(!dir.path().join("bad.msh").exists());
}

#[test]
fn a_mesh_beyond_the_memory_guard_is_refused_before_assembly() {
    // 1 MB: less than the bar's stiffness and mass matrices alone.
    let dir = temp_dir();
    let bar = example("bar_p1.msh");
    let args = ["precompute", bar.to_str().unwrap(), "-o", "a.bank", "--no-cache", "--material", "steel"];
    let run = modal_within_memory(dir.path(), &args, "0.001");
    let text = run.fails_with("stiffness and mass matrices alone would need").stderr;
    assert!(text.contains("DOF") && text.contains("coarser mesh"), "{text}");
    assert!(!dir.path().join("a.bank").exists(), "no output on failure");
}

#[test]
fn a_surface_whose_tets_cannot_fit_the_memory_guard_is_refused_before_meshing() {
    // The example bar at a 1 mm cell: ≈ 720 k tets, whose K, M and factor need at least
    // 8.6 GB. With a 1 GB guard it was meshed for 12 s (3.3 M DOF) and then refused.
    let dir = temp_dir();
    let bar = example("bar.obj");
    let args = [
        "precompute",
        bar.to_str().unwrap(),
        "-o",
        "a.bank",
        "--no-cache",
        "--material",
        "steel",
        "--cell",
        "0.001",
    ];
    let run = modal_within_memory(dir.path(), &args, "1");
    let text = run.fails_with("would be meshed into about").stderr;
    assert!(text.contains("memory limit of 1.0 GB") && text.contains("--cell"), "{text}");
    assert!(!dir.path().join("a.bank").exists(), "no output on failure");
}

#[test]
fn a_default_surface_mesh_beyond_the_memory_guard_is_coarsened_to_fit_and_not_cached() {
    // The demo bowl at its default sizes needs ≈ 0.6 GB; under a 0.3 GB guard it was
    // refused (a wine glass on a 24 GB machine: a minute of meshing and assembly, then
    // refused for its 32 GB factor). Now the first level is coarsened until it fits,
    // said in a warning, and the bank, not the request's answer, is not cached.
    let dir = temp_dir();
    let bowl = example("bowl.obj");
    let bowl = bowl.to_str().unwrap();
    let base = ["precompute", bowl, "--material", "glass", "--modes", "6", "--json"];
    let at_defaults =
        modal(dir.path(), &[&base[..], &["-o", "d.bank", "--no-cache", "--accuracy", "off"]].concat());
    let at_defaults = at_defaults.ok().json();
    let cached = ["-o", "a.bank", "--cache-dir", "cache"];
    let run = modal_within_memory(dir.path(), &[&base[..], &cached[..]].concat(), "0.3").ok();
    let warning =
        run.stderr.lines().find(|l| l.contains("above the memory limit of 0.3 GB")).unwrap_or_default();
    assert!(warning.contains("element size ×") && warning.contains("not cached"), "{}", run.stderr);
    let fitted = run.json();
    let dofs = |j: &Value| j["dofs"].as_u64().unwrap();
    assert!(dofs(&fitted) < dofs(&at_defaults), "{} DOF against {}", dofs(&fitted), dofs(&at_defaults));
    // A coarser mesh of the same bowl, with its error said.
    for (mode, reference) in fitted["modes"].as_array().unwrap().iter().zip(frequencies(&at_defaults)) {
        let f = mode["frequency_hz"].as_f64().unwrap();
        assert!((f / reference - 1.0).abs() < 0.05, "{f} Hz against {reference} Hz at the defaults");
        assert!(mode["error_estimate_pct"].as_f64().is_some_and(|e| e > 0.0), "{mode}");
    }
    let again = modal_within_memory(dir.path(), &[&base[..], &cached[..]].concat(), "0.3").ok();
    assert_eq!(again.json()["cached"], Value::Bool(false), "a coarsened bank is not served from the cache");
}

/// A first level coarsened to fit the memory guard that falls apart is
/// refused before its solve: a dumbbell (two 4 cm discs on a 6 mm neck, one
/// surface) is one body at the defaults; under a 0.05 GB guard, at × 2.3
/// cells, its neck is gone and it would ring as two loose pieces (a wine
/// glass of 1.5 mm wall came out in six).
#[test]
fn a_mesh_that_falls_apart_when_coarsened_for_memory_is_refused() {
    let dir = temp_dir();
    let profile = [
        (0.0, 0.0),
        (0.02, 0.0),
        (0.02, 0.04),
        (0.003, 0.04),
        (0.003, 0.10),
        (0.02, 0.10),
        (0.02, 0.14),
        (0.0, 0.14),
    ];
    let surface = modal_tetra::shapes::revolve(&profile, 32, "dumbbell");
    let mut obj = Vec::new();
    modal_tetra::write_obj(&surface, &mut obj).unwrap();
    std::fs::write(dir.path().join("dumbbell.obj"), obj).unwrap();
    let base =
        ["precompute", "dumbbell.obj", "--material", "steel", "--no-cache", "--accuracy", "off", "--json"];
    let whole = modal(dir.path(), &[&base[..], &["-o", "a.bank"]].concat()).ok().json();
    assert_eq!(whole["rigid_modes_removed"].as_u64(), Some(6), "one body at the defaults");
    let run = modal_within_memory(dir.path(), &[&base[..], &["-o", "b.bank"]].concat(), "0.05");
    let run = run.fails_with("falls apart into 2 parts (the surface is 1 body)");
    assert!(run.stderr.contains("to fit the memory limit"), "{}", run.stderr);
    assert!(!dir.path().join("b.bank").exists());
}

#[test]
fn a_mesh_whose_factor_exceeds_the_memory_guard_is_refused_before_its_matrices_are_assembled() {
    // A 5 cm cube at 4 mm, 59 k DOF: K and M ≈ 0.2 GB fit 0.3 GB, their factor (≈ 0.4 GB)
    // does not. Refused from the symbolic analysis of the pattern, before the values exist
    // (before: after assembly, by the eigensolver; at 4.5 M DOF that was 15 GB of K and M
    // assembled and a 21.5 GB peak on a 24 GB machine). With 1 GB it is solved.
    let dir = temp_dir();
    modal(dir.path(), &["mesh", "box", "--size", "0.05,0.05,0.05", "--h", "0.004", "-o", "cube.msh"]).ok();
    let args =
        ["precompute", "cube.msh", "-o", "a.bank", "--no-cache", "--material", "steel", "--modes", "5"];
    let run = modal_within_memory(dir.path(), &args, "0.3");
    let text = run.fails_with("and their factor").stderr;
    assert!(text.contains("59049 DOF") && text.contains("coarser mesh"), "{text}");
    assert!(!dir.path().join("a.bank").exists(), "no output on failure");
    modal_within_memory(dir.path(), &args, "1").ok();
    assert!(dir.path().join("a.bank").exists());
}

/// A geometry-only `.glb` (no modal model): the unit cube's 12 triangles,
/// placed by one node scaled by `scale` (glTF §5.25: T·R·S).
fn unit_cube_glb(scale: [f64; 3]) -> Vec<u8> {
    let cube = modal_tetra::shapes::cuboid(1.0, 1.0, 1.0);
    let mut bin: Vec<u8> = cube.vertices.iter().flatten().flat_map(|&c| (c as f32).to_le_bytes()).collect();
    bin.extend(cube.triangles.iter().flatten().flat_map(|&i| (i as u32).to_le_bytes()));
    let document = serde_json::json!({
        "asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "scale": scale}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [{"buffer": 0, "byteLength": 96}, {"buffer": 0, "byteOffset": 96, "byteLength": 144}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5125, "count": 36, "type": "SCALAR"}
        ]
    });
    modal_export::gltf::glb_container(&document, bin).unwrap()
}

#[test]
fn a_glb_or_off_without_a_modal_model_is_meshed_like_the_same_obj() {
    // Game assets come as glTF: one without the modal extension is geometry,
    // meshed and solved (one with it is read as a bank, as before).
    let dir = temp_dir();
    // Binary fractions: the glTF's f32 scale and the OBJ's decimals are the same numbers.
    let size = [0.125, 0.0625, 0.03125];
    std::fs::write(dir.path().join("box.glb"), unit_cube_glb(size)).unwrap();
    let obj = std::fs::File::create(dir.path().join("box.obj")).unwrap();
    modal_tetra::write_obj(&modal_tetra::shapes::cuboid(size[0], size[1], size[2]), obj).unwrap();
    let solve = |input: &str| {
        let args = ["precompute", input, "-o", "b.bank", "--no-cache", "--material", "steel", "--modes", "6"];
        modal(dir.path(), &[&args[..], &["--cell", "0.01", "--accuracy", "off", "--json"]].concat())
            .ok()
            .json()
    };
    let (from_glb, from_obj) = (solve("box.glb"), solve("box.obj"));
    assert_eq!(from_glb["dofs"], from_obj["dofs"]);
    assert_eq!(frequencies(&from_glb), frequencies(&from_obj), "the same mesh, the same modes");
    // Datasets (ModelNet) come as OFF, with the keyword fused to the counts.
    let cube = modal_tetra::shapes::cuboid(size[0], size[1], size[2]);
    let mut off = format!("OFF{} {} 0\n", cube.vertices.len(), cube.triangles.len());
    cube.vertices.iter().for_each(|p| off += &format!("{} {} {}\n", p[0], p[1], p[2]));
    cube.triangles.iter().for_each(|t| off += &format!("3 {} {} {}\n", t[0], t[1], t[2]));
    std::fs::write(dir.path().join("box.off"), off).unwrap();
    assert_eq!(frequencies(&solve("box.off")), frequencies(&from_obj), "OFF: the same modes");
}

#[test]
fn a_file_in_millimetres_is_refused_at_once_and_solved_with_its_scale() {
    // 3D printing and CAD write millimetres; read as metres, this 40 mm steel block
    // is 40 m long, every mode lies far below the band, and the solve used to fail
    // after minutes (a mug: 3 min 10 s, then "eigensolver stalled").
    let dir = temp_dir();
    let size_mm = [40.0, 20.0, 16.0];
    let obj = std::fs::File::create(dir.path().join("block_mm.obj")).unwrap();
    modal_tetra::write_obj(&modal_tetra::shapes::cuboid(size_mm[0], size_mm[1], size_mm[2]), obj).unwrap();
    let precompute = |input: &str, extra: &[&str]| {
        let args = ["precompute", input, "-o", "b.bank", "--no-cache", "--material", "steel", "--modes", "4"];
        modal(
            dir.path(),
            &[&args[..], &["--cell", "0.008", "--max-freq", "1e6", "--accuracy", "off", "--json"], extra]
                .concat(),
        )
    };
    // A block of 4.7 x 3.5 x 3.9 (a mug's size in inches) is solved, with a warning
    // said as the file is read, before the solve, and no warning once a scale is stated.
    let obj = std::fs::File::create(dir.path().join("block_in.obj")).unwrap();
    modal_tetra::write_obj(&modal_tetra::shapes::cuboid(4.7, 3.5, 3.9), obj).unwrap();
    let args = ["precompute", "block_in.obj", "-o", "i.bank", "--no-cache", "--material", "steel"];
    let inches =
        modal(dir.path(), &[&args[..], &["--cell", "1", "--modes", "2", "--accuracy", "off"]].concat()).ok();
    let said = inches.stderr.find("7.04 m across").expect("a size warning");
    assert!(said < inches.stderr.find("assembling K and M").unwrap(), "{}", inches.stderr);
    let stated = [&args[..], &["--cell", "1", "--modes", "2", "--accuracy", "off", "--scale", "1"]].concat();
    assert!(!modal(dir.path(), &stated).ok().stderr.contains("m across"));
    let refused = precompute("block_mm.obj", &[]).fails_with("--scale 0.001");
    assert!(refused.stderr.contains("47.5 m across"), "{}", refused.stderr);
    assert!(!dir.path().join("b.bank").exists(), "no output for a refused file");
    // The same for a tet mesh file (`mesh tet` only warns: meshing is cheap).
    let meshed =
        modal(dir.path(), &["mesh", "tet", "block_mm.obj", "-o", "block_mm.msh", "--cell", "8"]).ok();
    assert!(meshed.stderr.contains("--scale 0.001"), "{}", meshed.stderr);
    precompute("block_mm.msh", &[]).fails_with("--scale 0.001");
    // A stated scale must still be a unit conversion (1e300 overflowed every coordinate).
    for absurd in ["1e300", "1e-300"] {
        precompute("block_mm.obj", &["--scale", absurd]).fails_with("no unit conversion");
    }
    // With its scale it is the 40 mm block, and its modes are those of the file in metres.
    let in_metres = std::fs::File::create(dir.path().join("block.obj")).unwrap();
    modal_tetra::write_obj(&modal_tetra::shapes::cuboid(0.04, 0.02, 0.016), in_metres).unwrap();
    let scaled = frequencies(&precompute("block_mm.obj", &["--scale", "0.001"]).ok().json());
    let metres = frequencies(&precompute("block.obj", &[]).ok().json());
    assert_eq!(scaled.len(), 4);
    for (a, b) in scaled.iter().zip(&metres) {
        assert!((a / b - 1.0).abs() < 1e-9, "scaled {a} Hz against {b} Hz in metres");
    }
}

#[test]
fn a_bank_silent_in_the_band_is_said_after_one_level() {
    // A 40 mm steel block rings above 20 kHz: the first level shows the band empty,
    // and finer levels could only add minutes (a 6 mm bead went on to level 2).
    let dir = temp_dir();
    let obj = std::fs::File::create(dir.path().join("block.obj")).unwrap();
    modal_tetra::write_obj(&modal_tetra::shapes::cuboid(0.04, 0.02, 0.016), obj).unwrap();
    let args = ["precompute", "block.obj", "-o", "b.bank", "--no-cache", "--material", "steel", "--json"];
    let run = modal(dir.path(), &args).ok();
    assert_eq!(frequencies(&run.json()).len(), 0);
    assert!(run.stderr.contains("the bank is silent"), "{}", run.stderr);
    assert!(!run.stderr.contains("level 1"), "no second level for a silent bank: {}", run.stderr);
}

#[test]
fn surface_options_on_a_tet_mesh_are_named_not_dropped() {
    let dir = temp_dir();
    let bar = example("bar_p1.msh");
    let mut args = vec!["precompute", bar.to_str().unwrap(), "-o", "a.bank", "--modes", "4", "--no-cache"];
    args.extend(STEEL);
    args.extend(["--cell", "0.01", "--sheet-thickness", "0.002"]);
    let run = modal(dir.path(), &args).ok();
    assert!(
        run.stderr.contains("--cell, --sheet-thickness apply to surface meshes only")
            && run.stderr.contains("bar_p1.msh"),
        "{}",
        run.stderr
    );
}

#[test]
fn absurd_thread_and_mode_counts_are_refused_before_any_work() {
    // 100 000 threads stalled for over a minute before the solve; 0 was taken silently.
    let dir = temp_dir();
    let bar = example("bar_p1.msh");
    let args = ["precompute", bar.to_str().unwrap(), "-o", "b.bank", "--material", "steel", "--no-cache"];
    for n in ["0", "100000"] {
        modal(dir.path(), &[&args[..], &["--threads", n]].concat())
            .fails_with("--threads must be between 1 and 1024");
    }
    // 10¹¹ modes overflowed the memory estimate into a solve, or blamed the mesh.
    for n in ["0", "100000000000", "18446744073709551615"] {
        modal(dir.path(), &[&args[..], &["--modes", n]].concat())
            .fails_with("--modes must be between 1 and 100000");
    }
    // Within the range, a search space too large for the memory is said to be the modes'.
    let many = [&args[..], &["--modes", "50000"]].concat();
    modal_within_memory(dir.path(), &many, "1").fails_with("ask for fewer modes");
    assert!(!dir.path().join("b.bank").exists());
}

/// A 10 × 5 × 3 cm box as a `.gltf` whose geometry is in `box.bin` next to it;
/// `dent` moves the top of one corner down (1: a plain box).
fn gltf_box_with_external_buffer(dir: &std::path::Path, dent: f32) {
    let (x, y, z) = (0.1f32, 0.05f32, 0.03f32);
    let cuboid = modal_tetra::shapes::cuboid(f64::from(x), f64::from(y), f64::from(z));
    let mut v: Vec<[f32; 3]> = cuboid.vertices.iter().map(|p| p.map(|c| c as f32)).collect();
    v[7][2] *= dent;
    let f: Vec<[u16; 3]> = cuboid.triangles.iter().map(|t| t.map(|i| i as u16)).collect();
    let mut bin: Vec<u8> = v.iter().flatten().flat_map(|c: &f32| c.to_le_bytes()).collect();
    let vertex_bytes = bin.len();
    bin.extend(f.iter().flatten().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.join("box.bin"), &bin).unwrap();
    let gltf = serde_json::json!({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"uri": "box.bin", "byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": vertex_bytes},
            {"buffer": 0, "byteOffset": vertex_bytes, "byteLength": bin.len() - vertex_bytes}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [0, 0, 0], "max": [x, y, z]},
            {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}
        ]
    });
    std::fs::write(dir.join("box.gltf"), gltf.to_string()).unwrap();
}

#[test]
fn a_gltf_whose_bin_file_changed_is_solved_again() {
    // The cache key hashed the .gltf alone: after an artist re-exported the .bin,
    // the old bank was served (even to a batch with --no-cache, from its --out).
    let dir = temp_dir();
    let solve = |dir: &std::path::Path| {
        let args = ["precompute", "box.gltf", "-o", "b.bank", "--material", "steel", "--modes", "2"];
        modal(dir, &[&args[..], &["--cell", "0.01", "--accuracy", "off", "--json"]].concat()).ok().json()
    };
    gltf_box_with_external_buffer(dir.path(), 1.0);
    let plain = solve(dir.path());
    assert_eq!(solve(dir.path())["cached"], true, "the same files: served from the cache");
    gltf_box_with_external_buffer(dir.path(), 0.3);
    let dented = solve(dir.path());
    assert_eq!(dented["cached"], false);
    let mass = |report: &serde_json::Value| report["mass_kg"].as_f64().unwrap();
    assert!(mass(&dented) < 0.95 * mass(&plain), "{} kg against {} kg", mass(&dented), mass(&plain));
}
