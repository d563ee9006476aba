//! Issue 15, runtime: `render` hears each mode through its acoustic
//! transfer (per ear, in the body's rotating frame, per block), optionally
//! with the ground plane's image; deterministic for any thread count.

mod common;

use std::path::Path;

use modal_bank::{ModeBank, ModeTransfer, RadiationTable};
use modal_scene::{render, InMemoryProvider, RenderOptions, Rendered, Scene, SceneError};

const FREQS: [f64; 3] = [900.0, 2300.0, 4100.0];

fn scene(radiation: &str, reflection: bool) -> Scene {
    scene_at([0.1, 0.3, 0.8], "stereo", radiation, reflection)
}

fn scene_at(ear: [f64; 3], channels: &str, radiation: &str, reflection: bool) -> Scene {
    let [x, y, z] = ear;
    let text = format!(
        r#"
duration = 0.6
sample_rate = 16000
physics_rate = 1000
[listener]
position = [{x}, {y}, {z}]
channels = "{channels}"
radiation = "{radiation}"
ground_reflection = {reflection}
[ground]
material = "wood"
[[objects]]
name = "block"
mesh = {{ generate = "box", size = [0.08, 0.05, 0.04] }}
material = "wood"
position = [0.0, 0.12, 0.0]
rotation = {{ axis = [1.0, 1.0, 0.0], angle = 25.0 }}
angular_velocity = [0.0, 0.0, 12.0]
"#
    );
    Scene::from_toml_str(&text, Path::new(".")).expect("scene")
}

fn bank() -> ModeBank {
    common::block([0.08, 0.05, 0.04], &FREQS)
}

/// Mode 0 a dipole along x, mode 1 a quadrupole, mode 2 a monopole plus a
/// dipole along y (coefficients in Pa at unit modal velocity).
fn table(bank: &ModeBank) -> RadiationTable {
    let mut modes = Vec::new();
    for (i, f) in FREQS.iter().enumerate() {
        let k = 2.0 * std::f64::consts::PI * f / 343.0;
        let mut c = vec![[0.0; 2]; 9];
        match i {
            0 => (c[1], c[3]) = ([200.0, 0.0], [-200.0, 0.0]),
            1 => (c[4], c[8]) = ([0.0, 500.0], [0.0, 500.0]),
            _ => (c[0], c[2]) = ([1000.0, 300.0], [0.0, 2000.0]),
        }
        modes.push(ModeTransfer {
            mode: i,
            wavenumber: k,
            order: 2,
            coefficients: c,
            power_w: 1e-3,
            efficiency: 0.1,
        });
    }
    RadiationTable {
        centre_m: bank.mass.center_of_mass_m,
        fit_radius_m: 0.1,
        air_density_kg_m3: 1.21,
        sound_speed_m_s: 343.0,
        tolerance: 0.01,
        modes,
    }
}

fn provider(with_table: bool) -> InMemoryProvider {
    let b = bank();
    let t = table(&b);
    let mut p = InMemoryProvider::new();
    p.insert("box", b);
    if with_table {
        p.insert_radiation("box", t);
    }
    p
}

fn run(scene: &Scene, with_table: bool) -> Rendered {
    render(scene, &mut provider(with_table), &RenderOptions::default()).expect("render")
}

fn bits(r: &Rendered) -> Vec<Vec<u32>> {
    r.channels.iter().map(|c| c.iter().map(|x| x.to_bits()).collect()).collect()
}

#[test]
fn the_transfer_is_used_and_reported_and_changes_the_sound() {
    let with = run(&scene("transfer", false), true);
    let o = &with.report.objects[0];
    assert_eq!(o.modes_with_transfer, 3);
    assert!(o.impacts > 0 && with.report.peak > 1e-5, "{:?}", with.report);
    let estimate = run(&scene("estimate", false), true);
    assert_eq!(estimate.report.objects[0].modes_with_transfer, 0);
    assert_ne!(bits(&with), bits(&estimate));
    // The two ears hear different directivities: not merely a delay and gain.
    let (l, r) = (&with.channels[0], &with.channels[1]);
    assert_ne!(l, r);
}

#[test]
fn without_a_table_the_transfer_setting_falls_back_to_the_estimate_exactly() {
    let a = run(&scene("transfer", false), false);
    let b = run(&scene("estimate", false), false);
    assert_eq!(a.report.objects[0].modes_with_transfer, 0);
    assert_eq!(bits(&a), bits(&b));
}

#[test]
fn bit_identical_for_one_and_two_threads_with_transfer_and_reflection() {
    let scene = scene("transfer", true);
    let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().expect("pool");
    let one = pool(1).install(|| run(&scene, true));
    let two = pool(2).install(|| run(&scene, true));
    assert!(one.report.peak > 1e-5);
    assert_eq!(bits(&one), bits(&two));
}

#[test]
fn the_ground_image_is_what_an_ear_mirrored_in_the_floor_hears() {
    let ear = [0.1, 0.3, 0.8];
    let direct = run(&scene_at(ear, "mono", "transfer", false), true);
    let both = run(&scene_at(ear, "mono", "transfer", true), true);
    let mirrored = run(&scene_at([0.1, -0.3, 0.8], "mono", "transfer", false), true);
    let (d, b, m) = (&direct.channels[0], &both.channels[0], &mirrored.channels[0]);
    let peak = common::peak(m) as f64;
    assert!(peak > 1e-5);
    // Equal up to summation rounding and the −100 dB tail cut (which
    // depends on the farthest listening point).
    let err = (0..b.len()).map(|n| (b[n] as f64 - d[n] as f64 - m[n] as f64).abs()).fold(0.0, f64::max);
    assert!(err < 1e-4 * peak, "{err} vs {peak}");
}

#[test]
fn ground_reflection_needs_a_ground_plane() {
    let text = r#"
[listener]
ground_reflection = true
[[objects]]
mesh = { generate = "box", size = [0.08, 0.05, 0.04] }
material = "wood"
"#;
    let err = Scene::from_toml_str(text, Path::new(".")).expect_err("no ground");
    assert!(
        matches!(&err, SceneError::Invalid { path, .. } if path == "listener.ground_reflection"),
        "{err}"
    );
}
