//! Times the scene stages on stand-in banks: the demo scene and the scene of
//! 100 objects `meshes/rain100.toml` (balls, bars, blocks and bowls raining
//! onto a floor). With real banks, time `modal render meshes/rain100.toml`.
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
        let h = g.element_size.unwrap_or(match shape {
            Shape::Box { size } => size.iter().cloned().fold(f64::INFINITY, f64::min).max(0.01),
            _ => 0.012,
        });
        let mesh = generate::generate(&shape, h, 1)?;
        let material = request.material.clone().unwrap_or(Material::preset("steel")?);
        let freqs: Vec<f64> = (0..40).map(|i| 400.0 * (1.0 + 0.37 * i as f64)).collect();
        Ok(Arc::new(synthetic_bank(&mesh, material, &freqs)))
    }
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
    let rain = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../meshes/rain100.toml");
    let scene = Scene::from_file(&rain).expect("meshes/rain100.toml");
    run("100 objects (meshes/rain100.toml)", &scene);
}
