//! Cross-check of the radiation of real FEM modes against an independent
//! boundary-element solver: `tools/rad_ref.py` (bempp-cl, Galerkin with
//! continuous linear pressure and per-triangle linear normal velocity,
//! Burton–Miller, its own singular quadrature; see the script's header),
//! against our collocation solver with its default (clustered, frequency
//! adaptive) settings.
//!
//! Acceptance (issue #15): level error `20 log10(|p| / |p_ref|)` within 1 dB
//! median and 3 dB max, for the modes within 40 dB of the object's loudest
//! mode, at points ≥ 2 bounding radii away. Points more than 40 dB below
//! their mode's loudest point (nodal directions) are left out: there the
//! level says nothing about the mode.
//!
//! The errors quoted on each test are as measured on their date. Since
//! 2026-11-29 (night) the modes below their bank's interior-resonance bound
//! are solved by the conventional equation (`Formulation::Automatic`); the
//! per-mode changes, and every bank's errors today, are in BENCHMARKS.md,
//! "The conventional equation below the interior resonances".
//!
//! The committed data (`tests/data/`), each reference written by
//! `/work/venvs/bempp/bin/python tools/rad_ref.py BANK --sphere-points 16,2
//! --refine R [--quadrature Q] [--mode I …] -o OUT.json` (16 points at 2
//! bounding radii about the centre of mass), each mode at the `refine` (and
//! `quadrature`, default 4) its entry records:
//!
//! - `bar8.bank`, the demo's steel bar (`modal mesh box --size
//!   0.3,0.02,0.012 --h 0.006 --order 2 -o bar.msh`, `modal precompute
//!   bar.msh -o bar8.bank --material steel --modes 8 --no-cache`), and
//!   `bar8_bempp.json`: refine 0 (corner triangles) for modes 0–4, 6, 7 and 1
//!   (each quadratic triangle split in four) for mode 5, where the corner
//!   triangles were 12 dB off at a point 28 dB below the mode's loudest (the
//!   refined reference agrees with ours there within 0.4 dB). For mode 0 the
//!   two resolutions differ by 0.1 dB median.
//! - `bowl60.bank`, the demo's glass bowl (a hemispherical shell of 60 mm
//!   outer radius with a 4 mm wall: thin and concave; `modal mesh bowl
//!   --radius 0.06 --thickness 0.004 --h 0.006 --order 2 -o bowl60.msh`,
//!   `modal precompute bowl60.msh -o full.bank --material glass --modes 12
//!   --no-cache`, then `rad_ref.py full.bank --mode 0 --mode 2 --mode 4
//!   --mode 6 --trim bowl60.bank`: one mode of each of the four lowest
//!   degenerate pairs, 1.1–8.1 kHz, so that a pair counts once), and
//!   `bowl60_bempp.json`, at refine 0 (3 170 P1 unknowns; refine 1 would
//!   need about 30 GB for bempp's dense matrices).
//! - `bowl30.bank`, a 30 mm bowl with the same 4 mm wall and h = 6 mm, all
//!   its 4 modes below 20 kHz (`modal mesh bowl --radius 0.03 --thickness
//!   0.004 --h 0.006 --order 2`, `modal precompute --material glass
//!   --modes 8 --no-cache`), and `bowl30_bempp.json`: one mode of each pair
//!   (4.6 and 11.4 kHz) at refine 1, where the reference is measured to be
//!   converged across the wall (docs/radiation.md, "Cross-check against
//!   bempp-cl": refine 0 to 1 moves it by ≤ 0.9 dB, quadrature order 4 to 8
//!   by ≤ 4e-5 of the pressure).
//! - `twobars.bank`, **two parts**: two parallel steel bars (150 × 20 × 12 mm
//!   and 120 × 20 × 12 mm, 10 mm apart; `twobars.obj`, 40 lines), `modal
//!   precompute twobars.obj --material steel --modes 10 --cell 0.006
//!   --accuracy off --no-cache -o twobars.bank` (2.7–13.5 kHz; each mode
//!   moves one bar, the other scatters its sound), and `twobars_bempp.json`:
//!   all 10 modes at refine 1 (5 984 flat triangles, 2 996 P1 unknowns;
//!   80 min on 2 loaded cores).
//! - `block.bank`, the demo's wooden block, whose playable modes are
//!   under-resolved on its 1 472 panels (k·h 1.7–2.2; the four-panel split
//!   of its 10 mm triangles, 7.1 mm across; the solver now splits them
//!   once more, see the test):
//!   `modal mesh box --size 0.08,0.05,0.04 --h 0.01 --order 2 -o
//!   block.msh`, `modal precompute block.msh -o full.bank --material wood
//!   --max-freq 24000 --no-cache` (the demo's band; 4 modes), then
//!   `rad_ref.py full.bank --mode 0 --mode 1 --mode 2 --trim block.bank`:
//!   the three modes the demo plays (below its 21.6 kHz synthesis cap),
//!   13.5, 15.6 and 17.2 kHz. `block_bempp.json`: all three at refine 2
//!   (5 888 flat triangles with 2.5 mm legs, 2 946 P1 unknowns: 6–8 per
//!   wavelength at 17.2 kHz; 11 min on 2 loaded cores). Not converged as far as the others
//!   (`rad_ref.py --compare`): refine 1 to 2 moves it by 0.35 dB median,
//!   2.57 dB max (mode 0 at a point 28 dB below its loudest) over the 46
//!   counted mode-points, each mode's median 0.45 / 0.32 / 0.28 dB; refine
//!   0 to 1 moved it 3–5 times as much (second order), the same way: louder
//!   at most points, towards our levels. Quadrature order 4 to 8 (refine 1,
//!   the 17.2 kHz mode): ≤ 0.005 dB.
//! - `ring.bank`, a steel **ring** (a torus of radii 40 and 6 mm: vertices
//!   `((R + r cos w) cos u, (R + r cos w) sin u, r sin w)` at `u = 2πi/96`,
//!   `w = 2πj/16`, each quad `(i, j), (i+1, j), (i+1, j+1), (i, j+1)` split
//!   along its `(i, j)–(i+1, j+1)` diagonal, written as `ring.obj`; `modal
//!   mesh tet ring.obj -o ring.msh` (6 104 tets), `modal precompute ring.msh
//!   --material steel --no-cache -o ring.bank`: 15 modes, 3.7–19.1 kHz; a
//!   shape none of the solver's settings were chosen on), and
//!   `ring_bempp.json`: modes 0, 4 and 8 (3.7, 10.1 and 14.3 kHz; the last
//!   32 dB below the loudest, with a strongly directional field) at refine 1
//!   (8 800 flat triangles, 4 400 P1 unknowns; 42 min on 2 loaded cores).

