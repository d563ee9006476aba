//! Compact far-field representation: an outgoing multipole expansion about
//! a centre `c`,
//!
//! `p(x) = Σ_{l ≤ L} Σ_{|m| ≤ l} a_lm h_l(k|x − c|) Y_l^m(x̂)`, `x̂ = (x − c)/|x − c|`,
//!
//! valid outside the sphere of radius `R` (the body's radius about `c`).
//!
//! The coefficients are the exact projection of the boundary solution's
//! representation formula, with no sampling and no fit: for `|x − c| >
//! |y − c|` the addition theorem
//! `G(x, y) = ik Σ_lm h_l(k|x − c|) Y_l^m(x̂) j_l(k|y − c|) Y_l^m*(ŷ)`
//! turns `p(x) = ∫_S [p ∂G/∂n_y − G q] dS_y` into
//!
//! `a_lm = ik ∫_S [p(y) ∂/∂n_y ψ_lm*(y) − q(y) ψ_lm*(y)] dS_y`,
//! `ψ_lm(y) = j_l(k|y − c|) Y_l^m(ŷ)` (regular spherical waves),
//!
//! integrated with the 3-point rule (degree 2) on every panel: O(N·L²)
//! work for N panels and degree L. `ψ` and `∂ψ/∂n` come from the two
//! points `y ± δn`, `δ = 10⁻⁴ min(1/k, R)`: their mean and central
//! difference (truncation ≈ 10⁻⁸ relative, rounding ≈ 10⁻¹²).
//!
//! The order `L` is the smallest with the tail's mean-square pressure on
//! the sphere `r_fit = 2R`, `Σ_{l>L} Σ_m |a_lm h_l(k r_fit)|²` (Parseval),
//! at most `tol²` times the total: the stated error is a relative RMS
//! pressure error ≤ `tol` on that sphere (and smaller beyond it, since the
//! higher degrees fall off faster with `r`). Degrees up to `⌈kR⌉ + 16` are
//! projected (the tail at `2R` falls like `2^{−l}` beyond `kR`). Far away
//! `h_l(kr) → (−i)^{l+1} e^{ikr}/(kr)`, so the radiated power is
//! `P = Σ |a_lm|² / (2ρ₀c k²)`.

use faer::c64;

