//! Cross-check against an independent method on non-spherical bodies: the
//! boundary-element solution (Burton–Miller, singular quadrature, LU)
//! against equivalent sources (`mfs`: interior point sources fitted in
//! least squares, QR), at points at least two bounding radii away.

use faer::c64;
use modal_radiation::{mfs, solve, Air, BoundaryMesh, Formulation};

/// Ellipsoid with semi-axes (ax, ay, az) from the icosphere.
fn ellipsoid(ax: f64, ay: f64, az: f64, subdiv: u32) -> BoundaryMesh {
    let (v, t) = modal_mesh::icosphere(subdiv);
    BoundaryMesh::new(v.iter().map(|p| [ax * p[0], ay * p[1], az * p[2]]).collect(), &t).unwrap()
}

fn far_points(r: f64) -> Vec<[f64; 3]> {
    (0..12)
        .map(|i| {
            let th = 0.15 + 0.25 * i as f64;
            let ph = 1.1 * i as f64;
            [r * th.sin() * ph.cos(), r * th.sin() * ph.sin(), r * th.cos()]
        })
        .collect()
}

/// A normal-velocity field as a function of the outward normal.
type Field = fn([f64; 3]) -> c64;

#[test]
fn boundary_elements_agree_with_equivalent_sources_on_ellipsoids() {
    let air = Air::default();
    // A dipole-like, a quadrupole-like and a lumpy field; low and mid ka.
    let fields: [(&str, Field); 3] = [
        ("dipole", |n| c64::new(n[2], 0.0)),
        ("quadrupole", |n| c64::new(n[0] * n[1], 0.0)),
        ("lumpy", |n| c64::new(1.0 + n[0] - 0.5 * n[1] * n[2], 0.3 * n[2])),
    ];
    let mesh = ellipsoid(0.12, 0.08, 0.05, 3);
    let radius = mesh.radius_about([0.0; 3]);
    for f_hz in [300.0, 2000.0] {
        for (name, vfun) in &fields {
            let v: Vec<c64> = mesh.panels.iter().map(|p| vfun(p.normal)).collect();
            let bem = solve(&mesh, air, f_hz, std::slice::from_ref(&v), Formulation::BurtonMiller)
                .unwrap()
                .remove(0);
            let reference = mfs::fit(&mesh, air, f_hz, &|j, _| v[j], 1.5).unwrap();
            assert!(reference.residual < 0.2, "{name} {f_hz} Hz: MFS residual {}", reference.residual);
            let pairs: Vec<(c64, c64)> = far_points(2.0 * radius)
                .into_iter()
                .map(|x| (bem.pressure_at(&mesh, x).unwrap(), reference.pressure_at(x)))
                .collect();
            // Points within 40 dB of the loudest (nodal directions say nothing about level).
            let loudest = pairs.iter().map(|(_, b)| b.norm()).fold(0.0, f64::max);
            let mut errs: Vec<f64> = pairs
                .iter()
                .filter(|(_, b)| b.norm() > 0.01 * loudest)
                .map(|(a, b)| (20.0 * (a.norm() / b.norm()).log10()).abs())
                .collect();
            errs.sort_by(f64::total_cmp);
            let (median, max) = (errs[errs.len() / 2], errs[errs.len() - 1]);
            eprintln!(
                "{name} at {f_hz} Hz: median {median:.3} dB, max {max:.3} dB, MFS residual {:.3}",
                reference.residual
            );
            assert!(median < 0.3 && max < 1.0, "{name} at {f_hz} Hz: median {median:.3} dB, max {max:.3} dB");
        }
    }
}