use std::path::{Path, PathBuf};

use faer::c64;
use modal_bank::ModeBank;
use modal_radiation::{radiate_modes, RadiationOptions};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// One mode of a reference file: its index in the bank, frequency [Hz] and
/// complex pressures at the file's points.
struct RefMode {
    index: usize,
    frequency_hz: f64,
    pressure: Vec<c64>,
}

/// A reference file: points and, per mode, complex pressures.
struct Reference {
    points: Vec<[f64; 3]>,
    modes: Vec<RefMode>,
}

fn read_reference(path: &Path) -> Reference {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let num = |v: &serde_json::Value| v.as_f64().unwrap();
    let points =
        json["points"].as_array().unwrap().iter().map(|p| [num(&p[0]), num(&p[1]), num(&p[2])]).collect();
    let modes = json["modes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| RefMode {
            index: m["index"].as_u64().unwrap() as usize,
            frequency_hz: num(&m["frequency_hz"]),
            pressure: m["pressure_pa"]
                .as_array()
                .unwrap()
                .iter()
                .map(|z| c64::new(num(&z[0]), num(&z[1])))
                .collect(),
        })
        .collect();
    Reference { points, modes }
}

/// Per counted mode: its index and, per point, the reference's level there
/// relative to the mode's loudest point [dB] and our level error there [dB].
type ModeErrors = Vec<(usize, Vec<(f64, f64)>)>;

