//! The Burton–Miller weights of many source points seen from one point,
//! evaluated in SIMD lanes.
//!
//! A row of the system ([`crate::assembly`]) sees most of its source
//! panels from one point (its cluster's centre) by the centroid or the
//! 3-point rule. Each such point costs the formula of
//! [`CoupledKernels::point`]:
//!
//! `a = −G w u [t (d·n_y) − αt (n_x·n_y) − αs (d·n_x)(d·n_y) u]`,
//! `op = −G w [1 − αt (d·n_x) u]`,
//!
//! `G = e^{ikr}/(4πr)`, `u = 1/r²`, `t = ikr − 1`, `αt = −α + kr·iα`,
//! `αs = (3 − k²r²)α − 3kr·iα`. Called point by point, the libm `sincos`
//! call and the scalar complex products were ≈ 40 % of a capped
//! high-frequency solve. Here the points are gathered into columns
//! (structure of arrays) and one loop without calls or branches evaluates
//! them all, with [`crate::sincos`] in place of libm, so the compiler
//! vectorizes it: two lanes on any x86-64, four where the CPU has AVX2
//! (chosen at run time). Each lane does the same IEEE operations in the
//! same order either way, so the result does not depend on the lane width
//! (nor on the thread count).

use faer::c64;

use crate::kernels::CoupledKernels;
use crate::sincos::sin_cos;

const FOUR_PI: f64 = 4.0 * std::f64::consts::PI;

/// Source points gathered for one row: position, normal and weight, the
/// row slot and panel they belong to, and after [`SourcePoints::evaluate`]
/// their weights `a` and `op`.
#[derive(Default)]
pub(crate) struct SourcePoints {
    y: [Vec<f64>; 3],
    n: [Vec<f64>; 3],
    w: Vec<f64>,
    /// Which entry of the row, and which mesh panel, each point adds to.
    pub(crate) owner: Vec<(u32, u32)>,
    a: [Vec<f64>; 2],
    op: [Vec<f64>; 2],
}

impl SourcePoints {
    /// Empties the gathered points, keeping their storage.
    pub(crate) fn clear(&mut self) {
        for v in self.y.iter_mut().chain(&mut self.n) {
            v.clear();
        }
        self.w.clear();
        self.owner.clear();
    }

    /// Number of gathered points.
    pub(crate) fn len(&self) -> usize {
        self.w.len()
    }

    /// Adds a source point `y` (normal `n`, quadrature weight `w`) of panel
    /// `panel`, to be summed into row entry `slot`.
    #[inline]
    pub(crate) fn push(&mut self, y: [f64; 3], n: [f64; 3], w: f64, slot: usize, panel: usize) {
        for k in 0..3 {
            self.y[k].push(y[k]);
            self.n[k].push(n[k]);
        }
        self.w.push(w);
        self.owner.push((slot as u32, panel as u32));
    }

    /// `(a, op)` of gathered point `p` (after [`SourcePoints::evaluate`]).
    #[inline]
    pub(crate) fn weights(&self, p: usize) -> (c64, c64) {
        (c64::new(self.a[0][p], self.a[1][p]), c64::new(self.op[0][p], self.op[1][p]))
    }

    /// Evaluates every gathered point's `(a, op)` seen from `x` (normal
    /// `nx`), no point at `x`, every `k·r` within
    /// [`crate::sincos::MAX_ARGUMENT`].
    pub(crate) fn evaluate(&mut self, kernels: &CoupledKernels, x: [f64; 3], nx: [f64; 3]) {
        let n = self.len();
        for v in self.a.iter_mut().chain(&mut self.op) {
            v.clear();
            v.resize(n, 0.0);
        }
        let coefficients = Coefficients::new(kernels);
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: evaluate_avx2's one requirement, AVX2, was just detected.
            unsafe { evaluate_avx2(&coefficients, x, nx, self) };
            return;
        }
        evaluate_lanes(&coefficients, x, nx, self);
    }
}

/// The kernels' scalars: `k`, `α` and `iα` as real and imaginary parts.
struct Coefficients {
    k: f64,
    alpha: [f64; 2],
    i_alpha: [f64; 2],
}

impl Coefficients {
    fn new(kernels: &CoupledKernels) -> Coefficients {
        let (alpha, i_alpha) = (kernels.alpha(), kernels.i_alpha());
        Coefficients { k: kernels.k(), alpha: [alpha.re, alpha.im], i_alpha: [i_alpha.re, i_alpha.im] }
    }
}

/// [`evaluate_lanes`] compiled for AVX2 (four f64 lanes).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn evaluate_avx2(c: &Coefficients, x: [f64; 3], nx: [f64; 3], pts: &mut SourcePoints) {
    evaluate_lanes(c, x, nx, pts);
}

