//! Issue 16 acceptance (library level, stand-in banks): sliding and rolling
//! sound, silence at rest and after stopping, no double onset, determinism,
//! bad surface values.

mod common;

use std::path::Path;

use modal_fem::Material;
use modal_scene::{render, InMemoryProvider, RenderOptions, Rendered, Scene};

const BLOCK: [f64; 3] = [0.08, 0.04, 0.06];
const FS: f64 = 32_000.0;

/// A block resting on the floor (its bottom exactly at y = 0), sliding along
/// x at `speed` under gravity `g`, friction `mu` (object and floor).
fn slide_scene(speed: f64, g: f64, mu: f64, duration: f64) -> Scene {
    let text = format!(
        r#"
duration = {duration}
sample_rate = {FS}
gravity = [0.0, {}, 0.0]
[listener]
position = [0.0, 0.3, 0.6]
channels = "mono"
[ground]
material = "wood"
friction = {mu}
[[objects]]
name = "block"
mesh = {{ generate = "box", size = [{}, {}, {}] }}
material = "wood"
position = [0.0, {}, 0.0]
linear_velocity = [{speed}, 0.0, 0.0]
friction = {mu}
"#,
        -g,
        BLOCK[0],
        BLOCK[1],
        BLOCK[2],
        BLOCK[1] / 2.0
    );
    Scene::from_toml_str(&text, Path::new(".")).expect("scene")
}

fn block_provider(material: Material) -> InMemoryProvider {
    let mesh = modal_mesh::generate::box_mesh(BLOCK, [2, 2, 2]);
    let mut p = InMemoryProvider::new();
    p.insert("box", common::bank_on(&mesh, material, &[700.0, 1500.0, 2600.0, 4100.0, 6300.0, 9000.0]));
    p
}

fn wood() -> Material {
    Material::preset("wood").expect("wood")
}

fn run(scene: &Scene, p: &mut InMemoryProvider) -> Rendered {
    render(scene, p, &RenderOptions { collect_events: true }).expect("render")
}

fn window(y: &[f32], t0: f64, t1: f64) -> &[f32] {
    &y[(t0 * FS) as usize..(t1 * FS) as usize]
}

fn rms(x: &[f32]) -> f64 {
    (x.iter().map(|v| (*v as f64).powi(2)).sum::<f64>() / x.len() as f64).sqrt()
}

/// Power-weighted mean frequency [Hz].
fn centroid(x: &[f32]) -> f64 {
    let s = common::spectrum(x);
    let bin = FS / x.len() as f64;
    let (mut num, mut den) = (0.0, 0.0);
    for (k, m) in s.iter().enumerate() {
        num += k as f64 * bin * m * m;
        den += m * m;
    }
    num / den
}

/// Frames (hop 256) at which an onset is detected after `from` (seconds):
/// the positive spectral flux (Hann 512) relative to the previous frame's
/// magnitude sum, `Σ_b max(0, |X_k,b| − |X_k−1,b|) / Σ_b |X_k−1,b|`, exceeds
/// [`ONSET_RATIO`] (the spectrum's magnitude grows by that fraction at once).
fn onsets_after(y: &[f32], from: f64) -> Vec<usize> {
    let flux = relative_flux(y);
    let first = (from * FS / 256.0) as usize;
    (first.max(1)..flux.len()).filter(|&k| flux[k] > ONSET_RATIO).collect()
}

const ONSET_RATIO: f64 = 0.5;

/// Relative positive spectral flux per frame (module doc of [`onsets_after`]).
fn relative_flux(y: &[f32]) -> Vec<f64> {
    let (n, hop) = (512, 256);
    let mut prev: Option<Vec<f64>> = None;
    let mut flux = Vec::new();
    let mut start = 0;
    while start + n <= y.len() {
        let s = common::spectrum(&y[start..start + n]);
        flux.push(prev.as_ref().map_or(0.0, |p| {
            let rise: f64 = s.iter().zip(p).map(|(a, b)| (a - b).max(0.0)).sum();
            rise / (p.iter().sum::<f64>() + 1e-30)
        }));
        prev = Some(s);
        start += hop;
    }
    flux
}

