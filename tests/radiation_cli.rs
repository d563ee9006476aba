//! `modal radiation`: the JSON contract, errors, and the physics on a real
//! FEM sphere bank — spheroidal modes radiate as one multipole of degree l,
//! `p = iρ₀c Σ_m c_lm h_l(kr)/h_l'(ka) Y_l^m` (c_lm the projection of the
//! mode's normal velocity on Y_l^m), torsional modes (tangential motion)
//! radiate far less (≥ 35 dB on this coarse mesh, where the FEM modes
//! themselves move normally; ≥ 60 dB for exactly tangential fields, and on a
//! fine FEM sphere in an ignored test).

mod common;

use common::{modal, modal_within_memory, temp_dir};
use modal_bank::ModeBank;
use modal_radiation::c64;
use modal_radiation::modes::{boundary_mesh, normal_velocity};
use modal_radiation::special::{lm_index, spherical_hankel, spherical_harmonics};
use modal_radiation::Air;

const RADIUS: f64 = 0.05;
/// A soft, light solid so the lowest sphere modes sit near 1–2 kHz (ka ≈ 1–2).
const SOFT: [&str; 6] = ["--youngs", "1e8", "--density", "1000", "--poisson", "0.3"];

/// The FEM element size of the test's sphere bank [m].
const H: &str = "0.015";

/// Meshes and solves the sphere bank of element size `h` [m] in `dir` (sphere.bank).
fn sphere_bank(dir: &std::path::Path, h: &str) {
    let r = RADIUS.to_string();
    modal(dir, &["mesh", "sphere", "--radius", &r, "--h", h, "--order", "2", "-o", "sphere.msh"]).ok();
    let mut args = vec!["precompute", "sphere.msh", "-o", "sphere.bank", "--modes", "16", "--no-cache"];
    args.extend(SOFT);
    modal(dir, &args).ok();
}

fn points(r: f64) -> Vec<[f64; 3]> {
    (0..10)
        .map(|i| {
            let th = 0.2 + 0.3 * i as f64;
            let ph = 0.9 * i as f64;
            [r * th.sin() * ph.cos(), r * th.sin() * ph.sin(), r * th.cos()]
        })
        .collect()
}

fn point_args(pts: &[[f64; 3]]) -> Vec<String> {
    pts.iter().flat_map(|p| ["--point".to_string(), format!("{},{},{}", p[0], p[1], p[2])]).collect()
}

#[test]
fn sphere_modes_radiate_as_single_multipoles_and_torsional_modes_are_silent() {
    // The issue asks for ≥ 60 dB. Measured on this coarse mesh (h = 15 mm,
    // 3 elements per radius, fitted node normals): T2 −54.0 dB, T3
    // −39.8 dB worst. The FEM modes of this coarse sphere really move
    // normally (T3 −40.0 dB by harmonic projection with the curved
    // surface's own normals, tools/sphere_leak.py); the radiation side is
    // guarded at 60 dB by `exactly_tangential_fields_…`, and a finer FEM
    // sphere by the ignored test below.
    sphere_modes_and_torsional_leak(H, -35.0);
}

/// The issue's 60 dB on an FEM sphere fine enough for its torsional modes
/// to be tangential to that level: h = 6 mm, 214 347 DOF. Measured
/// (2026-11-26, dev profile, load ≈ 8): T2 −82.6 dB, T3 −65.1 dB worst, as
/// the harmonic projection of the FEM modes' own normal velocity
/// (tools/sphere_leak.py: −82.6, −65.1 dB), so the radiation adds no leak.
/// Heavy: precompute 3 min 29 s and 8.2 GB peak memory, radiation 12 s (the
/// whole test 240 s, passed 2026-11-26). Run with
/// `cargo test --test radiation_cli fine_fem_sphere -- --ignored --nocapture`.
#[test]
#[ignore]
fn torsional_modes_of_a_fine_fem_sphere_are_60_db_below_the_spheroidal_ones() {
    sphere_modes_and_torsional_leak("0.006", -60.0);
}

/// Each spheroidal mode of the FEM sphere of element size `h` radiates as
/// one multipole (within 0.5 dB), and every torsional mode's power is
/// below `guard_db` re the quietest spheroidal mode.
fn sphere_modes_and_torsional_leak(h: &str, guard_db: f64) {
    let dir = temp_dir();
    sphere_bank(dir.path(), h);
    let (spheroidal, torsional) = radiate_as_single_multipoles(dir.path(), "sphere.bank");
    assert!(
        !spheroidal.is_empty() && !torsional.is_empty(),
        "spheroidal {spheroidal:?}, torsional {torsional:?}"
    );
    let quietest_spheroidal = spheroidal.iter().map(|s| s.2).fold(f64::INFINITY, f64::min);
    eprintln!("spheroidal (mode, Hz, W): {spheroidal:?}\ntorsional: {torsional:?}");
    for (i, f, p) in &torsional {
        let db = 10.0 * (p / quietest_spheroidal).log10();
        assert!(db < guard_db, "torsional mode {i} ({f:.0} Hz) only {db:.1} dB below the spheroidal ones");
    }
    // A degenerate family (one degree l, frequencies within 10⁻³) radiates
    // the same power whichever member: only the mesh breaks the symmetry.
    // Measured on the 15 mm sphere: l = 2 quintuplet 0.024 dB, l = 3 triplet
    // 0.015 dB apart; Burton–Miller on these constant panels, before the
    // conventional equation took the frequencies below the interior
    // resonances, spread them 0.168 dB (docs/radiation.md).
    for a in &spheroidal {
        for b in spheroidal.iter().filter(|b| (b.1 / a.1 - 1.0).abs() < 1e-3) {
            let db = 10.0 * (a.2 / b.2).log10();
            assert!(
                db.abs() < 0.05,
                "degenerate modes {} and {} ({:.0} Hz): {db:.3} dB apart",
                a.0,
                b.0,
                a.1
            );
        }
    }
}

