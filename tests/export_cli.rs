//! End-to-end tests of `modal export`: Faust models (parsed back and, when the
//! Faust compiler is installed, compiled), and the refusals.

mod common;
use common::*;

use std::path::Path;

/// A steel bar bank (lightly damped, 12 modes) in `dir/bar.bank`.
fn bar_bank(dir: &Path) {
    let bar = example("bar_p1.msh");
    let mut args = vec!["precompute", bar.to_str().unwrap(), "-o", "bar.bank", "--modes", "12"];
    args.extend(STEEL);
    args.extend(["--alpha", "5", "--beta", "3e-8"]);
    modal(dir, &args).ok();
}

/// The numbers of a Faust modal model, read back from its text by a parser
/// that knows only the mesh2faust form (not the writer's code).
#[derive(Debug)]
struct ParsedFaust {
    name: String,
    n_modes: usize,
    n_ex_pos: usize,
    freqs: Vec<f64>,
    gains: Vec<f64>,
    t60s: Vec<f64>,
}

fn numbers(list: &str) -> Vec<f64> {
    list.split(',')
        .map(|s| match s.trim() {
            "ma.INFINITY" => f64::INFINITY,
            t => t.parse::<f64>().unwrap_or_else(|_| panic!("'{t}' is not a number")),
        })
        .collect()
}

/// The text between `open` (after `start`) and the matching `close`.
fn between<'a>(text: &'a str, start: &str, close: char) -> &'a str {
    let from = text.find(start).unwrap_or_else(|| panic!("no '{start}' in\n{text}")) + start.len();
    let len = text[from..].find(close).unwrap_or_else(|| panic!("'{start}' is not closed"));
    &text[from..from + len]
}

fn parse_faust(text: &str) -> ParsedFaust {
    assert!(text.contains("import(\"stdfaust.lib\");"));
    let head = text.lines().find(|l| l.contains("(exPos,t60Scale) = _ <: par(")).expect("model definition");
    let name = head.split('(').next().unwrap().trim().to_string();
    assert!(head.contains(
        "par(i,nModes,pm.modeFilter(modesFreqs(i),modesT60s(i),modesGains(int(exPos),i))) :> /(nModes)"
    ));
    let body = &text[text.find("with{").expect("with block")..];
    assert!(body.trim_end().ends_with("};"), "with block closes");
    ParsedFaust {
        name,
        n_modes: between(body, "nModes = ", ';').parse().unwrap(),
        n_ex_pos: between(body, "nExPos = ", ';').parse().unwrap(),
        freqs: numbers(between(body, "modesFreqs(n) = ba.take(n+1,(", ')')),
        gains: numbers(between(body, "modesGains(p,n) = waveform{", '}')),
        t60s: numbers(between(body, "modesT60s(n) = t60Scale*ba.take(n+1,(", ')')),
    }
}

