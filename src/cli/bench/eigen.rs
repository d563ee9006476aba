//! `modal bench eigen`: the whole `modal precompute` against scipy's `eigsh` (ARPACK +
//! SuperLU shift-invert) on the same matrices, side by side in one run.
//!
//! For each requested size a TET10 box (0.2 × 0.15 × 0.1 m, steel E = 200 GPa, ν = 0.3,
//! ρ = 7850 kg/m³) is generated with the element size whose DOF count is closest to the
//! target. Then, each as a child process of this executable so that wall time and peak RSS
//! (`wait4`'s `ru_maxrss`) are the child's own:
//! 1. `modal precompute MESH --no-cache --json --modes N --max-freq 1e6` (the band is wide
//!    open so the `--modes` cap decides), per-phase timings from its JSON;
//! 2. `modal export-matrices`, then `python scipy_eigs.py K.mtx M.mtx --modes N+rigid`,
//!    whose JSON holds the solve-only time `eigsh_s` and the frequencies.
//!
//! The ratio is our whole precompute wall time over scipy's solve-only time (the issue's
//! target is ≤ 0.1). Frequencies are compared mode by mode (rigid modes dropped). Timings
//! are reported, never asserted. Temporary files live in a directory removed at the end.

use crate::cli::output::{print_json, warn};
use anyhow::{bail, Context, Result};
use clap::Args;
use modal_mesh::generate::{generate, Shape};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// Box edge lengths of the benchmark meshes (m).
const BOX_SIZE: [f64; 3] = [0.2, 0.15, 0.1];
/// Steel: Young's modulus (Pa), Poisson ratio, density (kg/m³).
const STEEL: [&str; 3] = ["200e9", "0.3", "7850"];
/// Upper band edge (Hz) high enough that `--modes` caps the band.
const MAX_FREQ_HZ: &str = "1e6";

/// Options of `modal bench eigen`.
#[derive(Debug, Args)]
pub struct EigenBenchArgs {
    /// Target DOF counts of the TET10 box meshes, comma separated (the closest box is used).
    #[arg(long, value_delimiter = ',', default_value = "30000,100000")]
    dofs: Vec<usize>,
    /// Elastic modes to compute (scipy is asked for this many plus the rigid modes).
    #[arg(long, default_value_t = 50)]
    modes: usize,
    /// Python interpreter with numpy and scipy (default: $MODAL_PYTHON, else python3).
    #[arg(long)]
    python: Option<PathBuf>,
    /// scipy baseline script (default: ../shared/tools/scipy_eigs.py next to the repository).
    #[arg(long)]
    scipy_script: Option<PathBuf>,
    /// Run only our side (for machines without Python/scipy).
    #[arg(long)]
    skip_scipy: bool,
    /// Worker threads passed to `modal precompute --threads`.
    #[arg(long)]
    threads: Option<usize>,
    /// Print the results as JSON instead of a markdown table.
    #[arg(long)]
    json: bool,
}

/// One child process run: its stdout, wall time and peak resident memory.
struct ChildRun {
    stdout: String,
    wall_s: f64,
    peak_rss_mb: f64,
}

/// Results for one mesh size.
struct Row {
    dofs: usize,
    h: f64,
    ours: Value,
    ours_wall_s: f64,
    ours_rss_mb: f64,
    scipy: Option<ScipyRun>,
}

/// The scipy side of one row.
struct ScipyRun {
    eigsh_s: f64,
    wall_s: f64,
    peak_rss_mb: f64,
    max_freq_rel_diff: f64,
    max_residual: f64,
}

/// Runs the benchmark.
pub fn run(args: EigenBenchArgs) -> Result<()> {
    if args.dofs.is_empty() || args.dofs.iter().any(|&d| !(300..=5_000_000).contains(&d)) {
        bail!("--dofs: each target must be between 300 and 5000000");
    }
    if args.modes == 0 {
        bail!("--modes must be at least 1");
    }
    let exe = std::env::current_exe().context("cannot locate the modal executable")?;
    let scipy = if args.skip_scipy { None } else { Some(find_scipy(&args)?) };
    let tmp = TempDir::new()?;
    let mut rows = Vec::new();
    for &target in &args.dofs {
        rows.push(bench_size(&args, &exe, scipy.as_ref(), &tmp, target)?);
    }
    if args.json {
        print_json(&Value::Array(rows.iter().map(row_json).collect()))
    } else {
        print_table(&rows, args.modes);
        Ok(())
    }
}