/// Level errors of `ours` (pressures per mode index, at the reference's
/// points) for each counted mode we solved, and the reference modes left
/// out as more than `within_db` below the loudest. Which modes count is
/// decided on the whole reference, so a subset solved by us is judged
/// against the same loudest mode.
fn level_errors(
    reference: &Reference,
    ours: &[(usize, Vec<c64>)],
    within_db: f64,
) -> (ModeErrors, Vec<usize>) {
    let mean_square = |p: &[c64]| p.iter().map(|z| z.norm_sqr()).sum::<f64>() / p.len() as f64;
    let loudest = reference.modes.iter().map(|m| mean_square(&m.pressure)).fold(0.0, f64::max);
    let (mut counted, mut left_out) = (Vec::new(), Vec::new());
    for m in &reference.modes {
        if 10.0 * (mean_square(&m.pressure) / loudest).log10() < -within_db {
            left_out.push(m.index);
            continue;
        }
        let Some((_, got)) = ours.iter().find(|(i, _)| *i == m.index) else { continue };
        let top = m.pressure.iter().map(|z| z.norm()).fold(0.0, f64::max);
        let errs = m
            .pressure
            .iter()
            .zip(got)
            .map(|(w, g)| (20.0 * (w.norm() / top).log10(), 20.0 * (g.norm() / w.norm()).log10()))
            .collect();
        counted.push((m.index, errs));
    }
    (counted, left_out)
}

/// Median and max of |error| [dB] over the points within `within_db` of
/// their mode's loudest point (nodal directions say nothing about a level),
/// and how many points that is.
fn median_max(errs: &[(usize, Vec<(f64, f64)>)], within_db: f64) -> (f64, f64, usize) {
    let mut all: Vec<f64> = errs
        .iter()
        .flat_map(|(_, e)| e.iter().filter(|(l, _)| *l >= -within_db).map(|(_, x)| x.abs()))
        .collect();
    all.sort_by(f64::total_cmp);
    (all[all.len() / 2], all[all.len() - 1], all.len())
}

/// Our pressures at the reference's points for the given modes, and the
/// modes whose solve the solver flagged under-resolved
/// (`Progress::under_resolved`: its clusters had to grow past `κ` to fit the
/// dense-size cap, or its panels are coarse for the frequency).
fn ours(bank: &ModeBank, reference: &Reference, modes: &[usize]) -> (Vec<(usize, Vec<c64>)>, Vec<usize>) {
    let mut flagged = Vec::new();
    let results = radiate_modes(bank, modes, &RadiationOptions::default(), &mut |p| {
        eprintln!("{p}");
        if p.under_resolved {
            flagged.extend_from_slice(&p.modes);
        }
    })
    .unwrap();
    let pressures = modes
        .iter()
        .map(|&i| {
            let r = results.iter().find(|r| r.mode == i).unwrap();
            (i, reference.points.iter().map(|&x| r.pressure_at(x).unwrap()).collect())
        })
        .collect();
    (pressures, flagged)
}

