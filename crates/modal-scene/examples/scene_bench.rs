//! Times the scene stages on stand-in banks: the demo scene and a scene of
//! 100 objects (balls, bars and blocks raining onto a floor).
//!
//! `cargo run -p modal-scene --example scene_bench [--release]`

use std::path::Path;
use std::sync::Arc;

use modal_bank::ModeBank;
use modal_fem::Material;
use modal_mesh::generate::{self, Shape};
use modal_scene::stand_in::synthetic_bank;
use modal_scene::{render, BankProvider, BankRequest, MeshSource, ProviderError, RenderOptions, Scene};

/// Stand-in banks for generated meshes: 40 modes from 400 Hz up.
struct StandIn;

impl BankProvider for StandIn {
    fn bank(&mut self, request: &BankRequest) -> Result<Arc<ModeBank>, ProviderError> {
        let Some(MeshSource::Generate(g)) = &request.mesh else { return Err("generated meshes only".into()) };
        let shape = g.shape()?;
        let h = match shape {
            Shape::Box { size } => size.iter().cloned().fold(f64::INFINITY, f64::min).max(0.01),
            _ => 0.012,
        };
        let mesh = generate::generate(&shape, h, 1)?;
        let material = request.material.clone().unwrap_or(Material::preset("steel")?);
        let freqs: Vec<f64> = (0..40).map(|i| 400.0 * (1.0 + 0.37 * i as f64)).collect();
        Ok(Arc::new(synthetic_bank(&mesh, material, &freqs)))
    }
}

fn many_objects(n: usize) -> String {
    let mut s = String::from(
        "duration = 4.0\nsample_rate = 48000\n[listener]\nposition = [0.0, 0.5, 2.0]\n[ground]\n",
    );
    let kinds = [
        ("{ generate = \"sphere\", radius = 0.02 }", "steel"),
        ("{ generate = \"box\", size = [0.12, 0.02, 0.01] }", "aluminium"),
        ("{ generate = \"box\", size = [0.05, 0.04, 0.03] }", "wood"),
    ];
    for i in 0..n {
        let (mesh, material) = kinds[i % 3];
        let (x, z) = ((i % 10) as f64 * 0.15 - 0.7, (i / 10) as f64 * 0.15 - 0.7);
        let y = 0.1 + 0.03 * (i % 7) as f64;
        s += &format!(
            "[[objects]]\nmesh = {mesh}\nmaterial = \"{material}\"\nposition = [{x}, {y}, {z}]\nrotation = {{ euler = [{}, 0.0, {}] }}\n",
            (i * 37 % 90) as f64,
            (i * 53 % 90) as f64
        );
    }
    s
}

fn run(label: &str, scene: &Scene) {
    let out = render(scene, &mut StandIn, &RenderOptions::default()).expect("render");
    let r = &out.report;
    let rtf = |s: f64| r.duration_s / s;
    println!(
        "{label}: {} objects, {} impacts, {:.1} s audio | physics {:.3} s ({:.0}x), excitation {:.4} s, synthesis {:.3} s ({:.0}x), mix {:.3} s | total {:.0}x real time | peak {:.2}, clipped {}",
        r.objects.len(),
        r.impacts,
        r.duration_s,
        r.physics_s,
        rtf(r.physics_s),
        r.excitation_s,
        r.synthesis_s,
        rtf(r.synthesis_s),
        r.mix_s,
        r.real_time_factor(),
        r.peak,
        r.clipped_samples
    );
}

fn main() {
    run("demo (stand-in banks)", &Scene::demo());
    let scene = Scene::from_toml_str(&many_objects(100), Path::new(".")).expect("scene");
    run("100 objects", &scene);
}
