//! Compact far-field representation: an outgoing multipole expansion about
//! a centre `c`,
//!
//! `p(x) = Σ_{l ≤ L} Σ_{|m| ≤ l} a_lm h_l(k|x − c|) Y_l^m(x̂)`, `x̂ = (x − c)/|x − c|`,
//!
//! valid outside the sphere of radius `R` (the body's radius about `c`).
//! The coefficients are fitted on the sphere of radius `r_fit = 2R`, where
//! orthonormality gives `a_lm h_l(k r_fit) = ∫ p Y_l^m* dΩ`
//! (Gauss–Legendre in cos θ × trapezoid in φ, exact for degrees up to the
//! cap), with `p` from the boundary solution's representation formula.
//! Fitting at `r_fit` rather than from the far-field pattern keeps the
//! near-field terms accurate at low `kR`, where `h_l` is huge and the
//! far-field coefficients of high degree drown in rounding.
//!
//! The order `L` is the smallest with the tail's mean-square pressure on
//! the fit sphere `Σ_{l>L} Σ_m |a_lm h_l(k r_fit)|²` at most `tol²` times
//! the total (Parseval): the stated error is a relative RMS pressure error
//! ≤ `tol` on the sphere `r = r_fit` (and smaller beyond it, since the
//! higher degrees fall off faster with `r`). Far away
//! `h_l(kr) → (−i)^{l+1} e^{ikr}/(kr)`, so the radiated power is
//! `P = Σ |a_lm|² / (2ρ₀c k²)`.

use faer::c64;

use crate::bem::{Air, SurfaceField};
use crate::geometry::{norm, sub, BoundaryMesh};
use crate::kernels::Kernels;
use crate::quadrature::{gauss_legendre, TRIANGLE_7};
use crate::special::{lm_index, spherical_hankel, spherical_harmonics};

/// Extra degrees above `kR` in the fit (the near-field tail at
/// `r_fit = 2R` falls like `2^{−l}`, so 16 more degrees reach ≈ 1e-5).
pub const EXTRA_DEGREES: usize = 16;
/// Default relative RMS pressure error of the truncation at `r_fit`.
pub const DEFAULT_TOLERANCE: f64 = 0.01;

/// Outgoing multipole expansion of one radiating field.
#[derive(Clone, Debug, PartialEq)]
pub struct Multipole {
    /// Expansion centre [m].
    pub centre: [f64; 3],
    /// Wavenumber k [1/m].
    pub wavenumber: f64,
    /// Radius the coefficients were fitted at (2× the body radius) [m].
    pub fit_radius: f64,
    /// Highest degree L.
    pub order: usize,
    /// `a_lm` at index `l² + l + m` [Pa], `(L+1)²` values.
    pub coefficients: Vec<c64>,
}

impl Multipole {
    /// Pressure at `x` [Pa] (meaningful for `|x − c| ≥ fit_radius / 2`,
    /// accurate to the stated tolerance for `|x − c| ≥ fit_radius`).
    pub fn pressure_at(&self, x: [f64; 3]) -> c64 {
        let d = sub(x, self.centre);
        let r = norm(d);
        let h = spherical_hankel(self.order, self.wavenumber * r);
        let y = spherical_harmonics(self.order, d);
        let mut p = c64::new(0.0, 0.0);
        for (l, hl) in h.iter().enumerate() {
            for m in -(l as i64)..=l as i64 {
                let i = lm_index(l, m);
                p += self.coefficients[i] * hl * y[i];
            }
        }
        p
    }

    /// Far-field pattern `F(d̂)` with `p ≈ F e^{ikr}/r` [Pa·m].
    pub fn far_field(&self, direction: [f64; 3]) -> c64 {
        let y = spherical_harmonics(self.order, direction);
        let mut f = c64::new(0.0, 0.0);
        let mut phase = c64::new(0.0, -1.0); // (−i)^{l+1}
        for l in 0..=self.order {
            for m in -(l as i64)..=l as i64 {
                let i = lm_index(l, m);
                f += self.coefficients[i] * y[i] * phase;
            }
            phase *= c64::new(0.0, -1.0);
        }
        f / self.wavenumber
    }

    /// Radiated power `Σ|a_lm|² / (2ρ₀c k²)` [W].
    pub fn radiated_power(&self, air: Air) -> f64 {
        let s: f64 = self.coefficients.iter().map(|a| a.norm_sqr()).sum();
        s / (2.0 * air.impedance() * self.wavenumber * self.wavenumber)
    }

    /// Mean-square pressure on the fit sphere carried by each degree
    /// `l = 0..=L` [Pa²] (times 4π).
    pub fn degree_energies(&self) -> Vec<f64> {
        let h = spherical_hankel(self.order, self.wavenumber * self.fit_radius);
        (0..=self.order)
            .map(|l| {
                (-(l as i64)..=l as i64)
                    .map(|m| self.coefficients[lm_index(l, m)].norm_sqr() * h[l].norm_sqr())
                    .sum()
            })
            .collect()
    }
}