/// Cross-checks a committed bank against its committed reference, for the
/// modes `only` (all of the reference's if `None`): checks that the
/// reference belongs to the bank and its points are ≥ 2 bounding radii
/// away, prints the errors per mode and returns the counted modes' errors,
/// the modes left out (> 40 dB below the loudest) and the modes our solver
/// flagged under-resolved.
fn cross_check(
    bank_file: &str,
    reference_file: &str,
    only: Option<&[usize]>,
) -> (ModeErrors, Vec<usize>, Vec<usize>) {
    let bank = ModeBank::load(data(bank_file)).unwrap();
    let reference = read_reference(&data(reference_file));
    let c = bank.mass.center_of_mass_m;
    let dist = |p: [f64; 3]| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt();
    let bounding = bank.surface.positions.iter().map(|&p| dist(p)).fold(0.0, f64::max);
    assert!(reference.points.iter().all(|&p| dist(p) >= 2.0 * bounding * (1.0 - 1e-9)));
    for m in &reference.modes {
        assert_eq!(m.frequency_hz, bank.frequencies_hz[m.index], "the reference was computed on this bank");
    }
    let modes: Vec<usize> = match only {
        Some(only) => only.to_vec(),
        None => reference.modes.iter().map(|m| m.index).collect(),
    };
    let (got, flagged) = ours(&bank, &reference, &modes);
    let (errs, left_out) = level_errors(&reference, &got, 40.0);
    for (i, e) in &errs {
        let (md, mx, n) = median_max(&[(*i, e.clone())], 40.0);
        let note = if flagged.contains(i) { " (flagged under-resolved)" } else { "" };
        eprintln!("{bank_file} mode {i}: median {md:.3} dB, max {mx:.3} dB over {n} points{note}");
    }
    let (median, max, n) = median_max(&errs, 40.0);
    eprintln!(
        "{bank_file}, all counted modes: median {median:.3} dB, max {max:.3} dB over {n} mode-points; \
         left out (> 40 dB down): {left_out:?}; flagged under-resolved: {flagged:?}"
    );
    (errs, left_out, flagged)
}

/// The criterion: median ≤ 1 dB and max ≤ 3 dB over the counted
/// modes' points within 40 dB of their mode's loudest.
fn assert_criterion(errs: &[(usize, Vec<(f64, f64)>)]) {
    let (median, max, n) = median_max(errs, 40.0);
    assert!(median <= 1.0 && max <= 3.0, "median {median:.3} dB, max {max:.3} dB over {n} mode-points");
}

/// [`cross_check`] of `modes` (all when `None`), exactly `counted` of them
/// within 40 dB of the loudest mode, and [`assert_criterion`] on them.
fn assert_modes_agree(bank_file: &str, reference_file: &str, modes: Option<&[usize]>, counted: usize) {
    let (errs, left_out, _) = cross_check(bank_file, reference_file, modes);
    assert!(errs.len() == counted, "{counted} modes counted, {} were: {left_out:?} left out", errs.len());
    assert_criterion(&errs);
}

#[test]
fn demo_bar_modes_agree_with_the_bempp_reference() {
    let (errs, left_out, _) = cross_check("bar8.bank", "bar8_bempp.json", None);
    assert!(errs.len() >= 6, "at least six modes counted: {left_out:?} left out");
    assert_criterion(&errs);
}

/// The bowl's lowest pair (1143 Hz), in the default suite (a few seconds).
#[test]
fn demo_bowl_lowest_pair_agrees_with_the_bempp_reference() {
    assert_modes_agree("bowl60.bank", "bowl60_bempp.json", Some(&[0]), 1);
}

/// The bowl's four lowest pairs, 1.1–8.1 kHz (about 1.5 min in the
/// release profile on 2 loaded cores):
/// `cargo test -p modal-radiation --test bempp_reference -- --ignored demo_bowl_modes --nocapture`.
///
/// Measured 2026-11-26 at the default `κ` = 0.3: median 0.322 dB, max
/// 1.773 dB (the 3.0 kHz pair at a point 24.8 dB below its loudest) over 61
/// mode-points; per pair max 0.757 / 1.773 / 1.027 / 1.261 dB. The 5.3 and
/// 8.1 kHz pairs ask for more unknowns than the dense-size cap
/// (`MAX_DENSE_PANELS`), so their clusters are grown until they fit and the
/// solve says "under-resolved"; at a point 33 dB down their error depends
/// on where the grown clusters' boundaries fall (with the cap lifted to
/// 14 000: 1.08 / 1.26 dB). At the former `κ` = 0.5: max 3.98 dB.
#[test]
#[ignore = "about 3 min: the bowl's four lowest pairs"]
fn demo_bowl_modes_agree_with_the_bempp_reference() {
    assert_modes_agree("bowl60.bank", "bowl60_bempp.json", None, 4);
}