#[test]
fn a_hollow_ball_radiates_from_its_outside_only_as_single_multipoles() {
    // A sealed 3 mm shell of radius RADIUS, its inner wall facing the cavity.
    // The cavity's wall is no surface of the bank: its air never reaches the
    // listener, and kept, the solve would also solve the cavity's resonances.
    let dir = temp_dir();
    let mut ball = modal_tetra::shapes::icosphere(RADIUS, 4);
    let cavity = modal_tetra::shapes::icosphere(RADIUS - 0.003, 4);
    let offset = ball.vertices.len();
    ball.vertices.extend(cavity.vertices);
    ball.triangles.extend(cavity.triangles.iter().map(|t| [t[0] + offset, t[2] + offset, t[1] + offset]));
    ball.parts = vec![("ball".into(), 0..ball.triangles.len())];
    modal_tetra::write_obj(&ball, std::fs::File::create(dir.path().join("ball.obj")).unwrap()).unwrap();
    let mut args =
        vec!["precompute", "ball.obj", "-o", "ball.bank", "--modes", "6", "--no-cache", "--accuracy", "off"];
    args.extend(SOFT);
    modal(dir.path(), &args).ok();
    let bank = ModeBank::load(dir.path().join("ball.bank")).unwrap();
    let outside = 4.0 * std::f64::consts::PI * RADIUS * RADIUS;
    let area = boundary_mesh(&bank).unwrap().area();
    assert!((area / outside - 1.0).abs() < 0.01, "surface {area} m² against the outside's {outside} m²");
    let (spheroidal, _) = radiate_as_single_multipoles(dir.path(), "ball.bank");
    assert!(spheroidal.len() >= 5, "the five n = 2 modes: {spheroidal:?}");
}

/// Runs `modal radiation BANK` at [`points`] and checks each mode whose
/// normal velocity is not ≈ 0 against the single multipole of the sphere of
/// radius [`RADIUS`] its normal velocity asks for (within 0.5 dB at the points
/// within 20 dB of the loudest); returns `(mode, Hz, W)` of those
/// (spheroidal) and of the others (torsional).
#[allow(clippy::type_complexity)]
fn radiate_as_single_multipoles(
    dir: &std::path::Path,
    bank_file: &str,
) -> (Vec<(usize, f64, f64)>, Vec<(usize, f64, f64)>) {
    let pts = points(2.0 * RADIUS);
    let mut args: Vec<String> = ["radiation", bank_file, "--json"].map(String::from).to_vec();
    args.extend(point_args(&pts));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let run = modal(dir, &args).ok();
    assert!(run.stderr.contains("radiation"), "progress and timings on stderr: {}", run.stderr);
    let json = run.json();
    let modes = json["modes"].as_array().unwrap();
    assert!(!modes.is_empty());

    let bank = ModeBank::load(dir.join(bank_file)).unwrap();
    let mesh = boundary_mesh(&bank).unwrap();
    let air = Air::default();
    let (mut spheroidal, mut torsional) = (Vec::new(), Vec::new());
    for m in modes {
        let i = m["index"].as_u64().unwrap() as usize;
        let f = m["frequency_hz"].as_f64().unwrap();
        assert_eq!(f, bank.frequencies_hz[i]);
        let power = m["radiated_power_w"].as_f64().unwrap();
        let got: Vec<c64> = m["pressure_pa"]
            .as_array()
            .unwrap()
            .iter()
            .map(|z| c64::new(z[0].as_f64().unwrap(), z[1].as_f64().unwrap()))
            .collect();
        assert_eq!(got.len(), pts.len());
        // Normal-velocity share of the surface motion: ≈ 0 for torsional modes.
        let vn = normal_velocity(&bank, &mesh, i).unwrap();
        let (mut vn2, mut v2) = (0.0, 0.0);
        for (j, p) in mesh.panels.iter().enumerate() {
            vn2 += vn[j].norm_sqr() * p.area;
            let s: [f32; 3] = p
                .corners
                .map(|c| bank.shape_at(i, c))
                .iter()
                .fold([0.0; 3], |a, s| [a[0] + s[0] / 3.0, a[1] + s[1] / 3.0, a[2] + s[2] / 3.0]);
            v2 += (s[0] as f64).powi(2) * p.area
                + (s[1] as f64).powi(2) * p.area
                + (s[2] as f64).powi(2) * p.area;
        }
        if vn2 < 1e-3 * v2 {
            torsional.push((i, f, power));
            continue;
        }
        // Project v_n on Y_l^m (l ≤ 6) and find the degree.
        let order = 6;
        let mut c = vec![c64::new(0.0, 0.0); (order + 1) * (order + 1)];
        for (j, p) in mesh.panels.iter().enumerate() {
            let y = spherical_harmonics(order, p.centroid);
            let r2 = p.centroid.iter().map(|x| x * x).sum::<f64>();
            for (cl, yl) in c.iter_mut().zip(&y) {
                *cl += vn[j] * yl.conj() * (p.area / r2);
            }
        }
        let energy: Vec<f64> = (0..=order)
            .map(|l| (-(l as i64)..=l as i64).map(|m| c[lm_index(l, m)].norm_sqr()).sum())
            .collect();
        let total: f64 = energy.iter().sum();
        let l = (0..=order).max_by(|&a, &b| energy[a].total_cmp(&energy[b])).unwrap();
        assert!(energy[l] > 0.95 * total, "mode {i}: normal velocity is not one degree: {energy:?}");
        let k = 2.0 * std::f64::consts::PI * f / air.sound_speed_m_s;
        let hp = {
            let h = spherical_hankel(l + 1, k * RADIUS);
            if l == 0 {
                -h[1]
            } else {
                h[l - 1] - h[l] * ((l + 1) as f64 / (k * RADIUS))
            }
        };
        let want: Vec<c64> = pts
            .iter()
            .map(|x| {
                let r = x.iter().map(|v| v * v).sum::<f64>().sqrt();
                let h = spherical_hankel(l, k * r)[l];
                let y = spherical_harmonics(l, *x);
                let s: c64 = (-(l as i64)..=l as i64).map(|m| c[lm_index(l, m)] * y[lm_index(l, m)]).sum();
                c64::new(0.0, air.impedance()) * h / hp * s
            })
            .collect();
        let loudest = want.iter().map(|w| w.norm()).fold(0.0, f64::max);
        for (g, w) in got.iter().zip(&want) {
            if w.norm() > 0.1 * loudest {
                let db = 20.0 * (g.norm() / w.norm()).log10();
                assert!(
                    db.abs() < 0.5,
                    "mode {i} (l = {l}, {f:.0} Hz, ka = {:.2}): {db:.2} dB off",
                    k * RADIUS
                );
            }
        }
        spheroidal.push((i, f, power));
    }
    (spheroidal, torsional)
}

