//! End-to-end tests of `modal precompute-batch` and `modal catalogue merge`
//! (issue #17): shards in parallel processes on one cache equal the unsharded
//! run, a killed run resumes without redoing finished assets, a corrupt asset
//! is reported while the others complete, the scheduler environment selects
//! the shard, and a torn cache entry is detected and redone.
//!
//! The assets are tiny linear-tet boxes (a few hundred DOF, 4 modes), so the
//! whole file runs in seconds.

mod common;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::temp_dir;
use serde_json::Value;

/// Scheduler variables a test machine might have set; every run clears them.
const SCHEDULER_VARS: [&str; 6] = [
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_MIN",
    "SLURM_ARRAY_TASK_COUNT",
    "JOB_COMPLETION_INDEX",
    "MODAL_SHARD_COUNT",
    "MODAL_CACHE_DIR",
];

/// `modal ARGS` in `dir` with a clean scheduler environment plus `env`.
fn command(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_modal"));
    cmd.args(args).current_dir(dir);
    for var in SCHEDULER_VARS {
        cmd.env_remove(var);
    }
    cmd.env("MODAL_CACHE_DIR", dir.join("default-cache"));
    cmd.envs(env.iter().copied());
    cmd
}

struct Run {
    code: Option<i32>,
    stdout: String,
    stderr: String,
}

impl Run {
    fn from(output: Output) -> Run {
        Run {
            code: output.status.code(),
            stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
            stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
        }
    }

    fn ok(self) -> Run {
        assert_eq!(self.code, Some(0), "modal failed: {}\nstdout: {}", self.stderr, self.stdout);
        self
    }

    fn json(&self) -> Value {
        serde_json::from_str(&self.stdout)
            .unwrap_or_else(|e| panic!("stdout is not JSON ({e}): {}", self.stdout))
    }

    /// Exactly one `error:` line, mentioning `needle`; exit code 1; no panic.
    fn fails_with(self, needle: &str) -> Run {
        assert_eq!(self.code, Some(1), "expected exit code 1: {}", self.stderr);
        assert!(!self.stderr.contains("panicked"), "{}", self.stderr);
        let errors: Vec<&str> = self.stderr.lines().filter(|l| l.starts_with("error")).collect();
        assert_eq!(errors.len(), 1, "{}", self.stderr);
        assert!(errors[0].contains(needle), "'{}' does not mention '{needle}'", errors[0]);
        self
    }
}

