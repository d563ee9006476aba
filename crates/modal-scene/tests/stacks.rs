//! Bodies set exactly touching stay put (docs/scene-format.md: "Objects set
//! exactly touching are fine"), also when the touching faces share their
//! footprint — a bar on a bar, a brick on a brick — where rapier's queries are
//! at their most degenerate.

mod common;

use std::path::Path;

use modal_fem::Material;
use modal_scene::{render, InMemoryProvider, RenderOptions, Scene};

/// A 30 × 2 × 3 cm aluminium bar resting on another (`lower` is "fixed" or
/// "dynamic" on a floor), turned `turn_deg` about the vertical, its bottom
/// `gap_m` above the lower bar's top.
fn bar_on_bar(lower: &str, turn_deg: f64, gap_m: f64) -> String {
    format!(
        r#"
duration = 1.0
sample_rate = 16000
[listener]
position = [0.0, 0.3, 0.4]
channels = "mono"
{ground}
[[objects]]
name = "lower"
body = "{lower}"
mesh = {{ generate = "box", size = [0.3, 0.02, 0.03] }}
material = "aluminium"
position = [0.0, 0.01, 0.0]
[[objects]]
name = "upper"
mesh = {{ generate = "box", size = [0.3, 0.02, 0.03] }}
material = "aluminium"
position = [0.0, {y}, 0.0]
rotation = {{ euler = [0.0, {turn_deg}, 0.0] }}
"#,
        y = 0.03 + gap_m,
        ground = if lower == "dynamic" { "[ground]" } else { "" }
    )
}

#[test]
fn a_bar_set_on_a_bar_stays_put_and_silent() {
    let aluminium = Material::preset("aluminium").expect("aluminium");
    let mesh = modal_mesh::generate::box_mesh([0.3, 0.02, 0.03], [30, 2, 3]);
    let bank = common::bank_on(&mesh, aluminium, &[3000.0]);
    let mut failures = Vec::new();
    for lower in ["fixed", "dynamic"] {
        for turn in [0.0, 0.1, 1.0, 2.0, 45.0, 90.0] {
            for gap in [0.0, 1e-6] {
                let scene =
                    Scene::from_toml_str(&bar_on_bar(lower, turn, gap), Path::new(".")).expect("scene");
                let mut p = InMemoryProvider::new();
                p.insert("box", bank.clone());
                let out = render(&scene, &mut p, &RenderOptions { collect_events: true }).expect("render");
                let upper = &out.report.objects[1];
                let [x, y, z] = upper.final_position_m;
                // Before: thrown off at up to 8 m/s (fixed lower bar, 0.1–2°), or
                // fallen through (1 µm gap). The contacts are soft (rapier's
                // 30 Hz contact spring): a stack settles by ≈ 0.5 mm.
                let (slid, sank) = ((x * x + z * z).sqrt(), 0.03 - y);
                if !out.events.is_empty() || slid > 1e-3 || sank.abs() > 2e-3 || upper.peak_pa_at_1m > 1e-3 {
                    failures.push(format!(
                        "{lower} {turn}° gap {gap}: {} impacts, slid {slid:.4} m, sank {sank:.4} m, peak {:.2e} Pa",
                        out.events.len(),
                        upper.peak_pa_at_1m
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn three_bars_stacked_crosswise_stay_put_and_silent() {
    // Each bar is lifted over the one below, so the top one starts two gaps up:
    // it must still settle without an impact.
    let bar = |name: &str, y: f64, turn: f64| {
        format!(
            "[[objects]]\nname = \"{name}\"\nmesh = {{ generate = \"box\", size = [0.3, 0.02, 0.03] }}\n\
             material = \"aluminium\"\nposition = [0.0, {y}, 0.0]\nrotation = {{ euler = [0.0, {turn}, 0.0] }}\n"
        )
    };
    let text = format!(
        "duration = 1.0\nsample_rate = 16000\n[listener]\nchannels = \"mono\"\n[ground]\n{}{}{}",
        bar("bottom", 0.01, 0.0),
        bar("middle", 0.03, 90.0),
        bar("top", 0.05, 0.0)
    );
    let scene = Scene::from_toml_str(&text, Path::new(".")).expect("scene");
    let aluminium = Material::preset("aluminium").expect("aluminium");
    let mesh = modal_mesh::generate::box_mesh([0.3, 0.02, 0.03], [30, 2, 3]);
    let mut p = InMemoryProvider::new();
    p.insert("box", common::bank_on(&mesh, aluminium, &[3000.0]));
    let out = render(&scene, &mut p, &RenderOptions { collect_events: true }).expect("render");
    assert!(out.events.is_empty(), "{:?}", out.events);
    let [x, y, z] = out.report.objects[2].final_position_m;
    assert!((x * x + z * z).sqrt() < 1e-3 && (0.05 - y).abs() < 2e-3, "top bar ends at {x}, {y}, {z}");
}

/// A tower of `n` wooden blocks (10 × 5 × 10 cm) set on each other on the
/// floor, and a steel ball dropped onto its top from `drop_m` above it
/// (`None`: no ball).
fn tower(n: usize, drop_m: Option<f64>) -> Scene {
    let mut text =
        String::from("duration = 1.0\nsample_rate = 16000\n[listener]\nchannels = \"mono\"\n[ground]\n");
    for k in 0..n {
        text += &format!(
            "[[objects]]\nname = \"b{k}\"\nmesh = {{ generate = \"box\", size = [0.1, 0.05, 0.1] }}\n\
             material = \"wood\"\nposition = [0.0, {y}, 0.0]\n",
            y = 0.025 + 0.05 * k as f64
        );
    }
    if let Some(h) = drop_m {
        text += &format!(
            "[[objects]]\nname = \"ball\"\nmesh = {{ generate = \"sphere\", radius = 0.01 }}\nmaterial = \"steel\"\n\
             position = [0.0, {y}, 0.0]\n",
            y = 0.05 * n as f64 + 0.01 + h
        );
    }
    Scene::from_toml_str(&text, Path::new(".")).expect("scene")
}

#[test]
fn a_tower_set_at_rest_settles_without_a_click_and_a_ball_on_it_still_strikes() {
    // Settling under the tower's load closed the fourth block onto the third
    // at 0.056 m/s after 6 ms, above a new contact's 0.05 m/s: a click from a
    // tower at rest. Blocks set on each other touch from the start.
    let wood = Material::preset("wood").expect("wood");
    let mut p = InMemoryProvider::new();
    p.insert(
        "box",
        common::bank_on(&modal_mesh::generate::box_mesh([0.1, 0.05, 0.1], [4, 2, 4]), wood, &[900.0]),
    );
    p.insert("sphere", common::ball(0.01, &[5000.0]));
    let out = render(&tower(5, None), &mut p, &RenderOptions { collect_events: true }).expect("render");
    assert!(out.events.is_empty(), "{:?}", out.events);
    // Struck from outside, the same tower's blocks still sound.
    let out = render(&tower(5, Some(0.05)), &mut p, &RenderOptions { collect_events: true }).expect("render");
    let top: Vec<_> = out.events.iter().filter(|e| e.bodies.contains(&"b4".to_string())).collect();
    assert!(top.iter().any(|e| e.bodies.contains(&"ball".to_string())), "{:?}", out.events);
}