#[test]
fn points_inside_the_body_and_bad_air_are_clear_errors() {
    let dir = temp_dir();
    sphere_bank(dir.path(), H);
    modal(dir.path(), &["radiation", "sphere.bank", "--point", "0.01,0,0"]).fails_with("inside the body");
    modal(dir.path(), &["radiation", "sphere.bank", "--point", "1,0,0", "--sound-speed", "0"])
        .fails_with("sound speed");
    // Absurd but positive air is refused at once, not solved for minutes.
    for (flag, value) in [("--sound-speed", "1"), ("--sound-speed", "1e9"), ("--air-density", "1e200")] {
        let run = modal(dir.path(), &["radiation", "sphere.bank", "--point", "1,0,0", flag, value]);
        let run = run.fails_with("gases and liquids");
        assert!(
            !run.stderr.contains("mode(s) on"),
            "{flag} {value}: refused only after starting\n{}",
            run.stderr
        );
    }
    let bad = modal(dir.path(), &["radiation", "sphere.bank", "--point", "1,0"]);
    assert!(
        !bad.success && bad.stderr.contains("X,Y,Z") && !bad.stderr.contains("panicked"),
        "{}",
        bad.stderr
    );
    // Numbers no one types are shown as typed, not as 200 digits.
    let huge = modal(dir.path(), &["radiation", "sphere.bank", "--air-density", "1e200"]).fails_with("1e200");
    assert!(!huge.stderr.contains("00000000"), "{}", huge.stderr);
    // Clusters beyond κ = 1 cost accuracy silently (0.8 dB in power at κ = 2): refused.
    modal(dir.path(), &["radiation", "sphere.bank", "--cluster-kh", "2"]).fails_with("--cluster-kh");
    modal(dir.path(), &["radiation", "missing.bank", "--point", "1,0,0"]).fails_with("missing.bank");
    modal(dir.path(), &["radiation", "sphere.bank", "--point", "1,0,0", "--mode", "999"])
        .fails_with("does not exist");
}