fn modal(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Run {
    Run::from(command(dir, args, env).output().expect("modal runs"))
}

/// Writes `n` boxes of different sizes and element size `h` under `dir/props` (`box_NN.msh`).
fn boxes(dir: &Path, n: usize, h: &str) {
    std::fs::create_dir_all(dir.join("props")).unwrap();
    for i in 0..n {
        let size = format!("{},0.06,0.04", 0.12 + 0.01 * i as f64);
        let out = format!("props/box_{i:02}.msh");
        modal(dir, &["mesh", "box", "--size", &size, "--h", h, "-o", &out], &[]).ok();
    }
}

/// A manifest of `n` boxes: the first half listed (some with their own
/// material), the rest through a glob; linear tets, 4 modes.
fn manifest(dir: &Path, n: usize) -> PathBuf {
    manifest_of(dir, n, "0.03")
}

/// [`manifest`] with boxes of element size `h`.
fn manifest_of(dir: &Path, n: usize, h: &str) -> PathBuf {
    boxes(dir, n, h);
    let mut text =
        String::from("[defaults]\nmaterial = \"steel\"\norder = 1\nmodes = 4\nmax_freq = 200000\n\n");
    for i in 0..n / 2 {
        text.push_str(&format!("[[assets]]\npath = \"props/box_{i:02}.msh\"\n"));
        if i % 3 == 1 {
            text.push_str("material = \"glass\"\n");
        }
        text.push('\n');
    }
    // The glob also matches the listed boxes: those keep their [[assets]] options.
    text.push_str("[[globs]]\npattern = \"props/*.msh\"\nmaterial = \"aluminium\"\n");
    let path = dir.join("library.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn entries(catalogue: &Value) -> &Vec<Value> {
    catalogue["assets"].as_array().expect("an assets array")
}

fn load(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The catalogue with the run-dependent fields (`seconds`, `cached`) removed.
fn results(catalogue: &Value) -> Value {
    let mut c = catalogue.clone();
    for e in c["assets"].as_array_mut().unwrap() {
        let e = e.as_object_mut().unwrap();
        assert!(e.remove("seconds").is_some_and(|s| s.as_f64().is_some_and(|s| s >= 0.0)));
        assert!(e.remove("cached").is_some_and(|c| c.is_boolean()));
        assert!(e.remove("warnings").is_some_and(|w| w.is_array()));
    }
    c
}

/// A bank's bytes with the wall-clock timings of its solve zeroed.
fn bank_without_timings(path: &Path) -> Vec<u8> {
    let mut bank = modal_bank::ModeBank::load(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    bank.info.assemble_s = 0.0;
    bank.info.factor_s = 0.0;
    bank.info.solve_s = 0.0;
    bank.to_bytes().unwrap()
}

#[test]
fn three_parallel_shards_on_one_cache_equal_the_unsharded_run() {
    let dir = temp_dir();
    let d = dir.path();
    manifest(d, 12);
    let shards: Vec<Child> = (0..3)
        .map(|i| {
            let shard = format!("{i}/3");
            let args = ["precompute-batch", "library.toml", "--out", "sharded", "--shard", &shard];
            command(d, &args, &[])
                .args(["--cache-dir", "shared-cache", "--json"])
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    let mut per_shard = Vec::new();
    for child in shards {
        let run = Run::from(child.wait_with_output().unwrap()).ok();
        per_shard.push(run.json());
    }
    // Every asset ran in exactly one shard.
    let mut seen = BTreeSet::new();
    for (i, summary) in per_shard.iter().enumerate() {
        assert_eq!(summary["shard"]["index"], i);
        assert_eq!(summary["failed"], 0);
        for e in entries(summary) {
            assert!(seen.insert(e["path"].as_str().unwrap().to_string()), "{e} in two shards");
        }
        assert!(d.join(format!("sharded/catalogue-shard-{i}-of-3.json")).is_file());
    }
    assert_eq!(seen.len(), 12);

    let merged =
        modal(d, &["catalogue", "merge", "sharded", "-o", "sharded/catalogue.json", "--json"], &[]).ok();
    assert_eq!(merged.json()["assets"], 12);
    assert_eq!(merged.json()["complete"], true);
    let sharded = load(&d.join("sharded/catalogue.json"));

    // The unsharded run on a fresh cache solves everything again.
    let whole = modal(
        d,
        &["precompute-batch", "library.toml", "--out", "whole", "--cache-dir", "fresh-cache", "--json"],
        &[],
    )
    .ok()
    .json();
    assert_eq!((whole["computed"].as_u64(), whole["cached"].as_u64()), (Some(12), Some(0)));
    let unsharded = load(&d.join("whole/catalogue.json"));
    assert_eq!(results(&sharded), results(&unsharded));
    assert_eq!(unsharded["complete"], true);
    // Options reached the assets: glass, steel and aluminium boxes of one size differ.
    let f1: BTreeSet<String> =
        entries(&unsharded).iter().map(|e| e["first_frequency_hz"].to_string()).collect();
    assert_eq!(f1.len(), 12);
    for e in entries(&unsharded) {
        assert_eq!(e["status"], "ok");
        assert_eq!(e["modes"], 4);
        // Mass and size, for a library's check that each file was read in its unit.
        let i: f64 = e["path"].as_str().unwrap()[10..12].parse().unwrap();
        let size = [0.12 + 0.01 * i, 0.06, 0.04];
        let diagonal = size.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((e["size_m"].as_f64().unwrap() / diagonal - 1.0).abs() < 1e-9, "{e}");
        let density = e["mass_kg"].as_f64().unwrap() / size.iter().product::<f64>();
        assert!([7850.0, 2600.0, 2700.0].iter().any(|d| (density / d - 1.0).abs() < 1e-9), "{e}");
        assert!(e["warnings"].to_string().contains("no error estimate"), "{e}");
        assert!(!e["warnings"].to_string().contains("--scale"), "{e}");
        let bank = e["bank"].as_str().unwrap();
        let (a, b) = (d.join("sharded").join(bank), d.join("whole").join(bank));
        // Bit for bit apart from the wall-clock timings recorded in the bank.
        assert_eq!(bank_without_timings(&a), bank_without_timings(&b), "{bank}");
    }

    // Unsharded on the shared cache: every bank is a cache hit, byte-identical.
    let again = modal(
        d,
        &["precompute-batch", "library.toml", "--out", "again", "--cache-dir", "shared-cache", "--json"],
        &[],
    )
    .ok()
    .json();
    assert_eq!((again["computed"].as_u64(), again["cached"].as_u64()), (Some(0), Some(12)));
    assert_eq!(results(&load(&d.join("again/catalogue.json"))), results(&unsharded));
    for e in entries(&unsharded) {
        let bank = e["bank"].as_str().unwrap();
        let (a, b) = (d.join("sharded").join(bank), d.join("again").join(bank));
        assert_eq!(std::fs::read(a).unwrap(), std::fs::read(b).unwrap(), "{bank}");
    }
}

#[test]
fn a_killed_run_resumes_without_redoing_finished_assets() {
    let dir = temp_dir();
    let d = dir.path();
    // Boxes of ≈ 5000 DOF (≈ 0.3 s each), so the kill lands half-way.
    manifest_of(d, 8, "0.007");
    let args = ["precompute-batch", "library.toml", "--out", "out", "--cache-dir", "cache", "--jobs", "1"];
    let mut child = command(d, &args, &[]).stdout(Stdio::null()).stderr(Stdio::null()).spawn().unwrap();
    let start = Instant::now();
    let first_bank = || count_banks(&d.join("out")) > 0;
    while !first_bank() {
        assert!(child.try_wait().unwrap().is_none() || first_bank(), "the batch ended without a bank");
        assert!(start.elapsed() < Duration::from_secs(300), "no bank after 300 s");
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let finished = banks(&d.join("out"));
    assert!(!finished.is_empty() && finished.len() < 8, "killed after {} of 8 assets", finished.len());
    // The killed run's catalogue is readable and honest about what is missing.
    let partial = load(&d.join("out/catalogue.json"));
    assert_eq!(partial["complete"], partial["pending"].as_array().unwrap().is_empty());
    assert!(entries(&partial).len() <= finished.len());

    let rerun = modal(d, &[&args[..], &["--json"]].concat(), &[]).ok().json();
    assert_eq!(rerun["ok"], 8);
    for e in entries(&rerun) {
        let bank = e["bank"].as_str().unwrap().to_string();
        if finished.contains(&bank) {
            assert_eq!(e["cached"], true, "{bank} was finished before the kill but solved again");
        }
    }
    let computed = rerun["computed"].as_u64().unwrap() as usize;
    assert!(
        computed >= 1 && computed <= 8 - finished.len(),
        "{computed} solved, {} were finished",
        finished.len()
    );
    assert_eq!(load(&d.join("out/catalogue.json"))["complete"], true);
}

fn banks(dir: &Path) -> BTreeSet<String> {
    let props = dir.join("props");
    std::fs::read_dir(props)
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.ends_with(".bank") && !n.starts_with('.'))
                .map(|n| format!("props/{n}"))
                .collect()
        })
        .unwrap_or_default()
}

fn count_banks(dir: &Path) -> usize {
    banks(dir).len()
}

#[test]
fn a_corrupt_asset_is_reported_while_the_others_complete() {
    let dir = temp_dir();
    let d = dir.path();
    manifest(d, 3);
    std::fs::write(d.join("props/corrupt.msh"), "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\ngarbage\n")
        .unwrap();
    let mut text = std::fs::read_to_string(d.join("library.toml")).unwrap();
    text.push_str("\n[[assets]]\npath = \"props/missing.msh\"\n");
    std::fs::write(d.join("library.toml"), text).unwrap();
    let run = modal(
        d,
        &["precompute-batch", "library.toml", "--out", "out", "--cache-dir", "cache", "--json"],
        &[],
    )
    .fails_with("2 of 5 assets failed");
    let summary = run.json();
    assert_eq!((summary["ok"].as_u64(), summary["failed"].as_u64()), (Some(3), Some(2)));
    let catalogue = load(&d.join("out/catalogue.json"));
    assert_eq!(catalogue["complete"], true);
    for e in entries(&catalogue) {
        let path = e["path"].as_str().unwrap();
        if path.contains("corrupt") || path.contains("missing") {
            let status = e["status"].as_str().unwrap();
            assert!(status != "ok" && !status.is_empty());
            if path.contains("missing") {
                assert!(status.contains("missing.msh"), "{status}");
            }
            assert!(e["bank"].is_null() && e["modes"] == 0 && e["first_frequency_hz"].is_null());
        } else {
            assert_eq!(e["status"], "ok", "{e}");
            assert!(d.join("out").join(e["bank"].as_str().unwrap()).is_file());
        }
    }
    // The human table names the failure too.
    let table = modal(d, &["precompute-batch", "library.toml", "--out", "out", "--cache-dir", "cache"], &[]);
    assert!(table.stdout.contains("props/corrupt.msh") && table.stdout.contains("3 ok (3 reused), 2 failed"));
    assert!(table.stderr.contains("warning: props/missing.msh failed"), "{}", table.stderr);
    // Failed entries keep their bank's name (`id`), so a catalogue with failures merges whole.
    assert!(entries(&catalogue).iter().all(|e| e["id"].as_str().is_some_and(|id| id.ends_with(".bank"))));
    let merged = modal(d, &["catalogue", "merge", "out", "-o", "merged/catalogue.json", "--json"], &[]).ok();
    assert_eq!(
        (merged.json()["assets"].as_u64(), merged.json()["complete"].as_bool()),
        (Some(5), Some(true))
    );
    // A directory in the way of a bank fails that asset alone, before its solve.
    std::fs::create_dir_all(d.join("blocked/props/box_00.bank")).unwrap();
    let blocked =
        modal(d, &["precompute-batch", "library.toml", "--out", "blocked", "--cache-dir", "cache"], &[]);
    assert!(blocked.stderr.contains("a directory of that name is in the way"), "{}", blocked.stderr);
    assert!(blocked.stdout.contains("3 failed"), "{}", blocked.stdout);
}

#[test]
fn the_scheduler_environment_selects_the_shard() {
    let dir = temp_dir();
    let d = dir.path();
    manifest(d, 6);
    let base = ["precompute-batch", "library.toml", "--cache-dir", "cache", "--json"];
    let by_flag = |i: usize| {
        let shard = format!("{i}/3");
        let out = format!("flag{i}");
        let run = modal(d, &[&base[..], &["--out", &out, "--shard", &shard]].concat(), &[]).ok();
        paths(&run.json())
    };
    let slurm = modal(
        d,
        &[&base[..], &["--out", "slurm"]].concat(),
        &[("SLURM_ARRAY_TASK_ID", "2"), ("SLURM_ARRAY_TASK_MIN", "1"), ("SLURM_ARRAY_TASK_COUNT", "3")],
    )
    .ok();
    assert_eq!(slurm.json()["shard"]["index"], 1);
    assert_eq!(paths(&slurm.json()), by_flag(1));
    assert!(d.join("slurm/catalogue-shard-1-of-3.json").is_file());

    let k8s = modal(
        d,
        &[&base[..], &["--out", "k8s"]].concat(),
        &[("JOB_COMPLETION_INDEX", "2"), ("MODAL_SHARD_COUNT", "3")],
    )
    .ok();
    assert_eq!(paths(&k8s.json()), by_flag(2));
    assert!(d.join("k8s/catalogue-shard-2-of-3.json").is_file());
    let flag_count = modal(
        d,
        &[&base[..], &["--out", "k8s2", "--shard-count", "3"]].concat(),
        &[("JOB_COMPLETION_INDEX", "0")],
    )
    .ok();
    assert_eq!(paths(&flag_count.json()), by_flag(0));

    modal(d, &[&base[..], &["--out", "x"]].concat(), &[("JOB_COMPLETION_INDEX", "0")])
        .fails_with("--shard-count");
    modal(d, &[&base[..], &["--out", "x", "--shard", "3/3"]].concat(), &[]).fails_with("out of range");
    // Without any selection: the whole manifest.
    let whole = modal(d, &[&base[..], &["--out", "whole"]].concat(), &[]).ok();
    let all: BTreeSet<String> = (0..3).flat_map(by_flag).collect();
    assert_eq!(paths(&whole.json()), all);
    assert_eq!(all.len(), 6);
}

fn paths(summary: &Value) -> BTreeSet<String> {
    entries(summary).iter().map(|e| e["path"].as_str().unwrap().to_string()).collect()
}

#[test]
fn a_torn_cache_entry_is_detected_and_redone() {
    let dir = temp_dir();
    let d = dir.path();
    manifest(d, 2);
    let args = ["precompute-batch", "library.toml", "--cache-dir", "cache", "--json"];
    let first = modal(d, &[&args[..], &["--out", "one"]].concat(), &[]).ok().json();
    let victim = &entries(&first)[0];
    let entry = d.join("cache").join(format!("{}.bank", victim["hash"].as_str().unwrap()));
    let bytes = std::fs::read(&entry).unwrap();
    std::fs::write(&entry, &bytes[..bytes.len() / 2]).unwrap();
    let second = modal(d, &[&args[..], &["--out", "two"]].concat(), &[]).ok();
    assert!(second.stderr.contains("damaged cache entry"), "{}", second.stderr);
    let json = second.json();
    let cached: Vec<bool> = entries(&json).iter().map(|e| e["cached"].as_bool().unwrap()).collect();
    assert_eq!(cached, [false, true], "only the torn entry is solved again");
    // The entry was rewritten whole, and the recomputed bank equals the first.
    assert!(modal_bank::ModeBank::load(&entry).is_ok());
    let bank = victim["bank"].as_str().unwrap();
    assert_eq!(
        bank_without_timings(&d.join("one").join(bank)),
        bank_without_timings(&d.join("two").join(bank))
    );
}

#[test]
fn manifest_and_merge_mistakes_are_one_clear_line() {
    let dir = temp_dir();
    let d = dir.path();
    std::fs::write(d.join("typo.toml"), "[[assets]]\npath = \"a.msh\"\nmatrial = \"steel\"\n").unwrap();
    modal(d, &["precompute-batch", "typo.toml", "--out", "out"], &[]).fails_with("matrial");
    modal(d, &["precompute-batch", "absent.toml", "--out", "out"], &[]).fails_with("absent.toml");
    std::fs::create_dir_all(d.join("empty")).unwrap();
    modal(d, &["catalogue", "merge", "empty", "-o", "c.json"], &[]).fails_with("catalogue");
    // A missing shard makes the merge incomplete: refused, or written with --partial.
    manifest(d, 2);
    modal(
        d,
        &["precompute-batch", "library.toml", "--out", "out", "--shard", "0/2", "--cache-dir", "c"],
        &[],
    )
    .ok();
    modal(d, &["catalogue", "merge", "out", "-o", "all.json"], &[]).fails_with("shard 1 of 2");
    // The same when the shard catalogues are named as files (a shell glob).
    let shard_file = "out/catalogue-shard-0-of-2.json";
    modal(d, &["catalogue", "merge", shard_file, "-o", "all.json"], &[]).fails_with("shard 1 of 2");
    let partial = modal(d, &["catalogue", "merge", "out", "-o", "all.json", "--partial", "--json"], &[]).ok();
    assert_eq!(partial.json()["complete"], false);
    assert_eq!(load(&d.join("all.json"))["complete"], false);
    // Shards of two runs (another material here; another file list on a node that
    // saw fewer files) are not one library: their merge is refused.
    let glass = std::fs::read_to_string(d.join("library.toml")).unwrap().replace("steel", "glass");
    std::fs::write(d.join("glass.toml"), glass).unwrap();
    let args = ["precompute-batch", "glass.toml", "--out", "out", "--shard", "1/2", "--cache-dir", "c"];
    modal(d, &args, &[]).ok();
    modal(d, &["catalogue", "merge", "out", "-o", "mixed.json"], &[]).fails_with("another library");
    // A library that resolves to nothing (a mount missing on this node) is an error,
    // not a complete empty catalogue on every shard.
    std::fs::write(d.join("nothing.toml"), "[[globs]]\npattern = \"absent/*.obj\"\nmaterial = \"steel\"\n")
        .unwrap();
    modal(d, &["precompute-batch", "nothing.toml", "--out", "none"], &[]).fails_with("resolves to no asset");
    // A shard count without an index would run the whole library on every pod.
    let count_only = [("MODAL_SHARD_COUNT", "8")];
    modal(d, &["precompute-batch", "library.toml", "--out", "all"], &count_only)
        .fails_with("needs a shard index");
    // A cache "directory" that is a file is one error, not a damaged entry per asset.
    std::fs::write(d.join("not-a-dir"), b"").unwrap();
    let args = ["precompute-batch", "library.toml", "--out", "filecache", "--cache-dir", "not-a-dir"];
    modal(d, &args, &[]).fails_with("not a directory");
    assert!(!d.join("filecache").exists());
    // The memory guard's variable applies to a batch as to precompute.
    let args = ["precompute-batch", "library.toml", "--out", "tight", "--cache-dir", "c2"];
    modal(d, &args, &[("MODAL_MEMORY_LIMIT_GB", "banana")]).fails_with("MODAL_MEMORY_LIMIT_GB");
    let tight = modal(d, &[&args[..], &["--json"]].concat(), &[("MODAL_MEMORY_LIMIT_GB", "0.000001")]);
    assert_eq!(tight.code, Some(1), "{}", tight.stderr);
    let tight = tight.json();
    assert!(!entries(&tight).is_empty());
    for entry in entries(&tight) {
        let status = entry["status"].as_str().unwrap();
        assert!(status.contains("memory"), "{entry}");
        // The advice names the manifest's keys, not precompute's flags.
        assert!(status.contains("order = 1") && !status.contains("--"), "{status}");
    }
    // The --jobs solves that run at once share the limit: a limit one solve fits
    // in alone is too small for two at a time (measured: the two boxes of this
    // library need between 0.5 and 1 MB each; 1 MB solves them one by one, and
    // refuses them two by two, 0.5 MB each).
    let shared = |jobs: &str| {
        let args = [
            "precompute-batch",
            "library.toml",
            "--out",
            "shared",
            "--no-cache",
            "--force",
            "-j",
            jobs,
            "--json",
        ];
        let run = modal(d, &args, &[("MODAL_MEMORY_LIMIT_GB", "0.001")]);
        run.json()["failed"].as_u64().unwrap()
    };
    assert_eq!(shared("1"), 0);
    assert_eq!(shared("2"), 2, "both boxes refused at 0.5 MB each");
}

/// Banks of surface meshes carry the per-mode error estimate like `modal precompute`'s
/// (issue 14), unless the manifest turns it off with `accuracy = "off"`.
#[test]
fn surface_assets_get_the_error_estimate_unless_the_manifest_turns_it_off() {
    let dir = temp_dir();
    let sphere = modal_tetra::shapes::icosphere(0.05, 2);
    std::fs::create_dir_all(dir.path().join("props")).unwrap();
    for name in ["estimated", "plain"] {
        let file = std::fs::File::create(dir.path().join(format!("props/{name}.obj"))).unwrap();
        modal_tetra::write_obj(&sphere, file).unwrap();
    }
    let text = "[defaults]\nmaterial = \"steel\"\nmodes = 4\ncell = 0.02\n\n\
                [[assets]]\npath = \"props/estimated.obj\"\n\n\
                [[assets]]\npath = \"props/plain.obj\"\naccuracy = \"off\"\n";
    std::fs::write(dir.path().join("library.toml"), text).unwrap();
    modal(dir.path(), &["precompute-batch", "library.toml", "--out", "out", "--cache-dir", "cache"], &[])
        .ok();
    let estimate = |name: &str| {
        let bank = modal_bank::ModeBank::load(dir.path().join(format!("out/props/{name}.bank"))).unwrap();
        (bank.mode_count(), bank.info.error_estimate_pct)
    };
    let (modes, estimated) = estimate("estimated");
    assert_eq!(estimated.len(), modes, "one estimate per mode");
    assert!(estimated.iter().all(|e| e.is_some_and(|e| e > 0.0)), "{estimated:?}");
    let (_, plain) = estimate("plain");
    assert!(plain.is_empty(), "accuracy = \"off\": no estimate, got {plain:?}");
}

/// `transfer_max_freq` stores each audible mode's acoustic transfer in the
/// bank, the same table `modal radiation --max-freq F --store` writes for
/// that bank; a rerun reuses it, a changed frequency solves it again, and
/// `transfer_max_freq = 0` on an asset turns the `[defaults]` off.
#[test]
fn a_manifest_can_bake_each_audible_modes_transfer_into_its_bank() {
    let dir = temp_dir();
    let d = dir.path();
    boxes(d, 2, "0.03");
    let write = |top: &str| {
        let text = format!(
            "[defaults]\nmaterial = \"steel\"\norder = 1\nmodes = 4\nmax_freq = 200000\ntransfer_max_freq = {top}\n\n\
             [[assets]]\npath = \"props/box_00.msh\"\n\n\
             [[assets]]\npath = \"props/box_01.msh\"\ntransfer_max_freq = 0\n"
        );
        std::fs::write(d.join("library.toml"), text).unwrap();
    };
    let args = ["precompute-batch", "library.toml", "--out", "out", "--cache-dir", "cache", "--json"];
    let transfer = |summary: &Value| -> Vec<(u64, bool)> {
        entries(summary)
            .iter()
            .map(|e| (e["transfer_modes"].as_u64().unwrap(), e["cached"] == true))
            .collect()
    };
    let stored = |name: &str| modal_bank::ModeBank::load_with_radiation(d.join(name)).unwrap();

    write("20000");
    let first = modal(d, &args, &[]).ok().json();
    let (bank, table) = stored("out/props/box_00.bank");
    let audible: Vec<usize> = (0..bank.mode_count()).filter(|&i| bank.frequencies_hz[i] <= 20000.0).collect();
    assert!(!audible.is_empty() && audible.len() < bank.mode_count(), "{:?}", bank.frequencies_hz);
    let table = table.expect("box_00 stores its transfer");
    assert_eq!(table.modes.iter().map(|m| m.mode).collect::<Vec<_>>(), audible);
    assert_eq!(transfer(&first), [(audible.len() as u64, false), (0, false)]);
    assert!(stored("out/props/box_01.bank").1.is_none(), "transfer_max_freq = 0 stores none");

    // The same table as `modal radiation --store` of the bank.
    modal(d, &["radiation", "out/props/box_00.bank", "--max-freq", "20000", "--store", "cli.bank"], &[]).ok();
    let via_cli = stored("cli.bank").1.expect("the CLI stores a table");
    assert_eq!(via_cli, table, "the batch's table differs from `modal radiation --store`");

    // A rerun reuses both banks; a new frequency solves box_00's transfer again.
    assert_eq!(transfer(&modal(d, &args, &[]).ok().json()), [(audible.len() as u64, true), (0, true)]);
    let lower = 0.5 * (bank.frequencies_hz[0] + bank.frequencies_hz[1]);
    let below = bank.frequencies_hz.iter().filter(|&&f| f <= lower).count() as u64;
    write(&format!("{lower}"));
    assert_eq!(transfer(&modal(d, &args, &[]).ok().json()), [(below, false), (0, true)]);

    write("-1");
    modal(d, &["precompute-batch", "library.toml", "--out", "out"], &[]).fails_with("transfer_max_freq");
}
