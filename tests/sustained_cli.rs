//! Issue 16 end to end: the three sustained-contact example scenes render
//! through the real pipeline (FEM banks), their events carry sustained
//! segments, the output does not depend on the thread count, and bad surface
//! values are refused naming the key.

mod common;
use common::*;

use std::path::Path;

fn render(dir: &Path, scene: &str, env: &[(&str, &Path)]) -> (serde_json::Value, Vec<serde_json::Value>) {
    let path = example(scene);
    let args = ["render", path.to_str().unwrap(), "-o", "out.wav", "--events", "e.json", "--json"];
    let report = modal_with_env(dir, &args, env).ok().json();
    let events: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("e.json")).unwrap()).unwrap();
    (report, events.as_array().unwrap().clone())
}

fn sustained<'a>(events: &'a [serde_json::Value], a: &str, b: &str) -> Vec<&'a serde_json::Value> {
    events
        .iter()
        .filter(|e| e["kind"] == "sustained")
        .filter(|e| {
            let bodies: Vec<&str> =
                e["bodies"].as_array().unwrap().iter().map(|x| x.as_str().unwrap()).collect();
            bodies.contains(&a) && bodies.contains(&b)
        })
        .collect()
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap()
}

#[test]
fn issue_16_slide_scene_block_slides_down_the_ramp_and_stops() {
    let dir = temp_dir();
    let (report, events) = render(dir.path(), "slide.toml", &[]);
    assert_eq!(report["clipped_samples"], 0);
    let on_ramp = sustained(&events, "ramp", "block");
    let on_floor = sustained(&events, "block", "ground");
    assert!(!on_ramp.is_empty() && !on_floor.is_empty(), "{events:?}");
    // Sliding (not rolling), faster at the foot of the ramp than on average.
    let ramp = on_ramp[0];
    assert!(
        f(&ramp["mean_slip_fraction"]) > 0.9 && f(&ramp["max_speed_m_s"]) > f(&ramp["mean_speed_m_s"]),
        "{ramp}"
    );
    // It stops: the drive ends well before the end of the scene.
    let end = on_floor.iter().map(|e| f(&e["end_s"])).fold(0.0, f64::max);
    assert!(end < 2.0, "{on_floor:?}");
    let block = &report["objects"][1];
    assert!(block["force_segments"].as_u64().unwrap() > 100, "{block}");
    assert!(f(&block["final_position_m"][0]) > 0.3, "{block}");
}

#[test]
fn issue_16_roll_scene_ball_rolls_round_the_bowl_and_settles_identically_on_any_thread_count() {
    let dir = temp_dir();
    let one = Path::new("1");
    let (report, events) = render(dir.path(), "roll.toml", &[("RAYON_NUM_THREADS", one)]);
    let wav = std::fs::read(dir.path().join("out.wav")).unwrap();
    let rolls = sustained(&events, "bowl", "ball");
    assert_eq!(rolls.len(), 1, "{events:?}");
    let r = rolls[0];
    // Rolling (little slip), and it settles before the end.
    assert!(f(&r["mean_slip_fraction"]) < 0.3 && f(&r["end_s"]) < 2.4, "{r}");
    assert_eq!(report["impacts"], 1, "one landing, then rolling: {events:?}");
    let two = Path::new("2");
    let (again, _) = render(dir.path(), "roll.toml", &[("RAYON_NUM_THREADS", two)]);
    assert_eq!(again["banks_cached"], report["banks_requested"]);
    assert!(std::fs::read(dir.path().join("out.wav")).unwrap() == wav, "thread count changed the output");
}

#[test]
fn issue_16_spin_scene_disc_rolls_on_its_rim_then_lands_flat_on_the_table() {
    let dir = temp_dir();
    let (report, events) = render(dir.path(), "spin.toml", &[]);
    // It rolls on its rim (sustained contact with the table) until it falls
    // flat: the last impact, late in the scene.
    let rolling = sustained(&events, "disc", "ground");
    assert!(!rolling.is_empty(), "{events:?}");
    let t: Vec<f64> = events.iter().filter(|e| e["kind"] == "impact").map(|e| f(&e["time_s"])).collect();
    let landing = *t.last().expect("an impact");
    assert!(landing > 0.5, "{t:?}");
    let covered: f64 = rolling.iter().map(|e| f(&e["end_s"]).min(landing) - f(&e["start_s"])).sum();
    assert!(covered > 0.8 * landing, "sustained {covered} s of {landing} s: {events:?}");
    // It ends lying flat ON the table: its centre half its 6 mm thickness
    // above it (the reduced hull once let a flat disc sink 3 cm through).
    let y = f(&report["objects"][0]["final_position_m"][1]);
    assert!((y - 0.003).abs() < 5e-4, "{report}");
}

#[test]
fn issue_16_bad_surface_values_are_refused_naming_the_key() {
    let dir = temp_dir();
    let scene = "[[objects]]\nmesh = { generate = \"sphere\", radius = 0.02 }\nmaterial = \"steel\"\nposition = [0.0, 0.1, 0.0]\n";
    for (line, key) in [
        ("surface = { roughness = -1e-6 }", "objects[0].surface.roughness"),
        ("surface = { spectral_slope = nan }", "objects[0].surface.spectral_slope"),
        ("linear_velocity = [0.0, -5000.0, 0.0]", "objects[0].linear_velocity"),
    ] {
        std::fs::write(dir.path().join("s.toml"), format!("{scene}{line}\n")).unwrap();
        modal(dir.path(), &["render", "s.toml", "-o", "s.wav"]).fails_with(key);
    }
    std::fs::write(dir.path().join("s.toml"), format!("contact_prediction = 0.5\n{scene}")).unwrap();
    modal(dir.path(), &["render", "s.toml", "-o", "s.wav"]).fails_with("contact_prediction");
}
