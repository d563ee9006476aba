//! A thin disc lying flat rests on the floor (issue #16: the reduced convex
//! hull of a coin-like disc sank through the floor once flat, because parry
//! builds half-space contacts from only the first 4 vertices of a face; see
//! `face_hull.rs`).

mod common;

use std::path::Path;

use modal_fem::Material;
use modal_scene::{render, InMemoryProvider, RenderOptions, Scene};

/// Radius and thickness of the disc [m] (that of `meshes/spin.toml`).
const R: f64 = 0.04;
const T: f64 = 0.006;

fn disc_provider() -> InMemoryProvider {
    // Order 2, 3 mm cells: ≈ 170 nodes round each rim, so each cap of the
    // hull is one face with far more than 4 vertices.
    let mesh = modal_mesh::generate::cylinder(R, T, 0.003, 2).expect("disc mesh");
    let mut p = InMemoryProvider::new();
    p.insert("cylinder", common::bank_on(&mesh, Material::preset("steel").expect("steel"), &[2500.0]));
    p
}

/// Final centre of mass of a disc set down at `tilt_deg` from flat with
/// its lowest rim point `gap` above the floor, after 1.2 s.
fn final_centre(collider: &str, tilt_deg: f64, gap: f64) -> [f64; 3] {
    let t = tilt_deg.to_radians();
    // Centre height with the lowest rim point at y = gap.
    let y = gap + R * t.sin() + 0.5 * T * t.cos();
    let text = format!(
        r#"
duration = 1.2
sample_rate = 8000
[listener]
channels = "mono"
[ground]
[[objects]]
name = "disc"
mesh = {{ generate = "cylinder", radius = {R}, length = {T} }}
material = "steel"
position = [0.0, {y}, 0.0]
rotation = {{ euler = [{}, 0.0, 0.0] }}
collider = "{collider}"
"#,
        -90.0 + tilt_deg
    );
    let scene = Scene::from_toml_str(&text, Path::new(".")).expect("scene");
    let out = render(&scene, &mut disc_provider(), &RenderOptions::default()).expect("render");
    let at = out.report.objects[0].final_position_m;
    eprintln!("{collider}, tilt {tilt_deg}°: disc ends at {at:?}, {} steps", out.report.physics_steps);
    at
}

#[test]
fn a_flat_thin_disc_rests_on_the_floor() {
    for collider in ["hull", "auto", "decomposition"] {
        // Set down flat, at rest, 0.1 mm above the floor.
        let c = final_centre(collider, 0.0, 1e-4);
        assert!(
            (c[1] - 0.5 * T).abs() < 3e-4,
            "{collider}: flat disc's centre at y = {} (want {})",
            c[1],
            T / 2.0
        );
        // Set down on its rim tilted 25°: it falls flat and rests there
        // (with parry's first-4-vertices contact polygon it ended 3 cm
        // below the floor).
        let c = final_centre(collider, 25.0, 1e-4);
        assert!((c[1] - 0.5 * T).abs() < 3e-4, "{collider}: tilted disc's centre at y = {}", c[1]);
        assert!(c[0].abs() < R && c[2].abs() < R, "{collider}: {c:?}");
    }
}