#[test]
fn faust_model_parses_and_its_values_match_the_bank() {
    let dir = temp_dir();
    bar_bank(dir.path());
    let at = [[0.05, 0.01, 0.01], [0.3, 0.005, 0.002], [0.15, 0.0, 0.005]];
    let at_args: Vec<String> = at.iter().map(|p| format!("{},{},{}", p[0], p[1], p[2])).collect();
    let mut args = vec!["export", "bar.bank", "--faust", "bar.lib", "--faust-name", "bar", "--json"];
    for a in &at_args {
        args.extend(["--at", a]);
    }
    let report = modal(dir.path(), &args).ok().json();
    let text = std::fs::read_to_string(dir.path().join("bar.lib")).unwrap();
    let parsed = parse_faust(&text);
    let bank = modal_bank::ModeBank::load(dir.path().join("bar.bank")).unwrap();
    assert_eq!(parsed.name, "bar");
    assert_eq!(parsed.n_modes, 12);
    assert_eq!(parsed.n_ex_pos, 3);
    assert_eq!(parsed.freqs.len(), 12);
    assert_eq!(parsed.t60s.len(), 12);
    assert_eq!(parsed.gains.len(), 3 * 12);
    for i in 0..12 {
        // Damped frequency f√(1−ξ²) and T60 = ln(1000)/d, from the bank's own arrays.
        let xi = bank.damping_ratios[i];
        assert_eq!(parsed.freqs[i], bank.frequencies_hz[i] * (1.0 - xi * xi).sqrt(), "mode {i}");
        assert_eq!(parsed.t60s[i], 1000f64.ln() / bank.decay_rates[i], "mode {i}");
    }
    // Gains: |φ_i(x)·n| at the snapped point, each row divided by its largest.
    let model = modal_synth::SynthModel::new(&bank).unwrap();
    let mut dots = vec![0.0; 12];
    for (p, point) in at.iter().enumerate() {
        let hit = model.locate(*point).unwrap();
        model.shapes_dot(&hit, hit.normal, &mut dots);
        let scale = dots.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        assert!(scale > 0.0);
        let json = &report["faust"]["positions"][p];
        assert_eq!(json["gain_scale"].as_f64().unwrap(), scale);
        assert_eq!(json["surface_point"][0].as_f64().unwrap(), hit.position[0]);
        let row = &parsed.gains[p * 12..(p + 1) * 12];
        for i in 0..12 {
            assert!((row[i] - dots[i].abs() / scale).abs() < 1e-15, "position {p} mode {i}");
        }
        assert_eq!(row.iter().cloned().fold(0.0, f64::max), 1.0);
    }
    assert_eq!(report["faust"]["modes"], 12);
    // The free end of the bar moves in more modes than its nodal regions:
    // the rows differ.
    assert_ne!(parsed.gains[..12], parsed.gains[12..24]);
}

/// `faust` on the PATH (Debian package `faust`), if installed.
fn faust_compiler() -> Option<std::path::PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path).map(|d| d.join("faust")).find(|p| p.is_file())
}

