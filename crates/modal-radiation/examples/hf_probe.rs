//! Is a high-frequency shortcut good enough? The local plane-wave
//! impedance approximation takes the surface pressure as `p = ρ₀c v_n`
//! (exact for a plane wave leaving a flat surface, the limit of a
//! supersonic mode, `k ≫ k_s`) instead of solving the boundary integral
//! equation, and projects it to multipoles like the solve's result
//! ([`modal_radiation::multipole::fit`]). This probe compares the two far
//! fields per mode: radiated power, and the level in 400 directions
//! (Fibonacci sphere) within 40 dB of the loudest (BENCHMARKS.md
//! "High-frequency shortcut, measured and rejected").
//!
//! `cargo run --release -p modal-radiation --example hf_probe -- BANK MODE[,MODE…]`
use modal_bank::ModeBank;
use modal_radiation::multipole::fit;
use modal_radiation::{c64, radiate_modes, RadiationOptions, SurfaceField};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, bank, modes] = &args[..] else {
        eprintln!("usage: hf_probe BANK MODE[,MODE…]");
        std::process::exit(2);
    };
    let bank = ModeBank::load(std::path::Path::new(bank)).expect("bank");
    let modes: Vec<usize> = modes.split(',').map(|s| s.trim().parse().expect("mode index")).collect();
    let opts = RadiationOptions::default();
    let t = std::time::Instant::now();
    let rads = radiate_modes(&bank, &modes, &opts, &mut |p| eprintln!("{p}")).expect("radiate");
    eprintln!("bem {:.1} s", t.elapsed().as_secs_f64());
    // Fibonacci sphere: n nearly uniform directions.
    let n = 400;
    let dirs: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let phi = i as f64 * std::f64::consts::PI * (3.0 - 5f64.sqrt());
            let s = (1.0 - z * z).sqrt();
            [s * phi.cos(), s * phi.sin(), z]
        })
        .collect();
    for r in &rads {
        let s = &r.surface;
        let zc = s.air.impedance();
        let approx = SurfaceField {
            pressure: s.normal_velocity.iter().map(|v| v * zc).collect::<Vec<c64>>(),
            ..s.clone()
        };
        let t = std::time::Instant::now();
        let m2 = fit(&r.mesh, &[approx], r.multipole.centre, opts.multipole_tolerance).remove(0);
        let fit_s = t.elapsed().as_secs_f64();
        let p1 = r.multipole.radiated_power(s.air);
        let p2 = m2.radiated_power(s.air);
        let a: Vec<f64> = dirs.iter().map(|&d| r.multipole.far_field(d).norm()).collect();
        let b: Vec<f64> = dirs.iter().map(|&d| m2.far_field(d).norm()).collect();
        let top = a.iter().cloned().fold(0.0, f64::max);
        // Directions within 40 dB of the loudest, as in the cross-check.
        let mut errs: Vec<f64> = a
            .iter()
            .zip(&b)
            .filter(|(x, _)| **x >= top * 0.01)
            .map(|(x, y)| (20.0 * (y / x).log10()).abs())
            .collect();
        errs.sort_by(|x, y| x.total_cmp(y));
        println!(
            "mode {} {:.0} Hz eff {:.3}: power {:+.2} dB, dir median {:.2} max {:.2} dB ({} dirs), fit {:.2} s",
            r.mode,
            r.frequency_hz,
            r.efficiency,
            10.0 * (p2 / p1).log10(),
            errs[errs.len() / 2],
            errs[errs.len() - 1],
            errs.len(),
            fit_s
        );
    }
}
