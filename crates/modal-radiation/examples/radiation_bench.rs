//! Cost and accuracy of one radiation solve on the sphere (BENCHMARKS.md):
//! panels × ka → seconds for assembly + LU, for the multipole fit, and the
//! level error against the closed form of a Y_2^0 field
//! (`p = iρ₀c h_2(kr)/h_2'(ka) Y_2^0`).
//!
//! `cargo run --release -p modal-radiation --example radiation_bench [max_subdiv]`
use std::time::Instant;

use modal_radiation::special::{
    lm_index, spherical_hankel, spherical_hankel_derivative, spherical_harmonics,
};
use modal_radiation::{c64, multipole, solve, Air, BoundaryMesh, Formulation};

fn main() {
    let max_subdiv: u32 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(3);
    let a = 0.1;
    let air = Air::default();
    println!(
        "| panels | ka | k·h | solve s | fit s | order | level error dB (max over 6 points at r = 2a) |"
    );
    println!("|---|---|---|---|---|---|---|");
    for subdiv in 2..=max_subdiv {
        let (v, t) = modal_mesh::icosphere(subdiv);
        let mesh = BoundaryMesh::new(v.iter().map(|p| p.map(|x| a * x)).collect(), &t).unwrap();
        let h = mesh.panels.iter().map(|p| p.diameter).fold(0.0, f64::max);
        for ka in [0.5, 2.0, 6.0] {
            let k: f64 = ka / a;
            let f = k * air.sound_speed_m_s / (2.0 * std::f64::consts::PI);
            let vn: Vec<c64> =
                mesh.panels.iter().map(|p| spherical_harmonics(2, p.centroid)[lm_index(2, 0)]).collect();
            let t0 = Instant::now();
            let s = solve(&mesh, air, f, &[vn], Formulation::BurtonMiller).unwrap().remove(0);
            let solve_s = t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            let mp = multipole::fit(&mesh, std::slice::from_ref(&s), [0.0; 3], multipole::DEFAULT_TOLERANCE)
                .remove(0);
            let fit_s = t1.elapsed().as_secs_f64();
            let hp = spherical_hankel_derivative(2, ka)[2];
            let mut worst = 0.0f64;
            for i in 0..6 {
                let th = 0.3 + 0.45 * i as f64;
                let ph = 1.3 * i as f64;
                let x = [2.0 * a * th.sin() * ph.cos(), 2.0 * a * th.sin() * ph.sin(), 2.0 * a * th.cos()];
                let exact = c64::new(0.0, air.impedance()) * spherical_hankel(2, 2.0 * ka)[2] / hp
                    * spherical_harmonics(2, x)[lm_index(2, 0)];
                if exact.norm() > 1e-9 {
                    let got = s.pressure_at(&mesh, x).unwrap();
                    worst = worst.max((20.0 * (got.norm() / exact.norm()).log10()).abs());
                }
            }
            println!(
                "| {} | {ka} | {:.2} | {solve_s:.2} | {fit_s:.2} | {} | {worst:.3} |",
                mesh.len(),
                k * h,
                mp.order
            );
        }
    }
}
