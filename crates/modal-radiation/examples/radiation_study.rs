//! Accuracy study on the sphere: level error of the pulsating sphere vs
//! ka and mesh. `cargo run --release -p modal-radiation --example radiation_study`
use modal_radiation::special::{spherical_hankel, spherical_hankel_derivative};
use modal_radiation::{c64, multipole, shapes, solve, Air, BoundaryMesh, Formulation};

fn main() {
    let a = 0.1;
    let air = Air::default();
    for subdiv in [2, 3] {
        let (v, t) = shapes::icosphere(subdiv);
        let mesh = BoundaryMesh::new(v.iter().map(|p| p.map(|x| a * x)).collect(), &t).unwrap();
        for ka in [0.2, 1.0, 3.0, std::f64::consts::PI, 6.0] {
            let k: f64 = ka / a;
            let f = k * air.sound_speed_m_s / (2.0 * std::f64::consts::PI);
            for form in [Formulation::BurtonMiller, Formulation::Conventional] {
                let t0 = std::time::Instant::now();
                let s =
                    solve(&mesh, air, f, &[vec![c64::new(1.0, 0.0); mesh.len()]], form).unwrap().remove(0);
                let dt = t0.elapsed().as_secs_f64();
                let x: [f64; 3] = [0.13, 0.11, 0.17];
                let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
                let exact = c64::new(0.0, air.impedance()) * spherical_hankel(0, k * r)[0]
                    / spherical_hankel_derivative(0, ka)[0];
                let got = s.pressure_at(&mesh, x).unwrap();
                let mp = multipole::fit(&mesh, std::slice::from_ref(&s), [0.0; 3], 0.01).remove(0);
                let pw =
                    0.5 * air.impedance() * 4.0 * std::f64::consts::PI * a * a * ka * ka / (1.0 + ka * ka);
                println!(
                    "n={} ka={ka:.3} {form:?}: level {:+.3} dB phase {:+.4} rad; P_surf/P {:.4} P_mp/P {:.4} order {} ({dt:.2} s)",
                    mesh.len(),
                    20.0 * (got.norm() / exact.norm()).log10(),
                    (got / exact).arg(),
                    s.radiated_power(&mesh) / pw,
                    mp.radiated_power(air) / pw,
                    mp.order
                );
            }
        }
    }
}