/// Fits multipole expansions about `centre` to solutions that share one
/// wavenumber, truncated to relative RMS error `tol` at twice the body
/// radius (see the module doc).
pub fn fit(mesh: &BoundaryMesh, fields: &[SurfaceField], centre: [f64; 3], tol: f64) -> Vec<Multipole> {
    let Some(first) = fields.first() else { return Vec::new() };
    let k = first.wavenumber;
    let radius = mesh.radius_about(centre);
    let fit_radius = 2.0 * radius;
    let cap = (k * radius).ceil() as usize + EXTRA_DEGREES;
    let (nt, np) = (cap + 1, 2 * cap + 2);
    let (ct, wt) = gauss_legendre(nt);
    let points: Vec<([f64; 3], f64)> = ct
        .iter()
        .zip(&wt)
        .flat_map(|(&c, &w)| {
            let s = (1.0 - c * c).max(0.0).sqrt();
            (0..np).map(move |j| {
                let phi = 2.0 * std::f64::consts::PI * j as f64 / np as f64;
                ([s * phi.cos(), s * phi.sin(), c], w * 2.0 * std::f64::consts::PI / np as f64)
            })
        })
        .collect();
    let sources = SourcePoints::new(mesh, k);
    let h = spherical_hankel(cap, k * fit_radius);
    let ncoef = (cap + 1) * (cap + 1);
    let mut raw = vec![vec![c64::new(0.0, 0.0); ncoef]; fields.len()];
    let samples: Vec<Vec<c64>> = {
        use rayon::prelude::*;
        points
            .par_iter()
            .map(|(u, _)| {
                let x = [0, 1, 2].map(|q| centre[q] + fit_radius * u[q]);
                sources.pressures(x, fields)
            })
            .collect()
    };
    for ((u, w), p) in points.iter().zip(&samples) {
        let y = spherical_harmonics(cap, *u);
        for (f, pf) in p.iter().enumerate() {
            for (a, yv) in raw[f].iter_mut().zip(&y) {
                *a += pf * yv.conj() * *w;
            }
        }
    }
    raw.into_iter()
        .map(|proj| {
            // proj[lm] = a_lm h_l(k r_fit): choose L from its energies.
            let energy: Vec<f64> = (0..=cap)
                .map(|l| (-(l as i64)..=l as i64).map(|m| proj[lm_index(l, m)].norm_sqr()).sum())
                .collect();
            let total: f64 = energy.iter().sum();
            let mut order = cap;
            let mut tail = 0.0;
            for l in (1..=cap).rev() {
                if tail + energy[l] > tol * tol * total {
                    break;
                }
                tail += energy[l];
                order = l - 1;
            }
            let coefficients = (0..(order + 1) * (order + 1))
                .map(|i| {
                    let l = (i as f64).sqrt() as usize;
                    proj[i] / h[l]
                })
                .collect();
            Multipole { centre, wavenumber: k, fit_radius, order, coefficients }
        })
        .collect()
}

/// Quadrature points of every panel for field evaluation away from the
/// surface (7 per panel).
struct SourcePoints {
    kern: Kernels,
    /// (point, outward normal, weight·area, panel index)
    points: Vec<([f64; 3], [f64; 3], f64, usize)>,
}

impl SourcePoints {
    fn new(mesh: &BoundaryMesh, k: f64) -> SourcePoints {
        let mut points = Vec::with_capacity(mesh.len() * TRIANGLE_7.len());
        for (j, p) in mesh.panels.iter().enumerate() {
            let [a, b, c] = p.corners.map(|i| mesh.vertices[i]);
            for (bary, w) in TRIANGLE_7 {
                let y = [0, 1, 2].map(|q| bary[0] * a[q] + bary[1] * b[q] + bary[2] * c[q]);
                points.push((y, p.normal, w * p.area, j));
            }
        }
        SourcePoints { kern: Kernels::new(k), points }
    }

    /// Pressure of every field at `x` (far enough from the surface for the
    /// 7-point rule: at least a panel diameter or two).
    fn pressures(&self, x: [f64; 3], fields: &[SurfaceField]) -> Vec<c64> {
        let mut p = vec![c64::new(0.0, 0.0); fields.len()];
        for &(y, ny, w, j) in &self.points {
            let i = self.kern.point(x, [0.0, 0.0, 1.0], y, ny, w);
            for (pf, f) in p.iter_mut().zip(fields) {
                *pf += f.pressure[j] * i.dg_dny - f.dpdn(j) * i.g;
            }
        }
        p
    }
}