/// The small bowl against a reference converged across its 4 mm wall.
/// Measured 2026-11-26 at the default `κ` = 0.3: median 0.036 / 0.093 dB,
/// max 0.600 / 1.173 dB at 4.6 / 11.4 kHz. At the former `κ` = 0.5 the
/// 11.4 kHz mode was 4.01 dB off at a point 36 dB below its loudest; one
/// unknown per panel (`--full-resolution`) gives 1.99 dB there: that much is
/// the panels' own error (k·h = 0.81), the rest was the clusters'.
#[test]
fn small_bowl_agrees_with_a_converged_bempp_reference() {
    assert_modes_agree("bowl30.bank", "bowl30_bempp.json", None, 2);
}

/// A two-part object (two parallel bars 10 mm apart), its two lowest modes
/// in the default suite.
#[test]
fn two_bars_lowest_modes_agree_with_the_bempp_reference() {
    assert_modes_agree("twobars.bank", "twobars_bempp.json", Some(&[0, 1]), 2);
}

/// Every mode of the two-part object, 2.7–13.5 kHz (about 1.5 min in the
/// release profile):
/// `cargo test -p modal-radiation --test bempp_reference -- --ignored two_bars_every --nocapture`.
///
/// Measured 2026-11-26 at the default `κ` = 0.3 (this test, release
/// profile, 85 s): all 10 modes within 15 dB of the loudest, median
/// 0.327 dB, max 1.941 dB (mode 2, 4.4 kHz) over 160 mode-points; per mode max 0.35–0.70 dB except 1.94 (mode 2) and 1.00
/// (mode 5). Modes 6–9 (≥ 10.8 kHz) are flagged under-resolved (the
/// bank's 6 mm cell gives panels with k·h > 1) and still within 1 dB.
#[test]
#[ignore = "about 1.5 min: ten modes of a two-part object"]
fn two_bars_every_mode_agrees_with_the_bempp_reference() {
    assert_modes_agree("twobars.bank", "twobars_bempp.json", None, 10);
}

/// The demo's wooden block, the three modes it plays (13.5–17.2 kHz),
/// under-resolved on the bank's 1 472 panels (k·h 1.7–2.2). Since the fine
/// panels are too coarse and few, the solver splits each in four
/// (`modes::Panels::finer`, 5 888 panels, k·h 0.8–1.1; the two upper modes
/// are still flagged).
///
/// Measured 2026-11-26 (this test, 21 s in the test profile): median
/// 0.386 dB, max 1.717 dB over 46 mode-points; per mode median 0.536 /
/// 0.461 / 0.254 dB, max 1.498 / 1.531 / 1.717 dB. On the 1 472 panels
/// (before the finer level) it was median 0.727, max 2.914 dB (per mode max
/// 2.290 / 2.914 / 2.774 dB at points 28, 33 and 27 dB below their mode's
/// loudest, ours louder by about 1 dB at 13.5 kHz): within the criterion
/// by 0.09 dB only. The reference's own refine 1 to 2 change (header)
/// goes towards our levels; extrapolated as second order,
/// `p₂ + (p₂ − p₁)/3`, the coarse solve's max was 2.75 dB. The same block
/// meshed at h = 5 mm (`--h 0.005`, frequencies within 0.2 %) was within
/// 0.360 dB median, 2.101 dB max of this reference: the panels' coarseness
/// was most of the error, which the finer level removes.
#[test]
fn demo_block_under_resolved_modes_agree_with_the_bempp_reference() {
    assert_modes_agree("block.bank", "block_bempp.json", None, 3);
}