#[test]
fn faust_model_compiles_with_the_faust_compiler_when_installed() {
    let Some(faust) = faust_compiler() else {
        eprintln!("faust is not installed (apt-get install faust): only the parser test ran");
        return;
    };
    let dir = temp_dir();
    bar_bank(dir.path());
    let args =
        ["export", "bar.bank", "--faust", "bar.lib", "--at", "0.05,0.01,0.01", "--at", "0.3,0.01,0.01"];
    modal(dir.path(), &args).ok();
    let dsp = "import(\"stdfaust.lib\");\nimport(\"bar.lib\");\n\
               process = button(\"gate\") : ba.impulsify : modalModel(nentry(\"exPos\",0,0,1,1),1);\n";
    std::fs::write(dir.path().join("strike.dsp"), dsp).unwrap();
    let out = std::process::Command::new(faust)
        .args(["-lang", "cpp", "-o", "strike.cpp", "strike.dsp"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "faust failed: {}", String::from_utf8_lossy(&out.stderr));
    let cpp = std::fs::read_to_string(dir.path().join("strike.cpp")).unwrap();
    assert!(cpp.contains("class mydsp"), "generated C++ has the DSP class");
}

#[test]
fn faust_export_refuses_bad_input_and_leaves_nothing() {
    let dir = temp_dir();
    bar_bank(dir.path());
    // Far from the bar (0.3 x 0.02 x 0.01 m): refused, no file.
    modal(dir.path(), &["export", "bar.bank", "--faust", "x.lib", "--at", "0.15,0.5,0.0"])
        .fails_with("from the surface");
    modal(dir.path(), &["export", "bar.bank", "--faust", "x.lib", "--at", "0,0,0", "--faust-name", "9x"])
        .fails_with("not a Faust identifier");
    // Names Faust would refuse only when the library is compiled: say why now.
    modal(dir.path(), &["export", "bar.bank", "--faust", "x.lib", "--at", "0,0,0", "--faust-name", "ba"])
        .fails_with("--faust-name: `ba` is a Faust standard library environment (stdfaust.lib)");
    modal(dir.path(), &["export", "bar.bank", "--faust", "x.lib", "--at", "0,0,0", "--faust-name", "with"])
        .fails_with("`with` is a Faust keyword");
    assert!(!dir.path().join("x.lib").exists());
    assert!(files_in(dir.path()).iter().all(|f| !f.ends_with(".tmp")));
    // --faust needs --at (a malformed command line: exit code 2).
    let run = modal(dir.path(), &["export", "bar.bank", "--faust", "x.lib"]);
    assert_eq!(run.code, Some(2));
    // No output format at all.
    assert_eq!(modal(dir.path(), &["export", "bar.bank"]).code, Some(2));
    // With --json a malformed command line is one JSON object on stdout too.
    let typo = modal(dir.path(), &["info", "bar.bank", "--json", "--jsno"]);
    assert_eq!(typo.code, Some(2));
    assert_eq!(typo.json()["error"].as_str(), Some("unexpected argument '--jsno' found"), "{}", typo.stdout);
    assert!(typo.stderr.contains("a similar argument exists: '--json'"), "{}", typo.stderr);
    let help = modal(dir.path(), &["info", "--help", "--json"]);
    assert!(help.success && help.stdout.contains("Usage: modal info"), "help stays help: {}", help.stdout);
}

#[test]
fn gltf_export_round_trips_to_identical_wavs_and_banks() {
    let dir = temp_dir();
    bar_bank(dir.path());
    let report = modal(dir.path(), &["export", "bar.bank", "--gltf", "bar.glb", "--json"]).ok().json();
    assert!(report["gltf"]["bytes"].as_u64().unwrap() > 1000);
    let glb = std::fs::read(dir.path().join("bar.glb")).unwrap();
    assert_eq!(&glb[..4], b"glTF");
    // Strike the bank and the glTF the same way: the same samples.
    let strike = |bank: &str, out: &str| {
        let args = [
            "strike",
            bank,
            "--at",
            "0.05,0.01,0.01",
            "--at",
            "0.29,0.0,0.005",
            "--duration",
            "0.3",
            "-o",
            out,
        ];
        modal(dir.path(), &args).ok();
        std::fs::read(dir.path().join(out)).unwrap()
    };
    let from_bank = strike("bar.bank", "bank.wav");
    let from_gltf = strike("bar.glb", "gltf.wav");
    assert!(from_bank.len() > 10_000);
    assert_eq!(from_bank, from_gltf, "identical WAV bytes");
    // precompute on a glTF stores its modes: the same bank file, byte for byte.
    let json = modal(dir.path(), &["precompute", "bar.glb", "-o", "again.bank", "--json"]).ok().json();
    assert_eq!(json["modes"].as_array().unwrap().len(), 12);
    let original = std::fs::read(dir.path().join("bar.bank")).unwrap();
    assert_eq!(std::fs::read(dir.path().join("again.bank")).unwrap(), original);
    // info reads it too.
    let info = modal(dir.path(), &["info", "bar.glb", "--json"]).ok().json();
    assert_eq!(info["modes"], json["modes"]);
}

#[test]
fn a_scene_object_can_name_a_gltf_bank() {
    let dir = temp_dir();
    bar_bank(dir.path());
    modal(dir.path(), &["export", "bar.bank", "--gltf", "bar.glb"]).ok();
    let scene = |bank: &str| {
        format!(
            "duration = 0.4\nsample_rate = 16000\n[listener]\nposition = [0.0, 0.2, 0.5]\nchannels = \"mono\"\n\
             [ground]\nmaterial = \"wood\"\n[[objects]]\nname = \"bar\"\nbank = \"{bank}\"\nposition = [0.0, 0.05, 0.0]\n"
        )
    };
    std::fs::write(dir.path().join("a.toml"), scene("bar.bank")).unwrap();
    std::fs::write(dir.path().join("b.toml"), scene("bar.glb")).unwrap();
    let a = modal(dir.path(), &["render", "a.toml", "-o", "a.wav", "--json"]).ok().json();
    modal(dir.path(), &["render", "b.toml", "-o", "b.wav"]).ok();
    assert!(a["objects"][0]["impacts"].as_u64().unwrap() >= 1, "{a}");
    let wav = std::fs::read(dir.path().join("a.wav")).unwrap();
    assert_eq!(std::fs::read(dir.path().join("b.wav")).unwrap(), wav);
    // Named as a mesh, a glTF with a modal model is that bank too (it was
    // re-meshed from its surface and solved anew, without a word), retuned
    // to the object's material: here the bank's own, so the same sound.
    let same = "material = { youngs = 200e9, poisson = 0.3, density = 7850, alpha = 5, beta = 3e-8 }";
    let as_mesh = scene("bar.glb").replace("bank = \"bar.glb\"", &format!("mesh = \"bar.glb\"\n{same}"));
    std::fs::write(dir.path().join("c.toml"), as_mesh).unwrap();
    let said = modal(dir.path(), &["render", "c.toml", "-o", "c.wav", "--json"]).ok();
    assert!(said.stderr.contains("holds a modal model: used as the object's bank"), "{}", said.stderr);
    assert_eq!(said.json()["banks_solved"].as_u64(), Some(0), "{}", said.stdout);
    assert_eq!(std::fs::read(dir.path().join("c.wav")).unwrap(), wav);
}

#[test]
fn gltf_files_without_modal_data_are_refused() {
    let dir = temp_dir();
    std::fs::write(dir.path().join("junk.glb"), b"glTF but not really").unwrap();
    modal(dir.path(), &["strike", "junk.glb", "--at", "0,0,0", "-o", "x.wav"]).fails_with("junk.glb");
    modal(dir.path(), &["precompute", "junk.glb", "-o", "x.bank"]).fails_with("not a valid glTF");
    assert!(!dir.path().join("x.wav").exists() && !dir.path().join("x.bank").exists());
}

#[test]
fn a_stored_transfer_survives_the_gltf_round_trip() {
    // The bank's acoustic transfer travels in the glTF's side data: striking,
    // re-importing and rendering the .glb hear it as they do the .bank.
    let dir = temp_dir();
    bar_bank(dir.path());
    modal(dir.path(), &["radiation", "bar.bank", "--max-freq", "1200", "--store", "rad.bank"]).ok();
    let report = modal(dir.path(), &["export", "rad.bank", "--gltf", "rad.glb", "--json"]).ok().json();
    assert_eq!(report["gltf"]["radiation_modes"], 2, "{report}");
    assert_eq!(
        (report["gltf"]["modes"].as_u64(), report["gltf"]["skipped_modes"].as_u64()),
        (Some(12), Some(0))
    );
    let strike = |bank: &str, out: &str| {
        let run =
            modal(dir.path(), &["strike", bank, "--at", "0.29,0.0,0.005", "--duration", "0.3", "-o", out])
                .ok();
        (run.stderr, std::fs::read(dir.path().join(out)).unwrap())
    };
    let (bank_log, from_bank) = strike("rad.bank", "bank.wav");
    let (gltf_log, from_gltf) = strike("rad.glb", "gltf.wav");
    assert!(!gltf_log.contains("no radiation data"), "{gltf_log}");
    assert_eq!(bank_log.contains("no stored radiation"), gltf_log.contains("no stored radiation"));
    assert_eq!(from_bank, from_gltf, "identical WAV bytes");
    modal(dir.path(), &["precompute", "rad.glb", "-o", "again.bank"]).ok();
    let original = std::fs::read(dir.path().join("rad.bank")).unwrap();
    assert_eq!(std::fs::read(dir.path().join("again.bank")).unwrap(), original);
    let info = modal(dir.path(), &["info", "rad.glb", "--json"]).ok().json();
    assert!(info["modes"][0]["radiated_power_w"].as_f64().unwrap() > 0.0, "{info}");
    // A glTF output must be named .glb: the file is binary.
    modal(dir.path(), &["export", "rad.bank", "--gltf", "rad.gltf"]).fails_with("give it a .glb name");
    modal(dir.path(), &["export", "rad.bank", "--gltf", "rad2.bank"]).fails_with("give it a .glb name");
    modal(dir.path(), &["export", "rad.bank", "--vtk", "rad.txt"]).fails_with("give it a .vtu name");
    assert!(!dir.path().join("rad.txt").exists());
    assert!(!dir.path().join("rad.gltf").exists() && !dir.path().join("rad2.bank").exists());
}