use crate::bem::{Air, SurfaceField};
use crate::geometry::{norm, sub, BoundaryMesh};
use crate::quadrature::{on_triangle, TRIANGLE_3};
use crate::special::{lm_index, spherical_bessel_j, spherical_hankel, spherical_harmonics, Harmonics};

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

    /// RMS of the far-field pattern over all directions [Pa·m]:
    /// `√(Σ|a_lm|²/4π)/k`, since `|h_l(kr)| → 1/(kr)` and the `Y_l^m` are
    /// orthonormal on the unit sphere.
    pub fn far_field_rms(&self) -> f64 {
        let sum: f64 = self.coefficients.iter().map(|a| a.norm_sqr()).sum();
        (sum / (4.0 * std::f64::consts::PI)).sqrt() / self.wavenumber
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

/// The fit radius in body radii (the largest distance of a surface node
/// from the expansion centre): the truncation error is stated there.
pub const FIT_RADIUS_PER_BODY_RADIUS: f64 = 2.0;

/// Multipole expansions about `centre` of solutions that share one
/// wavenumber, by exact projection, truncated to relative RMS error `tol`
/// at twice the body radius (see the module doc). The work is split in
/// fixed chunks of panels summed in order: bit-identical for any thread
/// count.
pub fn fit(mesh: &BoundaryMesh, fields: &[SurfaceField], centre: [f64; 3], tol: f64) -> Vec<Multipole> {
    use rayon::prelude::*;
    let Some(first) = fields.first() else { return Vec::new() };
    let k = first.wavenumber;
    let radius = mesh.radius_about(centre);
    let fit_radius = FIT_RADIUS_PER_BODY_RADIUS * radius;
    let cap = (k * radius).ceil() as usize + EXTRA_DEGREES;
    let ncoef = (cap + 1) * (cap + 1);
    let delta = 1e-4 * (1.0 / k).min(radius);
    let nf = fields.len();
    let zero = c64::new(0.0, 0.0);
    let harmonics = Harmonics::new(cap);
    // ψ_lm*(y) for every (l, m), into `out`.
    let regular = |y: [f64; 3], out: &mut [c64]| {
        let d = sub(y, centre);
        let r = norm(d);
        let j = spherical_bessel_j(cap, k * r);
        harmonics.evaluate(if r > 0.0 { d } else { [0.0, 0.0, 1.0] }, out);
        for (l, jl) in j.iter().enumerate() {
            for v in &mut out[l * l..(l + 1) * (l + 1)] {
                *v = v.conj() * jl;
            }
        }
    };
    const CHUNK: usize = 64;
    let partial: Vec<Vec<c64>> = mesh
        .panels
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let mut acc = vec![zero; nf * ncoef];
            // ψ* at y + δn and y − δn, then their difference and sum.
            let (mut plus, mut minus) = (vec![zero; ncoef], vec![zero; ncoef]);
            for (o, p) in chunk.iter().enumerate() {
                let j = c * CHUNK + o;
                let t = p.corners.map(|i| mesh.vertices[i]);
                for (bary, w) in TRIANGLE_3 {
                    let y = on_triangle(bary, t);
                    regular([0, 1, 2].map(|q| y[q] + delta * p.normal[q]), &mut plus);
                    regular([0, 1, 2].map(|q| y[q] - delta * p.normal[q]), &mut minus);
                    for (u, v) in plus.iter_mut().zip(minus.iter_mut()) {
                        (*u, *v) = (*u - *v, *u + *v);
                    }
                    let (difference, sum) = (&plus, &minus);
                    let wa = w * p.area;
                    for (f, field) in fields.iter().enumerate() {
                        let pw = field.pressure[j] * (wa / (2.0 * delta));
                        let qw = field.dpdn(j) * (0.5 * wa);
                        let out = &mut acc[f * ncoef..(f + 1) * ncoef];
                        for i in 0..ncoef {
                            out[i] += pw * difference[i] - qw * sum[i];
                        }
                    }
                }
            }
            acc
        })
        .collect();
    let ik = c64::new(0.0, k);
    let h = spherical_hankel(cap, k * fit_radius);
    (0..nf)
        .map(|f| {
            let mut a = vec![zero; ncoef];
            for part in &partial {
                for (ai, v) in a.iter_mut().zip(&part[f * ncoef..(f + 1) * ncoef]) {
                    *ai += v;
                }
            }
            // a_lm h_l(k r_fit): the degree energies on the fit sphere.
            let energy: Vec<f64> = (0..=cap)
                .map(|l| (-(l as i64)..=l as i64).map(|m| (a[lm_index(l, m)] * ik * h[l]).norm_sqr()).sum())
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
            let coefficients = a[..(order + 1) * (order + 1)].iter().map(|v| v * ik).collect();
            Multipole { centre, wavenumber: k, fit_radius, order, coefficients }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `far_field_rms` is the RMS of `far_field` over the sphere (Fibonacci
    /// directions), and `far_field` is `r·e^{−ikr}·p` far away.
    #[test]
    fn far_field_rms_is_the_pattern_averaged_over_directions() {
        let order = 3;
        let coefficients = (0..(order + 1) * (order + 1))
            .map(|j| c64::new((j as f64 * 0.7).sin(), 0.2 * j as f64 - 1.0))
            .collect();
        let mp =
            Multipole { centre: [0.1, 0.0, -0.2], wavenumber: 15.0, fit_radius: 0.4, order, coefficients };
        let n = 4000;
        let mean_square: f64 = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let phi = i as f64 * std::f64::consts::PI * (3.0 - 5f64.sqrt());
                let s = (1.0 - z * z).sqrt();
                mp.far_field([s * phi.cos(), s * phi.sin(), z]).norm_sqr()
            })
            .sum::<f64>()
            / n as f64;
        let rms = mp.far_field_rms();
        assert!((mean_square.sqrt() - rms).abs() < 1e-3 * rms, "{} vs {rms}", mean_square.sqrt());
        let (d, r) = ([0.6, 0.0, 0.8], 1e4);
        let x = [0, 1, 2].map(|q| mp.centre[q] + d[q] * r);
        let phase = c64::new(0.0, -mp.wavenumber * r).exp();
        let far = mp.pressure_at(x) * r * phase;
        assert!((far - mp.far_field(d)).norm() < 1e-3 * mp.far_field(d).norm());
    }
}
