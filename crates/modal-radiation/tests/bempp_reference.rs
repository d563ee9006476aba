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
//! The committed data (`tests/data/`): `bar8.bank`, the demo's steel bar
//! (`modal mesh box --size 0.3,0.02,0.012 --h 0.006 --order 2 -o bar.msh`,
//! `modal precompute bar.msh -o bar8.bank --material steel --modes 8
//! --no-cache`), and `bar8_bempp.json`, written by
//! `/work/venvs/h15x/bin/python tools/rad_ref.py crates/modal-radiation/tests/data/bar8.bank
//! --sphere-points 16,2 --refine R [--mode I …] -o OUT.json` (16 points at 2
//! bounding radii about the centre of mass), each mode at the `refine` its
//! entry records: 0 (corner triangles) for modes 0–4, 6, 7 and 1 (each
//! quadratic triangle split in four) for mode 5, where the corner triangles
//! were 12 dB off at a point 28 dB below the mode's loudest (the refined
//! reference agrees with ours there within 0.4 dB). For mode 0 the two
//! resolutions differ by 0.1 dB median.

use std::path::{Path, PathBuf};

use faer::c64;
use modal_bank::ModeBank;
use modal_radiation::{radiate_modes, RadiationOptions};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// A reference file: points and, per mode, complex pressures.
struct Reference {
    points: Vec<[f64; 3]>,
    modes: Vec<(usize, f64, Vec<c64>)>,
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
        .map(|m| {
            let p = m["pressure_pa"].as_array().unwrap().iter().map(|z| c64::new(num(&z[0]), num(&z[1])));
            (m["index"].as_u64().unwrap() as usize, num(&m["frequency_hz"]), p.collect())
        })
        .collect();
    Reference { points, modes }
}

/// Level errors [dB] per counted mode, and the modes left out as more than
/// `within_db` below the loudest.
fn level_errors(
    reference: &Reference,
    ours: &[Vec<c64>],
    within_db: f64,
) -> (Vec<(usize, Vec<f64>)>, Vec<usize>) {
    let mean_square = |p: &[c64]| p.iter().map(|z| z.norm_sqr()).sum::<f64>() / p.len() as f64;
    let loudest = reference.modes.iter().map(|m| mean_square(&m.2)).fold(0.0, f64::max);
    let (mut counted, mut left_out) = (Vec::new(), Vec::new());
    for ((index, _, want), got) in reference.modes.iter().zip(ours) {
        if 10.0 * (mean_square(want) / loudest).log10() < -within_db {
            left_out.push(*index);
            continue;
        }
        let top = want.iter().map(|z| z.norm()).fold(0.0, f64::max);
        let errs = want
            .iter()
            .zip(got)
            .filter(|(w, _)| 20.0 * (w.norm() / top).log10() >= -within_db)
            .map(|(w, g)| 20.0 * (g.norm() / w.norm()).log10())
            .collect();
        counted.push((*index, errs));
    }
    (counted, left_out)
}

fn median_max(errs: &[(usize, Vec<f64>)]) -> (f64, f64) {
    let mut all: Vec<f64> = errs.iter().flat_map(|(_, e)| e.iter().map(|x| x.abs())).collect();
    all.sort_by(f64::total_cmp);
    (all[all.len() / 2], all[all.len() - 1])
}

/// Our pressures at the reference's points, mode by mode in its order.
fn ours(bank: &ModeBank, reference: &Reference) -> Vec<Vec<c64>> {
    let modes: Vec<usize> = reference.modes.iter().map(|m| m.0).collect();
    let results =
        radiate_modes(bank, &modes, &RadiationOptions::default(), &mut |p| eprintln!("{p}")).unwrap();
    modes
        .iter()
        .map(|&i| {
            let r = results.iter().find(|r| r.mode == i).unwrap();
            reference.points.iter().map(|&x| r.pressure_at(x).unwrap()).collect()
        })
        .collect()
}

#[test]
fn demo_bar_modes_agree_with_the_bempp_reference() {
    let bank = ModeBank::load(data("bar8.bank")).unwrap();
    let reference = read_reference(&data("bar8_bempp.json"));
    // The points are ≥ 2 bounding radii from the centre of mass.
    let c = bank.mass.center_of_mass_m;
    let dist = |p: [f64; 3]| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt();
    let bounding = bank.surface.positions.iter().map(|&p| dist(p)).fold(0.0, f64::max);
    assert!(reference.points.iter().all(|&p| dist(p) >= 2.0 * bounding * (1.0 - 1e-9)));
    for (i, f, _) in &reference.modes {
        assert_eq!(*f, bank.frequencies_hz[*i], "the reference was computed on this bank");
    }
    let got = ours(&bank, &reference);
    let (errs, left_out) = level_errors(&reference, &got, 40.0);
    for (i, e) in &errs {
        let (md, mx) = median_max(&[(*i, e.clone())]);
        eprintln!("mode {i}: median {md:.3} dB, max {mx:.3} dB over {} points", e.len());
    }
    let (median, max) = median_max(&errs);
    eprintln!(
        "all counted modes: median {median:.3} dB, max {max:.3} dB; left out (> 40 dB down): {left_out:?}"
    );
    assert!(errs.len() >= 6, "at least six modes counted: {left_out:?} left out");
    assert!(median <= 1.0 && max <= 3.0, "median {median:.3} dB, max {max:.3} dB");
}

/// Re-runs the reference (needs the Python packages of `tools/rad_ref.py`;
/// interpreter from `$MODAL_RAD_REF_PYTHON`, default
/// `/work/venvs/h15x/bin/python`) and checks it reproduces the committed
/// file, each mode at its recorded `refine`:
/// `cargo test -p modal-radiation --test bempp_reference -- --ignored`
/// (about 30 min on 2 loaded cores: bempp's JIT compile and 8 dense solves).
#[test]
#[ignore = "needs bempp-cl (Python); about 30 min"]
fn the_committed_reference_is_what_rad_ref_computes() {
    let python = std::env::var("MODAL_RAD_REF_PYTHON").unwrap_or("/work/venvs/h15x/bin/python".into());
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools/rad_ref.py");
    let text = std::fs::read_to_string(data("bar8_bempp.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let committed = read_reference(&data("bar8_bempp.json"));
    for refine in [0u64, 1] {
        let modes: Vec<String> = json["modes"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|m| m["refine"].as_u64() == Some(refine))
            .flat_map(|m| ["--mode".to_string(), m["index"].to_string()])
            .collect();
        let out = std::env::temp_dir().join(format!("bar8_bempp_{}_{refine}.json", std::process::id()));
        let status = std::process::Command::new(&python)
            .arg(&script)
            .arg(data("bar8.bank"))
            .args(["--sphere-points", "16,2", "--refine", &refine.to_string(), "-o"])
            .arg(&out)
            .args(&modes)
            .status()
            .unwrap();
        assert!(status.success());
        let fresh = read_reference(&out);
        let _ = std::fs::remove_file(&out);
        assert_eq!(fresh.points, committed.points);
        for a in &fresh.modes {
            let b = committed.modes.iter().find(|b| b.0 == a.0).unwrap();
            for (x, y) in a.2.iter().zip(&b.2) {
                assert!((x - y).norm() <= 1e-6 * y.norm().max(1e-30), "mode {}: {x} vs {y}", a.0);
            }
        }
    }
}
