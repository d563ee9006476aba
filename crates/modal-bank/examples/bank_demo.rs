//! Writes a synthetic bank (no eigen solve) or times the bank operations.
//!
//! ```text
//! cargo run -p modal-bank --example bank_demo -- write OUT.bank [MODES] [GRID]
//! cargo run -p modal-bank --example bank_demo -- bench [MODES] [GRID]
//! ```
//! `write` also writes `OUT.vtu`. The surface is a GRID × GRID plate of
//! 0.2 m side (triangulated), shapes are plate-like sine patterns.

use modal_bank::{export_vtu, export_vtu_file, retune, BankCache, CacheKey, ModeBank, RetuneSpec, SolveInfo};
use modal_fem::{MassProperties, Material};
use modal_mesh::Surface;
use std::f64::consts::PI;
use std::time::Instant;

fn plate(modes: usize, grid: usize) -> ModeBank {
    let side = 0.2;
    let h = side / (grid - 1) as f64;
    let positions: Vec<[f64; 3]> =
        (0..grid * grid).map(|k| [(k % grid) as f64 * h, (k / grid) as f64 * h, 0.0]).collect();
    let mut triangles = Vec::new();
    for j in 0..grid - 1 {
        for i in 0..grid - 1 {
            let a = j * grid + i;
            triangles.push([a, a + 1, a + grid + 1]);
            triangles.push([a, a + grid + 1, a + grid]);
        }
    }
    let mut shapes = Vec::with_capacity(modes * positions.len() * 3);
    for m in 0..modes {
        let (p, q) = (1 + m % 4, 1 + m / 4);
        for x in &positions {
            let w = (p as f64 * PI * x[0] / side).sin() * (q as f64 * PI * x[1] / side).sin();
            shapes.extend([0.0, 0.0, (0.5 * w) as f32]);
        }
    }
    let material = Material {
        name: Some("steel".into()),
        youngs_pa: 2.0e11,
        poisson: 0.29,
        density_kg_m3: 7850.0,
        alpha: 5.0,
        beta: 3e-8,
    };
    let volume = side * side * 0.01;
    let mass = volume * material.density_kg_m3;
    let mut bank = ModeBank {
        frequencies_hz: (0..modes).map(|i| 250.0 * (i + 1) as f64).collect(),
        damping_ratios: vec![],
        decay_rates: vec![],
        residuals: vec![1e-10; modes],
        shapes,
        surface: Surface {
            node_ids: (0..positions.len()).collect(),
            positions,
            triangles,
            triangle_edge_nodes: None,
        },
        material,
        mass: MassProperties {
            volume_m3: volume,
            mass_kg: mass,
            center_of_mass_m: [0.1, 0.1, 0.005],
            inertia_kg_m2: [
                [mass * 0.04 / 12.0, 0.0, 0.0],
                [0.0, mass * 0.04 / 12.0, 0.0],
                [0.0, 0.0, mass * 0.08 / 12.0],
            ],
        },
        info: SolveInfo {
            order: 1,
            input_hash: CacheKey::new("demo").add_u64("modes", modes as u64).finish(),
            ..Default::default()
        },
    };
    bank.recompute_damping();
    bank
}

/// Best of `reps` wall times [ms].
fn time_ms(reps: usize, mut f: impl FnMut()) -> f64 {
    (0..reps)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min)
}

fn bench(modes: usize, grid: usize) -> Result<(), Box<dyn std::error::Error>> {
    let bank = plate(modes, grid);
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("b.bank");
    let bytes = bank.to_bytes()?;
    let cache = BankCache::new(dir.path().join("cache"));
    let key = bank.info.input_hash.clone();
    cache.put(&key, &bank)?;
    println!("modes {modes}, surface nodes {}, file {:.2} MB", grid * grid, bytes.len() as f64 / 1e6);
    println!("to_bytes      {:8.2} ms", time_ms(5, || drop(bank.to_bytes())));
    println!("from_bytes    {:8.2} ms", time_ms(5, || drop(ModeBank::from_bytes(&bytes))));
    println!("save (fsync)  {:8.2} ms", time_ms(5, || drop(bank.save(&path))));
    println!("load          {:8.2} ms", time_ms(5, || drop(ModeBank::load(&path))));
    println!("cache get     {:8.2} ms", time_ms(5, || drop(cache.get(&key))));
    let spec = RetuneSpec { scale: Some(2.0), ..Default::default() };
    println!("retune        {:8.2} ms", time_ms(5, || drop(retune(&bank, spec.clone()))));
    println!("export_vtu    {:8.2} ms", time_ms(3, || drop(export_vtu(&bank, std::io::sink()))));
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let num = |i: usize, default: usize| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(default);
    match args.first().map(String::as_str) {
        Some("write") => {
            let out = args.get(1).ok_or("usage: write OUT.bank [MODES] [GRID]")?;
            let bank = plate(num(2, 8), num(3, 9).max(2));
            bank.save(out)?;
            export_vtu_file(&bank, std::path::Path::new(out).with_extension("vtu"))?;
            Ok(())
        }
        Some("bench") => bench(num(1, 64), num(2, 150).max(2)),
        _ => Err("usage: bank_demo write OUT.bank [MODES] [GRID] | bench [MODES] [GRID]".into()),
    }
}
