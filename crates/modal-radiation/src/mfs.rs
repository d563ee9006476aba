//! An independent second method for cross-checks: equivalent sources (the
//! method of fundamental solutions).
//!
//! The radiated field is written as point sources inside the body,
//! `p(x) = Σ_s a_s G(x, z_s)`, `G = e^{ikr}/(4πr)`, which satisfies the
//! Helmholtz equation and the radiation condition exactly; the strengths
//! `a_s` are fitted in least squares (Householder QR, faer) so that
//! `∂p/∂n = iωρ₀ v_n` at three interior points of every panel, rows
//! weighted by `√(area/3)`. Source `s` sits at panel `s`'s centroid moved
//! inwards along the normal by `retreat` times the mean panel diameter
//! (halved until the point is inside the body). Nothing is shared with the
//! boundary-element path but the panel geometry and the Green's function:
//! no singular integrals, no Burton–Miller coupling, no LU.
//!
//! It is a reference for smooth, not-too-thin bodies (spheres, ellipsoids,
//! bars with a few panels across); on thin shells the sources crowd and the
//! fit degrades, which is why it is not the production method.

use faer::c64;
use faer::prelude::SolveLstsq;
use faer::Mat;

use crate::bem::Air;
use crate::error::RadiationError;
use crate::geometry::{dot, norm, sub, BoundaryMesh};

/// Barycentric collocation points inside each panel.
const COLLOCATION: [[f64; 3]; 3] =
    [[2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0], [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0]];

/// Fitted equivalent sources of one field.
#[derive(Clone, Debug)]
pub struct EquivalentSources {
    /// Wavenumber [1/m].
    pub wavenumber: f64,
    /// Source positions (inside the body) [m].
    pub positions: Vec<[f64; 3]>,
    /// Source strengths [Pa·m].
    pub strengths: Vec<c64>,
    /// Relative least-squares residual of the normal-derivative fit.
    pub residual: f64,
}

impl EquivalentSources {
    /// Pressure at `x` [Pa].
    pub fn pressure_at(&self, x: [f64; 3]) -> c64 {
        let k = self.wavenumber;
        self.positions
            .iter()
            .zip(&self.strengths)
            .map(|(z, a)| {
                let r = norm(sub(x, *z));
                a * c64::new((k * r).cos(), (k * r).sin()) / (4.0 * std::f64::consts::PI * r)
            })
            .sum()
    }
}

/// Fits equivalent sources to the normal velocity `vn(panel, barycentric)`
/// [m/s] at `frequency_hz`.
pub fn fit(
    mesh: &BoundaryMesh,
    air: Air,
    frequency_hz: f64,
    vn: &dyn Fn(usize, [f64; 3]) -> c64,
    retreat: f64,
) -> Result<EquivalentSources, RadiationError> {
    // The air and the frequency; the velocity is a function here, no list.
    crate::bem::check_problem(air, frequency_hz, mesh.len(), &[])?;
    let omega = 2.0 * std::f64::consts::PI * frequency_hz;
    let k = omega / air.sound_speed_m_s;
    let iwr = c64::new(0.0, omega * air.density_kg_m3);
    let mean_diam = mesh.panels.iter().map(|p| p.diameter).sum::<f64>() / mesh.len() as f64;
    let positions: Vec<[f64; 3]> = mesh
        .panels
        .iter()
        .map(|p| {
            let mut d = retreat * mean_diam;
            loop {
                let z = [0, 1, 2].map(|q| p.centroid[q] - d * p.normal[q]);
                if mesh.contains(z) || d < 1e-3 * mean_diam {
                    return z;
                }
                d *= 0.5;
            }
        })
        .collect();
    let rows = 3 * mesh.len();
    let mut a = Mat::<c64>::zeros(rows, positions.len());
    let mut b = Mat::<c64>::zeros(rows, 1);
    for (j, p) in mesh.panels.iter().enumerate() {
        let corners = p.corners.map(|i| mesh.vertices[i]);
        let w = (p.area / 3.0).sqrt();
        for (c, bary) in COLLOCATION.iter().enumerate() {
            let row = 3 * j + c;
            let y = crate::quadrature::on_triangle(*bary, corners);
            for (s, z) in positions.iter().enumerate() {
                let d = sub(y, *z);
                let r = norm(d);
                let g = c64::new((k * r).cos(), (k * r).sin()) / (4.0 * std::f64::consts::PI * r);
                // ∂G/∂n_y = G (ik − 1/r) (d·n)/r
                a[(row, s)] = g * c64::new(-1.0 / r, k) * (dot(d, p.normal) / r) * w;
            }
            b[(row, 0)] = vn(j, *bary) * iwr * w;
        }
    }
    let x = a.qr().solve_lstsq(&b);
    let fitted = &a * &x;
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..rows {
        num += (fitted[(i, 0)] - b[(i, 0)]).norm_sqr();
        den += b[(i, 0)].norm_sqr();
    }
    Ok(EquivalentSources {
        wavenumber: k,
        positions,
        strengths: (0..x.nrows()).map(|i| x[(i, 0)]).collect(),
        residual: if den > 0.0 { (num / den).sqrt() } else { 0.0 },
    })
}
