//! Issue 5 point 3 (CCD for fast bodies): a small steel ball thrown fast at
//! the wall of a glass bowl whose collider is a convex decomposition (a
//! compound of thin convex parts) must bounce off the outside of the wall,
//! not tunnel through it.
//!
//! At the speeds used here the ball travels 1.5–12 cm per 1 ms physics step,
//! 4–30 times the wall's 4 mm thickness and 1.5–12 times its own diameter.
//! Up to ≈ 60 m/s rapier's contact prediction alone catches it; beyond, only
//! a continuous sweep against the (dynamic) bowl does. When every dynamic
//! body was a rapier "bullet" no such sweep ever ran (a bullet never sweeps
//! another bullet): at 100 m/s the ball flew through the bowl untouched.
//! Now a body is a bullet only while it is fast (`World::update_bullets`).

mod common;

use std::path::Path;

use common::BOWL_RADIUS_M;
use modal_scene::{render, InMemoryProvider, RenderOptions, Scene};

/// Height of the rim plane (the shell's sphere centre) above the bowl's
/// centre of mass, for the bowl of `common::bowl_and_ball` [m].
const RIM_ABOVE_COM_M: f64 = 0.029;
/// Radius of the ball [m].
const BALL_RADIUS_M: f64 = 0.005;

/// The bowl resting opening-up on a silent floor; the ball starts 0.15 m to
/// its left, level with the middle of the wall, flying at `speed` towards +x.
fn thrown_ball(speed_m_s: f64) -> String {
    format!(
        r#"
duration = 0.3
sample_rate = 16000
[listener]
channels = "mono"
[ground]
[[objects]]
name = "bowl"
mesh = {{ generate = "bowl", radius = {BOWL_RADIUS_M}, thickness = 0.004 }}
material = "glass"
position = [0.0, 0.0335, 0.0]
rotation = {{ euler = [-90.0, 0.0, 0.0] }}
collider = "decomposition"
[[objects]]
name = "ball"
mesh = {{ generate = "sphere", radius = {BALL_RADIUS_M} }}
material = "steel"
position = [-0.2, 0.045, 0.0]
linear_velocity = [{speed_m_s}, 0.0, 0.0]
"#
    )
}

fn provider() -> InMemoryProvider {
    common::bowl_and_ball(BALL_RADIUS_M)
}

#[test]
fn a_fast_ball_bounces_off_a_decomposed_bowl_wall_without_tunnelling() {
    for speed in [15.0, 30.0, 60.0, 120.0] {
        let scene = Scene::from_toml_str(&thrown_ball(speed), Path::new(".")).expect("scene");
        let out = render(&scene, &mut provider(), &RenderOptions { collect_events: true }).expect("render");
        let [bowl, ball] = [0, 1].map(|k| out.report.objects[k].final_position_m);
        eprintln!("{speed} m/s: bowl ends at {bowl:?}, ball at {ball:?}");
        // The first contact of the two is on the outside of the near wall:
        // at the shell's outer radius from the rim centre, on the −x side.
        let hit = out
            .events
            .iter()
            .find(|e| e.bodies.contains(&"ball".to_string()) && e.bodies.contains(&"bowl".to_string()))
            .unwrap_or_else(|| panic!("{speed} m/s: the ball never touched the bowl"));
        let centre = [0.0, 0.0335 + RIM_ABOVE_COM_M, 0.0];
        let r = (0..3).map(|c| (hit.point_m[c] - centre[c]).powi(2)).sum::<f64>().sqrt();
        assert!(hit.point_m[0] < -0.04, "{speed} m/s: first contact at {:?}", hit.point_m);
        assert!(
            r > BOWL_RADIUS_M - 0.003,
            "{speed} m/s: first contact {r} m from the centre, inside the shell"
        );
        // It bounced back: it ends on the near side of the bowl, outside it.
        assert!(
            ball[0] < bowl[0] - BOWL_RADIUS_M - BALL_RADIUS_M + 0.002,
            "{speed} m/s: the ball ended at {ball:?}, past the near wall of the bowl at {bowl:?}"
        );
    }
}

#[test]
fn a_swept_impact_is_timed_when_the_body_arrives_not_at_the_next_step() {
    // A 1 cm ball at `speed` in zero gravity, 0.3 m above a fixed 3 mm steel
    // plate, at a game's physics rate: it arrives after (0.3 − 0.01 − 0.0015)/v.
    // Continuous collision detection stops it there and the bounce comes in
    // the next step; timed at that step's start it was up to 16 ms late.
    for speed in [5.0, 10.0, 40.0] {
        let text = format!(
            "duration = 0.2\nsample_rate = 16000\nphysics_rate = 60\ngravity = [0.0, 0.0, 0.0]\n\
             [listener]\nchannels = \"mono\"\n\
             [[objects]]\nname = \"plate\"\nbody = \"fixed\"\n\
             mesh = {{ generate = \"box\", size = [0.3, 0.003, 0.3] }}\nmaterial = \"steel\"\n\
             [[objects]]\nname = \"ball\"\nmesh = {{ generate = \"sphere\", radius = 0.01 }}\n\
             material = \"steel\"\nposition = [0.0, 0.3, 0.0]\nlinear_velocity = [0.0, -{speed}, 0.0]\n"
        );
        let scene = Scene::from_toml_str(&text, Path::new(".")).expect("scene");
        let mut p = InMemoryProvider::new();
        p.insert("box", common::block([0.3, 0.003, 0.3], &[2000.0]));
        p.insert("sphere", common::ball(0.01, &[8000.0]));
        let out = render(&scene, &mut p, &RenderOptions { collect_events: true }).expect("render");
        let first = out.events.first().expect("an impact");
        let arrival = (0.3 - 0.01 - 0.0015) / speed;
        assert!((first.time_s - arrival).abs() < 2e-4, "{speed} m/s: at {} s, not {arrival} s", first.time_s);
    }
}