/// Issue #15: a face centre and a corner of a block (its winding number is ½
/// and ⅛ there) are on the surface, for `--point` and `--listener` alike:
/// refused before any solve, nothing on stdout; moving the point as far as
/// the error line says makes it valid.
#[test]
fn issue_15_points_on_the_block_surface_are_refused_and_the_advice_works() {
    let dir = temp_dir();
    modal(
        dir.path(),
        &["mesh", "box", "--size", "0.08,0.05,0.04", "--h", "0.02", "--order", "2", "-o", "b.msh"],
    )
    .ok();
    modal(
        dir.path(),
        &["precompute", "b.msh", "-o", "b.bank", "--modes", "4", "--material", "wood", "--no-cache"],
    )
    .ok();
    // Face centre (outward −z) and corner (outward −x−y−z).
    let s3 = 1.0 / 3f64.sqrt();
    for (at, out) in [([0.04, 0.025, 0.0], [0.0, 0.0, -1.0]), ([0.0; 3], [-s3, -s3, -s3])] {
        let p = format!("{},{},{}", at[0], at[1], at[2]);
        let refused = modal(dir.path(), &["radiation", "b.bank", "--point", &p, "--json"])
            .fails_with("lies on the body's surface");
        // No result on stdout: only the error, as JSON since --json was asked.
        let only_error = serde_json::from_str::<serde_json::Value>(refused.stdout.trim())
            .is_ok_and(|j| j.get("error").is_some() && j.get("modes").is_none());
        assert!(only_error && !refused.stderr.contains("inside"), "{} / {}", refused.stdout, refused.stderr);
        assert!(!refused.stderr.contains("radiation 1/"), "refused after a solve: {}", refused.stderr);
        let heard = modal(
            dir.path(),
            &["strike", "b.bank", "--at", "0.04,0.025,0.04", "--listener", &p, "-o", "x.wav"],
        )
        .fails_with("lies on the body's surface");
        assert!(heard.stdout.is_empty() && !dir.path().join("x.wav").exists());
        // "move the point at least T m away from the surface": 1.1 T is enough.
        let t: f64 =
            refused.stderr.split("at least ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
        let x = [0, 1, 2].map(|k| at[k] + 1.1 * t * out[k]);
        let p = format!("{},{},{}", x[0], x[1], x[2]);
        let json =
            modal(dir.path(), &["radiation", "b.bank", "--point", &p, "--mode", "0", "--json"]).ok().json();
        let z = &json["modes"][0]["pressure_pa"][0];
        assert!(z[0].as_f64().unwrap().hypot(z[1].as_f64().unwrap()) > 0.0, "{json}");
        // Just inside that distance it is still on the surface.
        let x = [0, 1, 2].map(|k| at[k] + 0.9 * t * out[k]);
        let p = format!("{},{},{}", x[0], x[1], x[2]);
        modal(dir.path(), &["radiation", "b.bank", "--point", &p]).fails_with("lies on the body's surface");
    }
}

#[test]
fn pressure_scales_with_air_density_and_skips_inaudible_modes() {
    let dir = temp_dir();
    sphere_bank(dir.path(), H);
    let run = |extra: &[&str]| {
        let mut a = vec![
            "radiation",
            "sphere.bank",
            "--point",
            "0.3,0.1,0.05",
            "--mode",
            "0",
            "--mode",
            "6",
            "--json",
        ];
        a.extend(extra);
        modal(dir.path(), &a).ok().json()
    };
    let base = run(&[]);
    let dense = run(&["--air-density", "2.42"]);
    for (a, b) in base["modes"].as_array().unwrap().iter().zip(dense["modes"].as_array().unwrap()) {
        let (pa, pb) = (&a["pressure_pa"][0], &b["pressure_pa"][0]);
        for c in 0..2 {
            let (x, y) = (pa[c].as_f64().unwrap(), pb[c].as_f64().unwrap());
            assert!((y - 2.0 * x).abs() <= 1e-9 * x.abs().max(1e-30), "p ∝ ρ₀: {x} vs {y}");
        }
        let (wa, wb) = (a["radiated_power_w"].as_f64().unwrap(), b["radiated_power_w"].as_f64().unwrap());
        assert!((wb / wa - 2.0).abs() < 1e-9, "P ∝ ρ₀ at fixed velocity: {wa} vs {wb}");
    }
    // Every mode of this bank lies above 20 Hz; a 1 kHz ceiling skips the higher ones.
    let capped = run(&["--max-freq", "1000"]);
    let bank = ModeBank::load(dir.path().join("sphere.bank")).unwrap();
    let skipped: Vec<u64> =
        capped["modes_skipped"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
    for i in [0u64, 6] {
        assert_eq!(skipped.contains(&i), bank.frequencies_hz[i as usize] > 1000.0, "mode {i}");
    }
}

#[test]
fn stored_far_field_matches_the_solve_and_info_shows_power() {
    let dir = temp_dir();
    sphere_bank(dir.path(), H);
    let far = [0.2, -0.15, 0.1];
    let p = format!("{},{},{}", far[0], far[1], far[2]);
    let args = [
        "radiation",
        "sphere.bank",
        "--point",
        &p,
        "--mode",
        "5",
        "--mode",
        "10",
        "--store",
        "rad.bank",
        "--json",
    ];
    let solved = modal(dir.path(), &args).ok().json();
    let (bank, table) = ModeBank::load_with_radiation(dir.path().join("rad.bank")).unwrap();
    let table = table.expect("the stored bank has a radiation table");
    assert_eq!(bank, ModeBank::load(dir.path().join("sphere.bank")).unwrap(), "same modes");
    assert_eq!(table.modes.iter().map(|m| m.mode).collect::<Vec<_>>(), [5, 10]);
    let info = modal(dir.path(), &["info", "rad.bank", "--json"]).ok().json();
    for m in solved["modes"].as_array().unwrap() {
        let i = m["index"].as_u64().unwrap() as usize;
        let entry = table.mode(i).unwrap();
        // Stored expansion vs the boundary-element pressure at the point.
        let mp = modal_radiation::modes::stored_multipole(&table, entry);
        let z = mp.pressure_at(far);
        let want =
            c64::new(m["pressure_pa"][0][0].as_f64().unwrap(), m["pressure_pa"][0][1].as_f64().unwrap());
        assert!((z - want).norm() < 0.02 * want.norm(), "mode {i}: stored {z} vs solved {want}");
        assert_eq!(info["modes"][i]["radiated_power_w"].as_f64(), m["radiated_power_w"].as_f64());
        assert!(info["modes"][i]["radiation_efficiency"].as_f64().unwrap() > 0.0);
    }
    assert!(info["modes"][0]["radiated_power_w"].is_null(), "modes not solved stay null");
    let table_text = modal(dir.path(), &["info", "rad.bank"]).ok().stdout;
    assert!(table_text.contains("radiated W"), "{table_text}");
    // Without --point the table has no level column to leave empty.
    let no_points = modal(dir.path(), &["radiation", "rad.bank", "--mode", "5"]).ok().stdout;
    assert!(!no_points.contains("level at each point"), "{no_points}");
    // One more mode adds to the stored transfer; the others are kept bit for bit.
    modal(dir.path(), &["radiation", "rad.bank", "--mode", "7", "--store", "more.bank"]).ok();
    let (_, more) = ModeBank::load_with_radiation(dir.path().join("more.bank")).unwrap();
    let more = more.unwrap();
    assert_eq!(more.modes.iter().map(|m| m.mode).collect::<Vec<_>>(), [5, 7, 10]);
    assert_eq!(more.mode(5), table.mode(5));
    assert_eq!(more.mode(10), table.mode(10));
    // Transfers for other air do not mix with the new ones: dropped, and said.
    let other = modal(
        dir.path(),
        &["radiation", "more.bank", "--mode", "7", "--sound-speed", "340", "--store", "c.bank"],
    )
    .ok();
    assert!(other.stderr.contains("2 transfer(s) stored for other modes"), "{}", other.stderr);
    let (_, c) = ModeBank::load_with_radiation(dir.path().join("c.bank")).unwrap();
    assert_eq!(c.unwrap().modes.iter().map(|m| m.mode).collect::<Vec<_>>(), [7]);
    // Retuned to twice the size (every ka kept) the transfer is rescaled, and
    // agrees with a new solve of the retuned bank; a damping change keeps it.
    let retuned = modal(dir.path(), &["retune", "rad.bank", "--scale", "2", "-o", "big.bank"]).ok();
    assert!(retuned.stdout.contains("radiated W"), "retune shows what it wrote: {}", retuned.stdout);
    let far2 = far.map(|x| 2.0 * x);
    let p2 = format!("{},{},{}", far2[0], far2[1], far2[2]);
    let resolved = modal(
        dir.path(),
        &["radiation", "big.bank", "--point", &p2, "--mode", "5", "--mode", "10", "--json"],
    )
    .ok()
    .json();
    let (_, big) = ModeBank::load_with_radiation(dir.path().join("big.bank")).unwrap();
    let big = big.expect("a size retune keeps the transfer");
    for m in resolved["modes"].as_array().unwrap() {
        let entry = big.mode(m["index"].as_u64().unwrap() as usize).unwrap();
        let z = modal_radiation::modes::stored_multipole(&big, entry).pressure_at(far2);
        let want =
            c64::new(m["pressure_pa"][0][0].as_f64().unwrap(), m["pressure_pa"][0][1].as_f64().unwrap());
        assert!((z - want).norm() < 0.02 * want.norm(), "mode {}: rescaled {z} vs solved {want}", m["index"]);
        let power = m["radiated_power_w"].as_f64().unwrap();
        assert!((entry.power_w / power - 1.0).abs() < 0.01, "power {} vs {power}", entry.power_w);
    }
    modal(dir.path(), &["retune", "rad.bank", "--alpha", "3", "-o", "damped.bank"]).ok();
    let (_, damped) = ModeBank::load_with_radiation(dir.path().join("damped.bank")).unwrap();
    assert_eq!(damped.as_ref(), Some(&table), "a damping change keeps the transfer as it is");
    let stiffer = modal(dir.path(), &["retune", "rad.bank", "--youngs", "2e8", "-o", "stiff.bank"]).ok();
    assert!(stiffer.stderr.contains("does not carry over"), "{}", stiffer.stderr);
    assert!(ModeBank::load_with_radiation(dir.path().join("stiff.bank")).unwrap().1.is_none());
    // A store that cannot be written fails before the solve (the pre-flight's words).
    modal(dir.path(), &["radiation", "sphere.bank", "--store", "sphere.bank/x.bank"])
        .fails_with("cannot create directory sphere.bank");
    modal(dir.path(), &["radiation", "sphere.bank", "--store", "."]).fails_with("is a directory");
}

#[test]
fn strike_hears_the_listener_by_default_linearly_and_audibly() {
    let dir = temp_dir();
    sphere_bank(dir.path(), H);
    modal(dir.path(), &["radiation", "sphere.bank", "--store", "rad.bank"]).ok();
    let strike = |bank: &str, extra: &[&str], out: &str| {
        let mut a =
            vec!["strike", bank, "--at", "0.05,0,0", "--duration", "0.2", "--float", "-o", out, "--json"];
        a.extend(extra);
        modal(dir.path(), &a).ok()
    };
    let one = strike("rad.bank", &[], "one.wav").json();
    assert_eq!(one["output"]["kind"], "listener");
    assert_eq!(one["output"]["transfer"], "stored");
    // Default listener: 0.5 m off the struck point along its normal.
    let l: Vec<f64> =
        one["output"]["listener_m"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let s: Vec<f64> =
        one["strikes"][0]["surface_point"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let d = ((l[0] - s[0]).powi(2) + (l[1] - s[1]).powi(2) + (l[2] - s[2]).powi(2)).sqrt();
    assert!((d - 0.5).abs() < 1e-9, "listener {d} m from the struck point");
    let peak = one["peak"].as_f64().unwrap();
    assert!(peak > 1e-2, "audible without --normalize: peak {peak} of full scale");
    let two = strike("rad.bank", &["--impulse", "0.02"], "two.wav").json();
    assert!((two["peak"].as_f64().unwrap() / peak - 2.0).abs() < 1e-6, "linear in the impulse");
    // Without stored radiation: the estimate, with a warning; or a solve on request, equal to the stored one.
    let est = strike("sphere.bank", &[], "est.wav");
    assert!(est.stderr.contains("no radiation data"), "{}", est.stderr);
    assert_eq!(est.json()["output"]["transfer"], "estimate");
    let solved = strike("sphere.bank", &["--solve-radiation"], "solved.wav").json();
    assert_eq!(solved["output"]["transfer"], "solved");
    assert!(
        (solved["peak"].as_f64().unwrap() / peak - 1.0).abs() < 0.02,
        "solved {} vs stored {peak}",
        solved["peak"]
    );
    // --transfer-max-freq caps the solve: above every mode it is the whole
    // solve, below every mode it is the estimate, sample for sample.
    let capped =
        |hz: &str, out: &str| strike("sphere.bank", &["--solve-radiation", "--transfer-max-freq", hz], out);
    assert_eq!(capped("1e9", "all.wav").json()["peak"], solved["peak"]);
    let none = capped("1", "none.wav");
    assert!(none.stderr.contains("keep the level estimate"), "{}", none.stderr);
    assert_eq!(none.json()["peak"], est.json()["peak"]);
    assert_eq!(
        std::fs::read(dir.path().join("none.wav")).unwrap(),
        std::fs::read(dir.path().join("est.wav")).unwrap()
    );
    let bare = ["strike", "sphere.bank", "--at", "0.05,0,0", "--transfer-max-freq", "5000", "-o", "b.wav"];
    assert!(!modal(dir.path(), &bare).success, "--transfer-max-freq needs --solve-radiation");
    let mut negative = vec!["strike", "sphere.bank", "--at", "0.05,0,0", "--solve-radiation", "-o", "b.wav"];
    negative.extend(["--transfer-max-freq", "-5"]);
    modal(dir.path(), &negative).fails_with("--transfer-max-freq must be a positive frequency");
    // The contact microphone stays available; a listener inside the body is an error.
    assert_eq!(strike("rad.bank", &["--mic", "0.05,0,0"], "mic.wav").json()["output"]["kind"], "contact_mic");
    modal(dir.path(), &["strike", "rad.bank", "--at", "0.05,0,0", "--listener", "0,0,0.01", "-o", "x.wav"])
        .fails_with("inside the body");
    assert!(!dir.path().join("x.wav").exists());
}

/// RMS of a float WAV.
fn wav_rms(path: &std::path::Path) -> f64 {
    let samples: Vec<f32> =
        hound::WavReader::open(path).unwrap().into_samples().map(Result::unwrap).collect();
    (samples.iter().map(|&x| (x as f64).powi(2)).sum::<f64>() / samples.len() as f64).sqrt()
}

#[test]
fn a_sphere_struck_anywhere_sounds_the_same_along_the_strike() {
    // A sphere's spheroidal modes come in multiplets of one frequency (2l + 1
    // shapes), turned arbitrarily by the eigensolver. Struck radially at any
    // point and heard along the same radius, the addition theorem makes each
    // multiplet's sound the same, but only when the modes' transfers are
    // summed with their phases: with levels |T_i| alone the multiplet's
    // shapes add or cancel by how they happen to be turned (−12.6 dB at one
    // of these directions before strike kept the phase).
    let dir = temp_dir();
    sphere_bank(dir.path(), H);
    modal(dir.path(), &["radiation", "sphere.bank", "--store", "rad.bank"]).ok();
    let directions =
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.577, 0.577, 0.577], [0.3, -0.8, 0.52], [-0.6, 0.48, 0.64]];
    let levels: Vec<f64> = directions
        .iter()
        .enumerate()
        .map(|(k, d)| {
            let n: f64 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let at = |r: f64| d.map(|c| c / n.sqrt() * r);
            let (s, l) = (at(RADIUS), at(RADIUS + 0.5));
            let out = format!("d{k}.wav");
            let (s, l) = (format!("{},{},{}", s[0], s[1], s[2]), format!("{},{},{}", l[0], l[1], l[2]));
            let args = [
                "strike",
                "rad.bank",
                "--at",
                &s,
                "--listener",
                &l,
                "--duration",
                "0.3",
                "--float",
                "-o",
                &out,
            ];
            modal(dir.path(), &args).ok();
            20.0 * wav_rms(&dir.path().join(out)).log10()
        })
        .collect();
    let (lo, hi) = levels.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
    assert!(hi - lo < 0.5, "the level depends on where the sphere is struck: {levels:?} dB");
}

#[test]
fn strikes_default_listener_stands_back_from_a_large_body() {
    // A 0.6 m sphere: 0.5 m off its surface is inside the 1.2 m sphere a
    // stored far field is accurate beyond, so the default listener stands on it.
    let dir = temp_dir();
    modal(dir.path(), &["mesh", "sphere", "--radius", "0.6", "--h", "0.3", "-o", "big.msh"]).ok();
    modal(
        dir.path(),
        &["precompute", "big.msh", "-o", "big.bank", "--modes", "2", "--no-cache", "--material", "steel"],
    )
    .ok();
    modal(dir.path(), &["radiation", "big.bank", "--store", "rad.bank"]).ok();
    let run = modal(
        dir.path(),
        &["strike", "rad.bank", "--at", "0.6,0,0", "--duration", "0.05", "-o", "b.wav", "--json"],
    )
    .ok();
    assert!(!run.stderr.contains("inside the"), "the default is not inside the fit sphere: {}", run.stderr);
    assert_eq!(run.json()["output"]["transfer"], "stored");
    let l: Vec<f64> =
        run.json()["output"]["listener_m"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let r = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
    assert!((r - 1.2).abs() < 0.012, "listener {l:?} at {r} m from the centre, not on the fit sphere");
    // Along the struck facet's normal (a coarse sphere's facet: near radial), beyond 0.5 m.
    assert!(l[0] > 1.1 && l[0] / r > 0.95, "not off the struck point: {l:?}");
}

#[test]
fn coarse_panels_at_low_frequency_agree_with_the_full_resolution() {
    // A 10× softer sphere: its modes near 500 Hz (ka ≈ 0.5) are solved on the
    // corner triangles (a quarter of the panels) unless --full-resolution.
    let dir = temp_dir();
    let r = RADIUS.to_string();
    modal(dir.path(), &["mesh", "sphere", "--radius", &r, "--h", "0.015", "--order", "2", "-o", "s.msh"])
        .ok();
    let args = [
        "precompute",
        "s.msh",
        "-o",
        "soft.bank",
        "--modes",
        "8",
        "--no-cache",
        "--youngs",
        "1e7",
        "--density",
        "1000",
        "--poisson",
        "0.3",
    ];
    modal(dir.path(), &args).ok();
    let run = |extra: &[&str]| {
        let mut a = vec![
            "radiation",
            "soft.bank",
            "--point",
            "0.2,0.1,-0.12",
            "--mode",
            "5",
            "--mode",
            "6",
            "--json",
        ];
        a.extend(extra);
        modal(dir.path(), &a).ok()
    };
    let (coarse, fine) = (run(&[]), run(&["--full-resolution"]));
    assert!(!coarse.stderr.contains("thin wall"), "{}", coarse.stderr);
    let panels = |stderr: &str| -> usize {
        let line = stderr.lines().find(|l| l.contains(" panels,")).unwrap_or_else(|| panic!("{stderr}"));
        line.split(" on ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap()
    };
    assert_eq!(4 * panels(&coarse.stderr), panels(&fine.stderr), "{}\n{}", coarse.stderr, fine.stderr);
    let (c, f) = (coarse.json(), fine.json());
    for (a, b) in c["modes"].as_array().unwrap().iter().zip(f["modes"].as_array().unwrap()) {
        let mag = |m: &serde_json::Value| {
            m["pressure_pa"][0][0].as_f64().unwrap().hypot(m["pressure_pa"][0][1].as_f64().unwrap())
        };
        let db = 20.0 * (mag(a) / mag(b)).log10();
        assert!(db.abs() < 0.5, "mode {}: coarse vs full resolution {db:.2} dB", a["index"]);
        let (pa, pb) = (a["radiated_power_w"].as_f64().unwrap(), b["radiated_power_w"].as_f64().unwrap());
        assert!((10.0 * (pa / pb).log10()).abs() < 0.5, "power {pa} vs {pb}");
    }
    // A sphere has no crease: refining at creases leaves its panels and levels
    // as they were; the flag needs --full-resolution and at most 3 rounds.
    let creased = run(&["--full-resolution", "--refine-creases", "2"]);
    assert_eq!(panels(&creased.stderr), panels(&fine.stderr), "{}", creased.stderr);
    assert_eq!(creased.json()["modes"], f["modes"]);
    let refused = modal(dir.path(), &["radiation", "soft.bank", "--mode", "5", "--refine-creases", "1"]);
    refused.fails_with("--refine-creases needs --full-resolution");
    let mut too_many = vec!["radiation", "soft.bank", "--mode", "5", "--full-resolution"];
    too_many.extend(["--refine-creases", "4"]);
    modal(dir.path(), &too_many).fails_with("--refine-creases must be at most 3");
    // Beyond the memory guard a solve is refused with the limit, not run
    // until the machine runs out (a full-resolution solve can need GBs).
    let mut tight = vec!["radiation", "soft.bank", "--point", "0.2,0.1,-0.12", "--mode", "5", "--json"];
    tight.push("--full-resolution");
    let refused = modal_within_memory(dir.path(), &tight, "0.001").fails_with("memory limit of 0.00 GB");
    assert!(refused.stderr.contains("drop --full-resolution"), "{}", refused.stderr);
    assert!(refused.json()["error"].is_string(), "{}", refused.stdout);
}

/// Exactly tangential fields on the FEM sphere's curved surface must stay
/// silent: the radiation pipeline (smooth-surface normals of the quadratic
/// surface, panels, Burton–Miller solve, multipole power) must not itself
/// leak a torsional field into sound. `x × ∇q` is tangential to every sphere
/// about the origin for any `q`; with `q` a harmonic polynomial of degree l
/// it is the torsional pattern of degree l, and `∇q` the spheroidal one
/// (normal velocity `l q / r`). All fields have unit RMS over the surface
/// nodes. (The FEM's own torsional modes are not exactly tangential: see
/// the test above; this one isolates the radiation side.)
#[test]
fn exactly_tangential_fields_on_the_fem_sphere_radiate_far_below_spheroidal_ones() {
    // The issue's 60 dB. Measured (this test, --nocapture): T2 −63.4 dB at
    // 1600 Hz, −65.2 dB at 2400 Hz; T3 −113.9, −103.4 dB. The floor is the
    // node normals' error (fitted, src/normals.rs: 0.029° mean here; the mean
    // of the triangles' normals, 0.77°, gave T2 −46.4 / −49.4 dB); with exact
    // radial node normals the same panel sampling gives −164 dB
    // (`tools/sphere_leak.py BANK --analytic --panels`, docs/radiation.md).
    const GUARD_DB: f64 = -60.0;
    let dir = temp_dir();
    sphere_bank(dir.path(), H);
    let mut bank = ModeBank::load(dir.path().join("sphere.bank")).unwrap();
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    };
    let grad_xy = |x: [f64; 3]| [x[1], x[0], 0.0];
    let grad_xyz = |x: [f64; 3]| [x[1] * x[2], x[0] * x[2], x[0] * x[1]];
    type Field = Box<dyn Fn([f64; 3]) -> [f64; 3]>;
    let fields: Vec<(&str, Field)> = vec![
        ("T2", Box::new(move |x| cross(x, grad_xy(x)))),
        ("T3", Box::new(move |x| cross(x, grad_xyz(x)))),
        ("S2", Box::new(grad_xy)),
        ("S3", Box::new(grad_xyz)),
    ];
    let freqs = [1600.0, 2400.0];
    let nodes = bank.surface.positions.clone();
    let mut shapes = Vec::new();
    let mut names = Vec::new();
    for &f in &freqs {
        for (name, field) in &fields {
            let u: Vec<[f64; 3]> = nodes.iter().map(|&x| field(x)).collect();
            let rms =
                (u.iter().map(|v| v.iter().map(|c| c * c).sum::<f64>()).sum::<f64>() / u.len() as f64).sqrt();
            shapes.extend(u.iter().flat_map(|v| v.map(|c| (c / rms) as f32)));
            names.push((*name, f));
        }
    }
    let n = names.len();
    bank.frequencies_hz = names.iter().map(|&(_, f)| f).collect();
    bank.shapes = shapes;
    bank.damping_ratios = vec![bank.damping_ratios[0]; n];
    bank.decay_rates = vec![bank.decay_rates[0]; n];
    bank.residuals = vec![0.0; n];
    let modes: Vec<usize> = (0..n).collect();
    let results = modal_radiation::radiate_modes(
        &bank,
        &modes,
        &modal_radiation::RadiationOptions::default(),
        &mut |_| {},
    )
    .unwrap();
    let power = |i: usize| results.iter().find(|r| r.mode == i).unwrap().power_w;
    let mut levels = Vec::new();
    for (fi, &f) in freqs.iter().enumerate() {
        let base = fi * fields.len();
        let quietest_spheroidal = power(base + 2).min(power(base + 3));
        for t in 0..2 {
            let db = 10.0 * (power(base + t) / quietest_spheroidal).log10();
            eprintln!("{} at {f} Hz: {db:.1} dB re the quietest spheroidal field", names[base + t].0);
            levels.push((names[base + t].0, f, db));
        }
    }
    for (name, f, db) in levels {
        assert!(db < GUARD_DB, "{name} at {f} Hz: only {db:.1} dB below the spheroidal fields");
    }
}

/// `modal precompute --transfer-max-freq F` stores the table `modal
/// radiation BANK --max-freq F --store` writes for the same bank (every
/// audible mode up to F), `info --json` shows it, and a bad F is refused
/// before any solve.
#[test]
fn precompute_can_store_the_transfer_of_its_audible_modes() {
    let dir = temp_dir();
    let d = dir.path();
    modal(d, &["mesh", "box", "--size", "0.12,0.06,0.04", "--h", "0.03", "-o", "box.msh"]).ok();
    let solve = ["precompute", "box.msh", "--material", "steel", "--order", "1", "--modes", "4"];
    let band = ["--max-freq", "200000", "--no-cache"];
    let json = modal(
        d,
        &[&solve[..], &band, &["-o", "box.bank", "--transfer-max-freq", "20000", "--json"]].concat(),
    )
    .ok()
    .json();
    let (bank, table) = ModeBank::load_with_radiation(d.join("box.bank")).unwrap();
    let table = table.expect("--transfer-max-freq stores a table");
    let audible: Vec<usize> = (0..bank.mode_count()).filter(|&i| bank.frequencies_hz[i] <= 20000.0).collect();
    assert!(!audible.is_empty() && audible.len() < bank.mode_count(), "{:?}", bank.frequencies_hz);
    assert_eq!(table.modes.iter().map(|m| m.mode).collect::<Vec<_>>(), audible);
    for (i, m) in json["modes"].as_array().unwrap().iter().enumerate() {
        assert_eq!(m["radiated_power_w"].is_null(), !audible.contains(&i), "mode {i}: {m}");
    }
    modal(d, &["radiation", "box.bank", "--max-freq", "20000", "--store", "cli.bank"]).ok();
    let (_, via_cli) = ModeBank::load_with_radiation(d.join("cli.bank")).unwrap();
    assert_eq!(via_cli.as_ref(), Some(&table), "precompute's table differs from `modal radiation --store`");

    for bad in ["0", "-5", "nan"] {
        modal(d, &[&solve[..], &band, &["-o", "bad.bank", "--transfer-max-freq", bad]].concat())
            .fails_with("--transfer-max-freq");
        assert!(!d.join("bad.bank").exists());
    }
}

/// A disc thinner than its panels (20 cm × 2 mm: the mesher sizes 6 mm
/// elements) gets the thin-wall warning before the
/// solve (the defaults can be several dB off in quiet directions there),
/// and not with `--full-resolution`; a body as thick as its panels (the
/// soft sphere above, `coarse_panels_…`) does not.
#[test]
fn a_thin_disc_is_warned_about_at_the_default_resolution() {
    let dir = temp_dir();
    let mesh = ["mesh", "cylinder", "--radius", "0.1", "--length", "0.002", "-o", "d.msh"];
    modal(dir.path(), &mesh).ok();
    let precompute =
        ["precompute", "d.msh", "-o", "d.bank", "--material", "steel", "--modes", "2", "--no-cache"];
    modal(dir.path(), &precompute).ok();
    let run = |extra: &[&str]| {
        let mut a = vec!["radiation", "d.bank", "--mode", "0", "--point", "0.2,0.1,0.15", "--json"];
        a.extend(extra);
        modal(dir.path(), &a).ok()
    };
    let default = run(&[]);
    let warning = default
        .stderr
        .lines()
        .find(|l| l.contains("thin wall"))
        .unwrap_or_else(|| panic!("{}", default.stderr));
    assert!(warning.starts_with("warning: ") && warning.contains("2.00 mm thick"), "{warning}");
    assert!(warning.contains("--full-resolution"), "{warning}");
    // With --full-resolution no warning comes before the solve (here refused
    // at once by a tiny memory guard, so the check costs no solve).
    let full = ["radiation", "d.bank", "--mode", "0", "--full-resolution"];
    let refused = modal_within_memory(dir.path(), &full, "0.001").fails_with("memory limit");
    assert!(!refused.stderr.contains("thin wall"), "{}", refused.stderr);
    // Three rounds at its rim take the disc past the full-resolution limit
    // (68 992 panels): refused before any solve, and the advice is fewer
    // rounds, not dropping --full-resolution (which the refinement needs).
    let mut refined = full.to_vec();
    refined.extend(["--refine-creases", "3"]);
    let over = modal(dir.path(), &refined).fails_with("round(s) of crease refinement make");
    assert!(over.stderr.contains("fewer --refine-creases rounds"), "{}", over.stderr);
    assert!(!over.stderr.contains("drop --full-resolution"), "{}", over.stderr);
}