/// The loop the compiler vectorizes (module doc): every slice cut to the
/// same length so that no bounds check is left inside.
#[inline(always)]
fn evaluate_lanes(c: &Coefficients, x: [f64; 3], nx: [f64; 3], pts: &mut SourcePoints) {
    let n = pts.w.len();
    let (y0, y1, y2) = (&pts.y[0][..n], &pts.y[1][..n], &pts.y[2][..n]);
    let (n0, n1, n2) = (&pts.n[0][..n], &pts.n[1][..n], &pts.n[2][..n]);
    let w = &pts.w[..n];
    let [a_re, a_im] = &mut pts.a;
    let [op_re, op_im] = &mut pts.op;
    let (a_re, a_im, op_re, op_im) = (&mut a_re[..n], &mut a_im[..n], &mut op_re[..n], &mut op_im[..n]);
    let (k, [al_re, al_im], [ia_re, ia_im]) = (c.k, c.alpha, c.i_alpha);
    for i in 0..n {
        let d = [y0[i] - x[0], y1[i] - x[1], y2[i] - x[2]];
        let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let r = r2.sqrt();
        let kr = k * r;
        let (sn, cs) = sin_cos(kr);
        let scale = w[i] / (FOUR_PI * r);
        let (gw_re, gw_im) = (cs * scale, sn * scale);
        let u = 1.0 / r2;
        let dny = d[0] * n0[i] + d[1] * n1[i] + d[2] * n2[i];
        let dnx = d[0] * nx[0] + d[1] * nx[1] + d[2] * nx[2];
        let nxny = nx[0] * n0[i] + nx[1] * n1[i] + nx[2] * n2[i];
        // αt = iα·kr − α, αs = α(3 − k²r²) − iα·3kr.
        let (at_re, at_im) = (ia_re * kr - al_re, ia_im * kr - al_im);
        let (f, g) = (3.0 - kr * kr, 3.0 * kr);
        let (as_re, as_im) = (al_re * f - ia_re * g, al_im * f - ia_im * g);
        // bracket = (−1 + i·kr)(d·n_y) − αt (n_x·n_y) − αs (d·n_x)(d·n_y) u.
        let c3 = dnx * dny * u;
        let br_re = -dny - at_re * nxny - as_re * c3;
        let br_im = kr * dny - at_im * nxny - as_im * c3;
        let (gu_re, gu_im) = (gw_re * u, gw_im * u);
        a_re[i] = -(gu_re * br_re - gu_im * br_im);
        a_im[i] = -(gu_re * br_im + gu_im * br_re);
        // op = −G w (1 − αt (d·n_x) u).
        let e = dnx * u;
        let (m_re, m_im) = (1.0 - at_re * e, -at_im * e);
        op_re[i] = -(gw_re * m_re - gw_im * m_im);
        op_im[i] = -(gw_re * m_im + gw_im * m_re);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batched_weights_equal_the_point_kernel_in_every_lane_width() {
        // Points around x at distances 1 mm – 1 m, with k·r up to ≈ 400.
        let alpha = c64::new(0.0, 1.0 / 300.0);
        let kernels = CoupledKernels::new(300.0, alpha);
        let (x, nx) = ([0.01, -0.02, 0.03], [0.0, 0.6, 0.8]);
        let mut pts = SourcePoints::default();
        let mut want = Vec::new();
        for i in 0..37 {
            let t = i as f64;
            let r = 0.001 * 1.2f64.powf(t);
            let y = [x[0] + r * (0.7 * t).cos(), x[1] + r * (0.7 * t).sin(), x[2] + 0.3 * r];
            let ny = [(0.3 * t).sin(), (0.3 * t).cos(), 0.0];
            let w = 1e-6 * (1.0 + t);
            pts.push(y, ny, w, i % 5, i);
            want.push(kernels.point(x, nx, y, ny, w));
        }
        pts.evaluate(&kernels, x, nx);
        let wide = (0..pts.len()).map(|p| pts.weights(p)).collect::<Vec<_>>();
        // The portable loop (two lanes) gives the same bits as the run-time choice.
        let c = Coefficients::new(&kernels);
        evaluate_lanes(&c, x, nx, &mut pts);
        for (p, (a, op)) in wide.iter().enumerate() {
            assert_eq!((*a, *op), pts.weights(p), "point {p}");
            let (a0, op0) = want[p];
            assert!((a - a0).norm() <= 1e-13 * a0.norm(), "a at point {p}: {a} vs {a0}");
            assert!((op - op0).norm() <= 1e-13 * op0.norm(), "op at point {p}: {op} vs {op0}");
        }
        assert_eq!(pts.owner[36], (1, 36));
    }
}