/// Python interpreter and script, checked to import scipy.
struct Scipy {
    python: PathBuf,
    script: PathBuf,
}

fn find_scipy(args: &EigenBenchArgs) -> Result<Scipy> {
    let python = args
        .python
        .clone()
        .or_else(|| std::env::var_os("MODAL_PYTHON").map(PathBuf::from))
        .unwrap_or_else(|| PathBuf::from("python3"));
    let script = match &args.scipy_script {
        Some(s) => s.clone(),
        None => default_script().context(
            "scipy_eigs.py not found next to the repository; pass --scipy-script PATH or --skip-scipy",
        )?,
    };
    if !script.is_file() {
        bail!("scipy script {} does not exist; pass --scipy-script PATH or --skip-scipy", script.display());
    }
    let ok = Command::new(&python)
        .args(["-c", "import numpy, scipy.sparse.linalg"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    if !ok {
        bail!(
            "{} cannot import numpy and scipy; pass --python PATH (or set MODAL_PYTHON) or use --skip-scipy",
            python.display()
        );
    }
    Ok(Scipy { python, script })
}

/// `../shared/tools/scipy_eigs.py` next to the repository or the working directory.
fn default_script() -> Option<PathBuf> {
    let rel = Path::new("..").join("shared").join("tools").join("scipy_eigs.py");
    [Path::new(env!("CARGO_MANIFEST_DIR")).join(&rel), rel].into_iter().find(|p| p.is_file())
}

/// DOF count of the TET10 box for element size `h` (cells per axis as in `modal_mesh`'s
/// generator: ⌈size/h⌉; quadratic Kuhn boxes have (2n+1) nodes per axis).
fn box_dofs(h: f64) -> usize {
    BOX_SIZE.iter().map(|s| 2 * ((s / h).ceil().max(1.0) as usize) + 1).product::<usize>() * 3
}

/// Element size whose box DOF count is closest to `target`.
fn h_for_dofs(target: usize) -> f64 {
    let mut best = (usize::MAX, 0.05);
    let mut h = 0.1;
    while h > 1e-4 {
        let d = box_dofs(h);
        let err = d.abs_diff(target);
        if err < best.0 {
            best = (err, h);
        }
        if d > 2 * target {
            break;
        }
        h *= 0.995;
    }
    best.1
}

fn bench_size(
    args: &EigenBenchArgs,
    exe: &Path,
    scipy: Option<&Scipy>,
    tmp: &TempDir,
    target: usize,
) -> Result<Row> {
    let h = h_for_dofs(target);
    let mesh = generate(&Shape::Box { size: BOX_SIZE }, h, 2).context("box mesh")?;
    let dofs = 3 * mesh.nodes.len();
    let mesh_path = tmp.path.join(format!("box{dofs}.msh"));
    modal_mesh::write_msh41_file(&mesh_path, &mesh).context("cannot write the benchmark mesh")?;
    drop(mesh);
    let material = ["--youngs", STEEL[0], "--poisson", STEEL[1], "--density", STEEL[2]];
    let bank = tmp.path.join(format!("box{dofs}.bank"));
    let modes = args.modes.to_string();
    let mut cmd = Command::new(exe);
    cmd.arg("precompute").arg(&mesh_path).arg("-o").arg(&bank).args(material);
    cmd.args(["--modes", &modes, "--max-freq", MAX_FREQ_HZ, "--no-cache", "--json"]);
    if let Some(t) = args.threads {
        cmd.args(["--threads", &t.to_string()]);
    }
    let run = run_child(cmd, &tmp.path.join("precompute.err"), "modal precompute")?;
    let ours: Value = serde_json::from_str(&run.stdout).context("modal precompute printed invalid JSON")?;
    let _ = std::fs::remove_file(&bank);
    let scipy = match scipy {
        Some(s) => Some(run_scipy(s, exe, tmp, &mesh_path, &material, &ours, args.modes)?),
        None => None,
    };
    Ok(Row { dofs, h, ours, ours_wall_s: run.wall_s, ours_rss_mb: run.peak_rss_mb, scipy })
}

fn run_scipy(
    s: &Scipy,
    exe: &Path,
    tmp: &TempDir,
    mesh: &Path,
    material: &[&str],
    ours: &Value,
    modes: usize,
) -> Result<ScipyRun> {
    let dir = tmp.path.join("matrices");
    let mut cmd = Command::new(exe);
    cmd.arg("export-matrices").arg(mesh).arg("--out").arg(&dir).args(material).arg("--json");
    run_child(cmd, &tmp.path.join("export.err"), "modal export-matrices")?;
    let rigid = ours["rigid_modes_removed"].as_u64().unwrap_or(0) as usize;
    let mut cmd = Command::new(&s.python);
    cmd.arg(&s.script).arg(dir.join("K.mtx")).arg(dir.join("M.mtx"));
    cmd.args(["--modes", &(modes + rigid).to_string()]);
    let run = run_child(cmd, &tmp.path.join("scipy.err"), "scipy_eigs.py")?;
    let _ = std::fs::remove_dir_all(&dir);
    let out: Value = serde_json::from_str(&run.stdout).context("scipy_eigs.py printed invalid JSON")?;
    let theirs: Vec<f64> = floats(&out["frequencies_hz"]).into_iter().skip(rigid).collect();
    let mine: Vec<f64> = ours["modes"]
        .as_array()
        .map(|m| m.iter().filter_map(|x| x["frequency_hz"].as_f64()).collect())
        .unwrap_or_default();
    let max_freq_rel_diff =
        mine.iter().zip(&theirs).map(|(a, b)| (a - b).abs() / b.abs().max(1e-300)).fold(0.0, f64::max);
    Ok(ScipyRun {
        eigsh_s: out["eigsh_s"].as_f64().context("scipy_eigs.py JSON has no eigsh_s")?,
        wall_s: run.wall_s,
        peak_rss_mb: run.peak_rss_mb,
        max_freq_rel_diff,
        max_residual: out["max_relative_residual"].as_f64().unwrap_or(f64::NAN),
    })
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().map(|a| a.iter().filter_map(Value::as_f64).collect()).unwrap_or_default()
}

/// Runs `cmd` with stdout captured and stderr to `err_file`; measures wall time from here
/// and the child's peak RSS through `wait4`.
fn run_child(mut cmd: Command, err_file: &Path, what: &str) -> Result<ChildRun> {
    let err = std::fs::File::create(err_file).context("cannot create a temporary file")?;
    cmd.stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::from(err));
    let start = Instant::now();
    let mut child = cmd.spawn().with_context(|| format!("cannot start {what}"))?;
    let mut stdout = String::new();
    if let Some(mut out) = child.stdout.take() {
        std::io::Read::read_to_string(&mut out, &mut stdout)
            .with_context(|| format!("reading {what} output"))?;
    }
    let (status, rss_kb) = wait_with_rusage(child.id())?;
    let wall_s = start.elapsed().as_secs_f64();
    if status != 0 {
        let msg = std::fs::read_to_string(err_file).unwrap_or_default();
        let last = msg.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("no message");
        bail!("{what} failed (exit status {status}): {last}");
    }
    Ok(ChildRun { stdout, wall_s, peak_rss_mb: rss_kb as f64 / 1024.0 })
}

/// Waits for `pid`; returns (exit status, or 128 + signal; peak RSS in KiB).
fn wait_with_rusage(pid: u32) -> Result<(i32, i64)> {
    let pid = libc::pid_t::try_from(pid).context("child pid out of range")?;
    let mut status: libc::c_int = 0;
    // SAFETY: rusage is plain old data, zero is a valid bit pattern; wait4 writes into
    // `status` and `usage`, both valid for the duration of the call. The child was spawned
    // by us and is not waited for by std (its `Child` handle is dropped unwaited).
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let r = loop {
        let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
        if r == -1 && std::io::Error::last_os_error().kind() == std::io::ErrorKind::Interrupted {
            continue;
        }
        break r;
    };
    if r != pid {
        bail!("wait4 failed: {}", std::io::Error::last_os_error());
    }
    let code = if libc::WIFEXITED(status) { libc::WEXITSTATUS(status) } else { 128 + libc::WTERMSIG(status) };
    Ok((code, usage.ru_maxrss))
}

/// A temporary directory removed on drop.
struct TempDir {
    path: PathBuf,
}

impl TempDir {
    fn new() -> Result<Self> {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.subsec_nanos())
            .unwrap_or(0);
        let path = std::env::temp_dir().join(format!("modal-bench-eigen-{}-{nanos}", std::process::id()));
        std::fs::create_dir_all(&path).with_context(|| format!("cannot create {}", path.display()))?;
        Ok(Self { path })
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        if let Err(e) = std::fs::remove_dir_all(&self.path) {
            warn(&format!("cannot remove temporary directory {}: {e}", self.path.display()));
        }
    }
}