/// Re-runs the references (needs the Python packages of `tools/rad_ref.py`;
/// interpreter from `$MODAL_RAD_REF_PYTHON`, default
/// `/work/venvs/bempp/bin/python`) and checks each reproduces its committed
/// file, each mode at its recorded `refine` and `quadrature`:
/// `cargo test -p modal-radiation --test bempp_reference -- --ignored`
/// (about 3 h on 2 loaded cores: bempp's JIT compile and the dense
/// solves, 14 min for the bar at refine 0, 13 min for its mode 5 at refine
/// 1, 5–10 min per mode of either bowl, 80 min for the two bars, 11 min
/// for the block).
/// A ring (a torus), an unseen shape for the solver's settings.
/// Measured 2026-11-29 (this test, 3.5 s): median 0.089 dB, max 1.456 dB
/// over 46 mode-points; per mode max 0.065 / 0.560 / 1.456 dB (modes 4 and 8
/// flagged under-resolved: clusters grown to κ = 0.38 and 2.79 to fit).
#[test]
fn a_ring_agrees_with_the_bempp_reference() {
    assert_modes_agree("ring.bank", "ring_bempp.json", None, 3);
}

#[test]
#[ignore = "needs bempp-cl (Python); about 2 h"]
fn the_committed_references_are_what_rad_ref_computes() {
    let python = std::env::var("MODAL_RAD_REF_PYTHON").unwrap_or("/work/venvs/bempp/bin/python".into());
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools/rad_ref.py");
    let objects = [
        ("bar8.bank", "bar8_bempp.json"),
        ("bowl60.bank", "bowl60_bempp.json"),
        ("bowl30.bank", "bowl30_bempp.json"),
        ("twobars.bank", "twobars_bempp.json"),
        ("block.bank", "block_bempp.json"),
        ("ring.bank", "ring_bempp.json"),
    ];
    for (bank, file) in objects {
        let text = std::fs::read_to_string(data(file)).unwrap();
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        let committed = read_reference(&data(file));
        // Each mode's settings: its own entry's, else the file's.
        let setting = |m: &serde_json::Value, key: &str| m[key].as_u64().or(json[key].as_u64()).unwrap_or(4);
        let mut runs: Vec<(u64, u64)> = json["modes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| (setting(m, "refine"), setting(m, "quadrature")))
            .collect();
        runs.sort();
        runs.dedup();
        for (refine, quadrature) in runs {
            let modes: Vec<String> = json["modes"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|m| (setting(m, "refine"), setting(m, "quadrature")) == (refine, quadrature))
                .flat_map(|m| ["--mode".to_string(), m["index"].to_string()])
                .collect();
            let out = std::env::temp_dir()
                .join(format!("{file}_{}_{refine}_{quadrature}.json", std::process::id()));
            let status = std::process::Command::new(&python)
                .arg(&script)
                .arg(data(bank))
                .args(["--sphere-points", "16,2", "--refine", &refine.to_string()])
                .args(["--quadrature", &quadrature.to_string(), "-o"])
                .arg(&out)
                .args(&modes)
                .status()
                .unwrap();
            assert!(status.success());
            let fresh = read_reference(&out);
            let _ = std::fs::remove_file(&out);
            assert_eq!(fresh.points, committed.points);
            for a in &fresh.modes {
                let b = committed.modes.iter().find(|b| b.index == a.index).unwrap();
                for (x, y) in a.pressure.iter().zip(&b.pressure) {
                    assert!(
                        (x - y).norm() <= 1e-6 * y.norm().max(1e-30),
                        "{file} mode {}: {x} vs {y}",
                        a.index
                    );
                }
            }
        }
    }
}