/// Sliding block: louder with speed and with load, brighter with speed,
/// and no impact at all (the contact starts at rest height).
#[test]
fn issue_16_sliding_level_rises_with_speed_and_load_centroid_with_speed() {
    let mut p = block_provider(wood());
    // Low friction, so the speed stays nearly constant under every load.
    let (t0, t1) = (0.03, 0.15);
    let mut level = |speed: f64, g: f64| {
        let out = run(&slide_scene(speed, g, 0.01, t1), &mut p);
        assert_eq!(out.report.impacts, 0, "a block set down at rest height is no impact");
        assert_eq!(out.sustained.len(), 1, "{:?}", out.sustained);
        let w = window(&out.channels[0], t0, t1);
        (rms(w), centroid(w), out.sustained[0].clone())
    };
    let speeds: Vec<_> = [0.2, 0.4, 0.8].iter().map(|&v| level(v, 9.81)).collect();
    let loads: Vec<_> = [9.81, 19.62, 39.24].iter().map(|&g| level(0.4, g)).collect();
    for k in 0..2 {
        assert!(speeds[k + 1].0 > 1.2 * speeds[k].0, "level vs speed: {speeds:?}");
        assert!(speeds[k + 1].1 > speeds[k].1 * 1.05, "centroid vs speed: {speeds:?}");
        assert!(loads[k + 1].0 > 1.2 * loads[k].0, "level vs load: {loads:?}");
    }
    // The events report the load (m g) and speed of each run.
    let mass = 0.08 * 0.04 * 0.06 * 750.0;
    for (k, (_, _, e)) in loads.iter().enumerate() {
        let want = mass * 9.81 * 2f64.powi(k as i32);
        assert!((e.mean_force_n / want - 1.0).abs() < 0.1, "{e:?} vs {want}");
        assert!(e.mean_slip_fraction > 0.9 && (e.mean_speed_m_s - 0.4).abs() < 0.06, "{e:?}");
    }
}

/// A heavily damped block (all modes decay within a few ms) slides and
/// stops: the drive ends within 20 ms of the analytic stopping time and
/// the output is 60 dB below the sliding level from then on; at rest it
/// stays silent.
#[test]
fn issue_16_sliding_block_is_silent_within_20_ms_of_stopping() {
    let damped = Material::custom(1.1e10, 0.25, 750.0, 3000.0, 2e-6).expect("material");
    let mut p = block_provider(damped);
    let (speed, mu) = (0.3, 0.5);
    let out = run(&slide_scene(speed, 9.81, mu, 0.4), &mut p);
    let t_stop = speed / (mu * 9.81);
    assert_eq!(out.sustained.len(), 1, "{:?}", out.sustained);
    let e = &out.sustained[0];
    assert!(e.end_s <= t_stop + 0.02 && e.end_s > t_stop - 0.02, "{e:?}, stop at {t_stop}");
    let y = &out.channels[0];
    let sliding = rms(window(y, 0.005, t_stop - 0.01));
    let after = window(y, t_stop + 0.02, 0.39);
    let late = after.iter().fold(0.0f64, |m, v| m.max((*v as f64).abs()));
    assert!(sliding > 0.0 && late < 1e-3 * sliding, "sliding rms {sliding}, after stop peak {late}");
}

/// A block set down at rest: exactly silent, no sustained segment.
#[test]
fn issue_16_a_body_at_rest_is_silent() {
    let mut p = block_provider(wood());
    let out = run(&slide_scene(0.0, 9.81, 0.5, 0.5), &mut p);
    assert!(out.sustained.is_empty() && out.events.is_empty());
    assert_eq!(out.report.objects[0].force_segments, 0);
    assert!(out.channels[0].iter().all(|v| *v == 0.0));
}

/// A ball rolling on a sounding plate (plus `extra` TOML).
fn roll_scene(speed: f64, duration: f64) -> Scene {
    roll_scene_with(speed, duration, "")
}

/// A small steel pebble thrown up so it lands on the plate at ≈ 0.7 s.
const PEBBLE: &str = r#"
[[objects]]
name = "pebble"
mesh = { generate = "cylinder", radius = 0.005, length = 0.005 }
material = "steel"
position = [0.5, 0.3, 0.15]
linear_velocity = [0.0, 3.0, 0.0]
"#;

fn roll_scene_with(speed: f64, duration: f64, extra: &str) -> Scene {
    let r = 0.02;
    let text = format!(
        r#"
duration = {duration}
sample_rate = {FS}
[listener]
position = [0.2, 0.3, 0.5]
channels = "mono"
[ground]
material = "steel"
size = [1.0, 0.4]
thickness = 0.01
center = [0.3, 0.0]
[[objects]]
name = "ball"
mesh = {{ generate = "sphere", radius = {r} }}
material = "steel"
position = [0.0, {}, 0.0]
linear_velocity = [{speed}, 0.0, 0.0]
angular_velocity = [0.0, 0.0, {}]
"#,
        r + 0.0005,
        -speed / r
    ) + extra;
    Scene::from_toml_str(&text, Path::new(".")).expect("scene")
}