/// Our side's summary numbers from the precompute JSON.
struct Ours {
    modes: usize,
    assemble: f64,
    factor: f64,
    solve: f64,
    max_residual: f64,
    expected: u64,
    found: u64,
}

fn ours(v: &Value) -> Ours {
    let modes = v["modes"].as_array().map(Vec::as_slice).unwrap_or(&[]);
    let t = &v["timings_s"];
    Ours {
        modes: modes.len(),
        assemble: t["assemble"].as_f64().unwrap_or(f64::NAN),
        factor: t["factor"].as_f64().unwrap_or(f64::NAN),
        solve: t["solve"].as_f64().unwrap_or(f64::NAN),
        max_residual: modes.iter().filter_map(|m| m["residual"].as_f64()).fold(0.0, f64::max),
        expected: v["inertia_check"]["expected"].as_u64().unwrap_or(0),
        found: v["inertia_check"]["found"].as_u64().unwrap_or(0),
    }
}

fn row_json(r: &Row) -> Value {
    let o = ours(&r.ours);
    let mut v = json!({
        "dofs": r.dofs,
        "h_m": r.h,
        "modes": o.modes,
        "timings_s": r.ours["timings_s"],
        "precompute_wall_s": r.ours_wall_s,
        "precompute_peak_rss_mb": r.ours_rss_mb,
        "max_residual": o.max_residual,
        "inertia_check": r.ours["inertia_check"],
    });
    if let Some(s) = &r.scipy {
        v["scipy"] = json!({
            "eigsh_s": s.eigsh_s,
            "wall_s": s.wall_s,
            "peak_rss_mb": s.peak_rss_mb,
            "max_residual_incl_rigid": s.max_residual,
        });
        v["ratio"] = json!(r.ours_wall_s / s.eigsh_s);
        v["max_freq_rel_diff"] = json!(s.max_freq_rel_diff);
    }
    v
}

fn print_table(rows: &[Row], modes: usize) {
    println!("TET10 steel box {:?} m, {modes} elastic modes, band 20 Hz .. {MAX_FREQ_HZ} Hz\n", BOX_SIZE);
    println!("| DOF | modes | assemble s | factor s | solve s | precompute wall s | our peak MB | scipy eigsh s | scipy peak MB | ratio | max residual | inertia exp/found | max freq diff |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for r in rows {
        let o = ours(&r.ours);
        let (eigsh, srss, ratio, diff) = match &r.scipy {
            Some(s) => (
                format!("{:.2}", s.eigsh_s),
                format!("{:.0}", s.peak_rss_mb),
                format!("{:.3}", r.ours_wall_s / s.eigsh_s),
                format!("{:.1e}", s.max_freq_rel_diff),
            ),
            None => ("-".into(), "-".into(), "-".into(), "-".into()),
        };
        println!(
            "| {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.0} | {eigsh} | {srss} | {ratio} | {:.1e} | {}/{} | {diff} |",
            r.dofs,
            o.modes,
            o.assemble,
            o.factor,
            o.solve,
            r.ours_wall_s,
            r.ours_rss_mb,
            o.max_residual,
            o.expected,
            o.found
        );
    }
}