fn roll_provider() -> InMemoryProvider {
    let mut p = InMemoryProvider::new();
    let steel = Material::preset("steel").expect("steel");
    let plate = modal_mesh::generate::box_mesh([1.0, 0.01, 0.4], [10, 1, 4]);
    p.insert("box", common::bank_on(&plate, steel.clone(), &[180.0, 430.0, 790.0, 1300.0, 2200.0, 3500.0]));
    // A finely faceted ball, so its hull rolls smoothly.
    let ball = modal_mesh::generate::sphere(0.02, 0.004, 1).expect("sphere mesh");
    p.insert("sphere", common::bank_on(&ball, steel.clone(), &[5200.0, 7900.0]));
    let pebble = modal_mesh::generate::cylinder(0.005, 0.005, 0.0025, 1).expect("cylinder mesh");
    p.insert("cylinder", common::bank_on(&pebble, steel, &[9500.0]));
    p
}

/// Rolling ball: it sounds while it rolls, its level falls as it slows, and
/// no onset is detected after the landing (spectral flux).
#[test]
fn issue_16_rolling_ball_sounds_falls_as_it_slows_without_new_onsets() {
    let out = run(&roll_scene(0.6, 1.5), &mut roll_provider());
    let y = &out.channels[0];
    let rolling: Vec<_> = out.sustained.iter().filter(|e| e.mean_slip_fraction < 0.5).collect();
    assert!(!rolling.is_empty(), "{:?}", out.sustained);
    let impact = out.events.first().map_or(0.0, |e| e.time_s);
    // Sounds while it rolls, and falls as it slows.
    let levels: Vec<f64> =
        (0..4).map(|k| rms(window(y, 0.2 + 0.3 * k as f64, 0.45 + 0.3 * k as f64))).collect();
    assert!(levels[0] > 0.0, "{levels:?}");
    assert!(levels[0] > levels[3] * 1.2 && levels[1] > levels[3], "{levels:?}");
    // No onset after the landing (spectral flux against its running median).
    let found = onsets_after(y, impact + 0.05);
    assert!(found.is_empty(), "onsets at frames {found:?} (landing at {impact} s)");
    // The detector does see an onset: a pebble landing on the plate at
    // ≈ 0.7 s while the ball rolls.
    let with = run(&roll_scene_with(0.6, 1.5, PEBBLE), &mut roll_provider());
    let landed = with.events.iter().find(|e| e.bodies[0] == "pebble").expect("pebble lands").time_s;
    let found = onsets_after(&with.channels[0], impact + 0.05);
    assert!(found.iter().any(|&k| (k as f64 * 256.0 / FS - landed).abs() < 0.03), "{found:?} vs {landed}");
}

/// Bit-identical output with one and with two threads.
#[test]
fn issue_16_sustained_render_is_identical_across_thread_counts() {
    let scene = roll_scene(0.6, 0.5);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
    let a = one.install(|| run(&scene, &mut roll_provider()));
    let b = two.install(|| run(&scene, &mut roll_provider()));
    assert!(!a.sustained.is_empty());
    assert!(a.channels == b.channels && a.sustained == b.sustained);
}

#[test]
fn issue_16_bad_surface_values_name_the_key() {
    let base = r#"
[[objects]]
mesh = { generate = "sphere", radius = 0.02 }
material = "steel"
position = [0.0, 0.1, 0.0]
"#;
    let cases = [
        ("surface = { roughness = -1e-6 }", "objects[0].surface.roughness"),
        ("surface = { spectral_slope = nan }", "objects[0].surface.spectral_slope"),
        ("surface = { correlation_length = 5.0 }", "objects[0].surface.correlation_length"),
        ("surface = { finish = \"velvet\" }", "objects[0].surface.finish"),
        ("linear_velocity = [1e9, 0.0, 0.0]", "objects[0].linear_velocity"),
        ("angular_velocity = [0.0, 1e7, 0.0]", "objects[0].angular_velocity"),
    ];
    for (line, key) in cases {
        let text = format!("{base}{line}\n");
        let err = Scene::from_toml_str(&text, Path::new(".")).expect_err(line).to_string();
        assert!(err.contains(key), "{line}: {err}");
    }
    let ground = "[ground]\nsurface = { roughness = inf }\n";
    let err = Scene::from_toml_str(ground, Path::new(".")).expect_err("ground").to_string();
    assert!(err.contains("ground.surface.roughness"), "{err}");
    // Good values parse; sustained contact can be switched off.
    let ok = format!("sustained = false\n{base}surface = {{ finish = \"polished\", roughness = 2e-7 }}\n");
    let scene = Scene::from_toml_str(&ok, Path::new(".")).expect("valid");
    assert!(!scene.sustained);
}
