//! The Burton–Miller weights of many source points, each seen from its
//! own point, evaluated in SIMD lanes.
//!
//! A row of the system ([`crate::assembly`]) sees most source panels from
//! its cluster's centre or a member centroid by the centroid or the
//! 3-point rule, and its near pairs add a 7-point remainder. Each such
//! point costs one of two formulas, with `G = e^{ikr}/(4πr)`, `u = 1/r²`,
//! `t = ikr − 1`, `αt = −α + kr·iα`, `αs = (3 − k²r²)α − 3kr·iα`:
//!
//! - **coupled** ([`CoupledKernels::point`]):
//!   `a = −G w u [t (d·n_y) − αt (n_x·n_y) − αs (d·n_x)(d·n_y) u]`,
//!   `op = −G w [1 − αt (d·n_x) u]`;
//! - **remainder** (the kernels minus their `k⁰`, `k²` terms,
//!   [`crate::kernels::Kernels::remainder`]): `a = −(R_{∂G/∂n_y} + α R_{∂²G})`,
//!   `op = −(R_G + α R_{∂G/∂n_x})` with `e = e^{ikr}`, `h = k²r²/2`,
//!   `R_G = (e − 1) w/(4πr)`, `R_{∂G/∂n_y} = −R_{∂G/∂n_x}·(d·n_y)/(d·n_x) =
//!   [e(ikr − 1) + 1 + h](d·n_y) w/(4πr³)`,
//!   `R_{∂²G} = {[e(1 − ikr) − 1 − h] n_x·n_y − [e(3 − 3ikr − k²r²) − 3 − h]
//!   (d·n_x)(d·n_y)/r²} w/(4πr³)`.
//!
//! Called point by point, the libm `sincos` call and the scalar complex
//! products were ≈ 40 % of a capped high-frequency solve. Here the points
//! are gathered into columns (structure of arrays) and one loop without
//! calls or branches evaluates them all, with [`crate::sincos`] in place
//! of libm, so the compiler vectorizes it: two lanes on any x86-64, four
//! where the CPU has AVX2 (chosen at run time). Each lane does the same
//! IEEE operations in the same order either way, so the result does not
//! depend on the lane width (nor on the thread count).

use std::ops::Range;

use faer::c64;

use crate::kernels::CoupledKernels;
use crate::sincos::{sin_cos, MAX_ARGUMENT};

const FOUR_PI: f64 = 4.0 * std::f64::consts::PI;

/// Which kernels a batch of points evaluates (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Formula {
    /// The whole coupled kernels.
    Coupled,
    /// The near pairs' remainder.
    Remainder,
    /// The coupled kernels' coefficients for a source normal given later:
    /// `a(n_y) = P (d·n_y) + Q (n_x·n_y)` (`a` is linear in `n_y`), with
    /// `P = −G w u (t − αs (d·n_x) u)`, `Q = G w u αt`, and `op`. The far
    /// cluster sums of [`crate::assembly`] apply it to a summed normal and
    /// to dipole moments.
    Linear,
}

const COUPLED: u8 = 0;
const REMAINDER: u8 = 1;
const LINEAR: u8 = 2;

/// Source points gathered for one row: the point and normal each is seen
/// from, its position, normal and weight, the row slot and panel it
/// belongs to, and after [`SourcePoints::evaluate`] its weights `a`, `op`.
#[derive(Default)]
pub(crate) struct SourcePoints {
    /// The points as columns, [`CHUNK`] to a block; blocks are kept when
    /// cleared, so a thread allocates them once.
    chunks: Vec<Box<Columns>>,
    len: usize,
    /// Row entry and panel (or cluster) of each point.
    owner: Vec<(u32, u32)>,
    /// `a` (or `P`), `op` and `Q` of the points (real, imaginary), first
    /// `len()` valid (`Q` by [`Formula::Linear`] alone).
    a: [Vec<f64>; 2],
    op: [Vec<f64>; 2],
    q: [Vec<f64>; 2],
}

/// Points per block of columns: a block's columns stay in L1.
const CHUNK: usize = 64;

impl SourcePoints {
    /// Empties the gathered points, keeping their storage.
    pub(crate) fn clear(&mut self) {
        self.len = 0;
        self.owner.clear();
    }

    /// Number of gathered points.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Adds a source point `y` (normal `n`, quadrature weight `w`) of panel
    /// `panel` (or the cluster it stands for) seen from `x` (normal `nx`),
    /// to be summed into row entry `slot`.
    #[inline]
    pub(crate) fn push(
        &mut self,
        (x, nx): ([f64; 3], [f64; 3]),
        y: [f64; 3],
        n: [f64; 3],
        w: f64,
        slot: usize,
        panel: usize,
    ) {
        let (block, i) = (self.len / CHUNK, self.len % CHUNK);
        if block == self.chunks.len() {
            self.chunks.push(Box::default());
        }
        let cols = &mut self.chunks[block];
        for k in 0..3 {
            cols.x[k][i] = x[k];
            cols.nx[k][i] = nx[k];
            cols.y[k][i] = y[k];
            cols.n[k][i] = n[k];
        }
        cols.w[i] = w;
        self.len += 1;
        self.owner.push((slot as u32, panel as u32));
    }

    /// The row entry and mesh panel (or cluster) of each gathered point, in
    /// order.
    pub(crate) fn owners(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.owner.iter().map(|&(slot, panel)| (slot as usize, panel as usize))
    }

    /// `(a, op)` of gathered point `p` (after [`SourcePoints::evaluate`]).
    #[inline]
    pub(crate) fn weights(&self, p: usize) -> (c64, c64) {
        (c64::new(self.a[0][p], self.a[1][p]), c64::new(self.op[0][p], self.op[1][p]))
    }

    /// `(P, Q, op)` of gathered point `p` (after [`SourcePoints::evaluate`]
    /// by [`Formula::Linear`]).
    #[inline]
    pub(crate) fn linear_weights(&self, p: usize) -> (c64, c64, c64) {
        let (a, op) = self.weights(p);
        (a, c64::new(self.q[0][p], self.q[1][p]), op)
    }

    /// Evaluates every gathered point's `(a, op)` by `formula`; no point
    /// at its observer. A block with some `k·r` beyond
    /// [`crate::sincos::MAX_ARGUMENT`] (a field point far away) is
    /// evaluated again with libm's `sin_cos`.
    pub(crate) fn evaluate(&mut self, kernels: &CoupledKernels, formula: Formula) {
        self.evaluate_by(kernels, formula, Trig::Polynomial);
    }

    /// [`SourcePoints::evaluate`] with `trig`.
    fn evaluate_by(&mut self, kernels: &CoupledKernels, formula: Formula, trig: Trig) {
        let n = self.len();
        for v in self.a.iter_mut().chain(&mut self.op).chain(&mut self.q) {
            if v.len() < n {
                v.resize(n, 0.0);
            }
        }
        for start in (0..n).step_by(CHUNK) {
            let end = n.min(start + CHUNK);
            if !self.evaluate_block(kernels, formula, trig, start..end) {
                self.evaluate_block(kernels, formula, Trig::Libm, start..end);
            }
        }
    }

    /// Points `range` (one block of columns) by `formula` with `trig`;
    /// false when some `k·r` was beyond the polynomial `sin_cos`'s range.
    fn evaluate_block(
        &mut self,
        c: &CoupledKernels,
        formula: Formula,
        trig: Trig,
        range: Range<usize>,
    ) -> bool {
        let columns = (&*self.chunks[range.start / CHUNK], range.len());
        let ([a_re, a_im], [op_re, op_im], [q_re, q_im]) = (&mut self.a, &mut self.op, &mut self.q);
        let out = Outputs {
            a: [&mut a_re[range.clone()], &mut a_im[range.clone()]],
            op: [&mut op_re[range.clone()], &mut op_im[range.clone()]],
            q: [&mut q_re[range.clone()], &mut q_im[range]],
        };
        match formula {
            Formula::Coupled => evaluate_with::<COUPLED>(c, columns, out, trig),
            Formula::Remainder => evaluate_with::<REMAINDER>(c, columns, out, trig),
            Formula::Linear => evaluate_with::<LINEAR>(c, columns, out, trig),
        }
    }
}

/// [`evaluate_lanes`] of formula `F` with `trig`; false when some `k·r`
/// was beyond the polynomial `sin_cos`'s range.
fn evaluate_with<const F: u8>(
    c: &CoupledKernels,
    (cols, n): (&Columns, usize),
    out: Outputs<'_>,
    trig: Trig,
) -> bool {
    match trig {
        Trig::Libm => evaluate_lanes::<F, true>(c, (cols, n), out),
        Trig::Polynomial => evaluate_polynomial::<F>(c, (cols, n), out),
        #[cfg(test)]
        Trig::PolynomialPortable => evaluate_lanes::<F, false>(c, (cols, n), out),
    }
}

/// The `sin_cos` of an evaluation and how it is compiled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Trig {
    /// libm's, point by point (any argument).
    Libm,
    /// [`crate::sincos`], four lanes where the CPU has AVX2.
    Polynomial,
    /// [`crate::sincos`], two lanes (any x86-64): the tests' reference.
    #[cfg(test)]
    PolynomialPortable,
}

/// A block of points as columns (structure of arrays).
struct Columns {
    x: [[f64; CHUNK]; 3],
    nx: [[f64; CHUNK]; 3],
    y: [[f64; CHUNK]; 3],
    n: [[f64; CHUNK]; 3],
    w: [f64; CHUNK],
}

impl Default for Columns {
    fn default() -> Self {
        let zero = [[0.0; CHUNK]; 3];
        Columns { x: zero, nx: zero, y: zero, n: zero, w: [0.0; CHUNK] }
    }
}

/// Where a chunk's `(a, op)` (and `Q`) go, as real and imaginary parts.
struct Outputs<'a> {
    a: [&'a mut [f64]; 2],
    op: [&'a mut [f64]; 2],
    q: [&'a mut [f64]; 2],
}

/// [`evaluate_lanes`] with the vectorizable `sin_cos`, compiled for AVX2
/// (four f64 lanes) when the CPU has it.
fn evaluate_polynomial<const F: u8>(
    c: &CoupledKernels,
    (cols, n): (&Columns, usize),
    out: Outputs<'_>,
) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: evaluate_avx2's one requirement, AVX2, was just detected.
        return unsafe { evaluate_avx2::<F>(c, (cols, n), out) };
    }
    evaluate_lanes::<F, false>(c, (cols, n), out)
}

/// [`evaluate_lanes`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn evaluate_avx2<const F: u8>(c: &CoupledKernels, (cols, n): (&Columns, usize), out: Outputs<'_>) -> bool {
    evaluate_lanes::<F, false>(c, (cols, n), out)
}

/// The loop the compiler vectorizes (module doc): every slice cut to the
/// same length so that no bounds check is left inside; the formula and
/// the `sin_cos` are chosen at compile time. False when the polynomial
/// `sin_cos` met some `k·r` beyond its range (the results are then wrong).
#[inline(always)]
fn evaluate_lanes<const F: u8, const LIBM: bool>(
    c: &CoupledKernels,
    (cols, n): (&Columns, usize),
    out: Outputs<'_>,
) -> bool {
    let k = c.k();
    let mut beyond = 0u64;
    let (x0, x1, x2) = (&cols.x[0][..n], &cols.x[1][..n], &cols.x[2][..n]);
    let (m0, m1, m2) = (&cols.nx[0][..n], &cols.nx[1][..n], &cols.nx[2][..n]);
    let (y0, y1, y2) = (&cols.y[0][..n], &cols.y[1][..n], &cols.y[2][..n]);
    let (n0, n1, n2) = (&cols.n[0][..n], &cols.n[1][..n], &cols.n[2][..n]);
    let w = &cols.w[..n];
    let Outputs { a: [a_re, a_im], op: [op_re, op_im], q: [q_re, q_im] } = out;
    let (a_re, a_im, op_re, op_im) = (&mut a_re[..n], &mut a_im[..n], &mut op_re[..n], &mut op_im[..n]);
    let (q_re, q_im) = (&mut q_re[..n], &mut q_im[..n]);
    for i in 0..n {
        let observer = ([x0[i], x1[i], x2[i]], [m0[i], m1[i], m2[i]]);
        let point = Point::at::<LIBM>(k, observer, [y0[i], y1[i], y2[i]], [n0[i], n1[i], n2[i]], w[i]);
        beyond |= u64::from(point.kr > MAX_ARGUMENT);
        let (a, op) = match F {
            REMAINDER => point.remainder(c),
            LINEAR => {
                let (p, q, op) = point.linear(c);
                (q_re[i], q_im[i]) = (q[0], q[1]);
                (p, op)
            }
            _ => point.coupled(c),
        };
        (a_re[i], a_im[i], op_re[i], op_im[i]) = (a[0], a[1], op[0], op[1]);
    }
    LIBM || beyond == 0
}

/// One source point's geometry seen from its observer: `k·r`, `e^{ikr}`,
/// `w/(4πr)`, `1/r²`, `d·n_y`, `d·n_x`, `n_x·n_y`.
struct Point {
    kr: f64,
    e: [f64; 2],
    scale: f64,
    u: f64,
    dny: f64,
    dnx: f64,
    nxny: f64,
}

/// A complex number as `[re, im]`.
#[inline(always)]
fn parts(z: c64) -> [f64; 2] {
    [z.re, z.im]
}

/// `(a·b)` of complex numbers as `[re, im]`.
#[inline(always)]
fn mul(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]]
}

impl Point {
    /// Source point `y` (normal `n`, weight `w`) seen from `(x, nx)` at
    /// wavenumber `k`; `LIBM` picks libm's `sin_cos` over
    /// [`crate::sincos`] (valid to [`MAX_ARGUMENT`], the caller checks).
    #[inline(always)]
    fn at<const LIBM: bool>(
        k: f64,
        (x, nx): ([f64; 3], [f64; 3]),
        y: [f64; 3],
        n: [f64; 3],
        w: f64,
    ) -> Point {
        let d = [y[0] - x[0], y[1] - x[1], y[2] - x[2]];
        let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let r = r2.sqrt();
        let kr = k * r;
        let (sn, cs) = if LIBM { kr.sin_cos() } else { sin_cos(kr) };
        Point {
            kr,
            e: [cs, sn],
            scale: w / (FOUR_PI * r),
            u: 1.0 / r2,
            dny: d[0] * n[0] + d[1] * n[1] + d[2] * n[2],
            dnx: d[0] * nx[0] + d[1] * nx[1] + d[2] * nx[2],
            nxny: nx[0] * n[0] + nx[1] * n[1] + nx[2] * n[2],
        }
    }

    /// `(a, op)` of the coupled kernels (module doc).
    #[inline(always)]
    fn coupled(&self, c: &CoupledKernels) -> ([f64; 2], [f64; 2]) {
        let Point { kr, e, scale, u, dny, dnx, nxny } = *self;
        let (al, ia) = (parts(c.alpha()), parts(c.i_alpha()));
        let gw = [e[0] * scale, e[1] * scale];
        let alpha_t = [ia[0] * kr - al[0], ia[1] * kr - al[1]];
        let (f, g) = (3.0 - kr * kr, 3.0 * kr);
        let alpha_s = [al[0] * f - ia[0] * g, al[1] * f - ia[1] * g];
        let c3 = dnx * dny * u;
        let bracket =
            [-dny - alpha_t[0] * nxny - alpha_s[0] * c3, kr * dny - alpha_t[1] * nxny - alpha_s[1] * c3];
        let a = mul([gw[0] * u, gw[1] * u], bracket);
        let e_nx = dnx * u;
        let op = mul(gw, [1.0 - alpha_t[0] * e_nx, -alpha_t[1] * e_nx]);
        ([-a[0], -a[1]], [-op[0], -op[1]])
    }

    /// `(P, Q, op)` of [`Formula::Linear`].
    #[inline(always)]
    fn linear(&self, c: &CoupledKernels) -> ([f64; 2], [f64; 2], [f64; 2]) {
        let Point { kr, e, scale, u, dnx, .. } = *self;
        let (al, ia) = (parts(c.alpha()), parts(c.i_alpha()));
        let gwu = [e[0] * scale * u, e[1] * scale * u];
        let alpha_t = [ia[0] * kr - al[0], ia[1] * kr - al[1]];
        let (f, g) = (3.0 - kr * kr, 3.0 * kr);
        let alpha_s = [al[0] * f - ia[0] * g, al[1] * f - ia[1] * g];
        let e_nx = dnx * u;
        let p = mul(gwu, [-1.0 - alpha_s[0] * e_nx, kr - alpha_s[1] * e_nx]);
        let q = mul(gwu, alpha_t);
        let op = mul([e[0] * scale, e[1] * scale], [1.0 - alpha_t[0] * e_nx, -alpha_t[1] * e_nx]);
        ([-p[0], -p[1]], q, [-op[0], -op[1]])
    }

    /// `(a, op)` of the remainder kernels (module doc).
    #[inline(always)]
    fn remainder(&self, c: &CoupledKernels) -> ([f64; 2], [f64; 2]) {
        let Point { kr, e, scale, u, dny, dnx, nxny } = *self;
        let al = parts(c.alpha());
        let h = 0.5 * kr * kr;
        let su = scale * u;
        // R₁ = [e(ikr − 1) + 1 + h]/(4πr³), times w.
        let t = mul(e, [-1.0, kr]);
        let r1 = [(t[0] + 1.0 + h) * su, t[1] * su];
        let g = [(e[0] - 1.0) * scale, e[1] * scale];
        let dg_dny = [r1[0] * dny, r1[1] * dny];
        let dg_dnx = [-r1[0] * dnx, -r1[1] * dnx];
        let p = mul(e, [1.0, -kr]);
        let q = mul(e, [3.0 - kr * kr, -3.0 * kr]);
        let cdd = dnx * dny * u;
        let d2g = [((p[0] - 1.0 - h) * nxny - (q[0] - 3.0 - h) * cdd) * su, (p[1] * nxny - q[1] * cdd) * su];
        let al_d2g = mul(al, d2g);
        let al_dnx = mul(al, dg_dnx);
        ([-dg_dny[0] - al_d2g[0], -dg_dny[1] - al_d2g[1]], [-g[0] - al_dnx[0], -g[1] - al_dnx[1]])
    }
}

/// Source points kept as columns for the whole assembly (structure of
/// arrays: positions, normals, weights), to be seen from one observer at a
/// time by [`SourceColumns::for_each_coupled`]: the far panels of a source
/// cluster ([`crate::assembly`]) without gathering them point by point.
#[derive(Default)]
pub(crate) struct SourceColumns {
    y: [Vec<f64>; 3],
    n: [Vec<f64>; 3],
    w: Vec<f64>,
}

impl SourceColumns {
    /// Appends source point `y` (normal `n`, weight `w`).
    pub(crate) fn push(&mut self, y: [f64; 3], n: [f64; 3], w: f64) {
        for k in 0..3 {
            self.y[k].push(y[k]);
            self.n[k].push(n[k]);
        }
        self.w.push(w);
    }

    /// Number of points.
    pub(crate) fn len(&self) -> usize {
        self.w.len()
    }

    /// The coupled weights `(a, op)` (module doc) of points `range` seen
    /// from `observer` (point, normal), handed to `sink` with each point's
    /// index in order: the same bits as [`SourcePoints::evaluate`] of the
    /// same points by [`Formula::Coupled`] (the same per-point arithmetic,
    /// [`Point::at`], in lanes [`CHUNK`] at a time; a chunk with some `k·r`
    /// beyond [`MAX_ARGUMENT`] takes libm's `sin_cos`, as a gathered block does).
    pub(crate) fn for_each_coupled(
        &self,
        c: &CoupledKernels,
        observer: ([f64; 3], [f64; 3]),
        range: Range<usize>,
        mut sink: impl FnMut(usize, c64, c64),
    ) {
        let mut out = ChunkWeights::default();
        for start in range.clone().step_by(CHUNK) {
            let part = start..range.end.min(start + CHUNK);
            if !observed_polynomial(c, observer, self.slices(part.clone()), &mut out) {
                observed_lanes::<true>(c, observer, self.slices(part.clone()), &mut out);
            }
            for (i, p) in part.enumerate() {
                sink(p, c64::new(out.a[0][i], out.a[1][i]), c64::new(out.op[0][i], out.op[1][i]));
            }
        }
    }

    /// The columns of points `range`.
    fn slices(&self, range: Range<usize>) -> ObservedSources<'_> {
        let (y, n) = (&self.y, &self.n);
        ObservedSources {
            y: [&y[0][range.clone()], &y[1][range.clone()], &y[2][range.clone()]],
            n: [&n[0][range.clone()], &n[1][range.clone()], &n[2][range.clone()]],
            w: &self.w[range],
        }
    }
}

/// Up to [`CHUNK`] points' columns, all seen from one observer.
struct ObservedSources<'a> {
    y: [&'a [f64]; 3],
    n: [&'a [f64]; 3],
    w: &'a [f64],
}

/// `(a, op)` of up to [`CHUNK`] points, real and imaginary parts.
struct ChunkWeights {
    a: [[f64; CHUNK]; 2],
    op: [[f64; CHUNK]; 2],
}

impl Default for ChunkWeights {
    fn default() -> Self {
        ChunkWeights { a: [[0.0; CHUNK]; 2], op: [[0.0; CHUNK]; 2] }
    }
}

/// [`observed_lanes`] with the polynomial `sin_cos`, compiled for AVX2 when
/// the CPU has it; false when some `k·r` was beyond its range.
fn observed_polynomial(
    c: &CoupledKernels,
    observer: ([f64; 3], [f64; 3]),
    src: ObservedSources<'_>,
    out: &mut ChunkWeights,
) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: observed_avx2's one requirement, AVX2, was just detected.
        return unsafe { observed_avx2(c, observer, src, out) };
    }
    observed_lanes::<false>(c, observer, src, out)
}

/// [`observed_lanes`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn observed_avx2(
    c: &CoupledKernels,
    observer: ([f64; 3], [f64; 3]),
    src: ObservedSources<'_>,
    out: &mut ChunkWeights,
) -> bool {
    observed_lanes::<false>(c, observer, src, out)
}

/// The coupled weights of `src` seen from `observer`, the loop the
/// compiler vectorizes (like [`evaluate_lanes`], whose per-point
/// arithmetic it shares through [`Point::at`]).
#[inline(always)]
fn observed_lanes<const LIBM: bool>(
    c: &CoupledKernels,
    observer: ([f64; 3], [f64; 3]),
    src: ObservedSources<'_>,
    out: &mut ChunkWeights,
) -> bool {
    let (k, n) = (c.k(), src.w.len().min(CHUNK));
    let mut beyond = 0u64;
    let (y0, y1, y2) = (&src.y[0][..n], &src.y[1][..n], &src.y[2][..n]);
    let (n0, n1, n2) = (&src.n[0][..n], &src.n[1][..n], &src.n[2][..n]);
    let w = &src.w[..n];
    let ChunkWeights { a: [a_re, a_im], op: [op_re, op_im] } = out;
    let (a_re, a_im, op_re, op_im) = (&mut a_re[..n], &mut a_im[..n], &mut op_re[..n], &mut op_im[..n]);
    for i in 0..n {
        let point = Point::at::<LIBM>(k, observer, [y0[i], y1[i], y2[i]], [n0[i], n1[i], n2[i]], w[i]);
        beyond |= u64::from(point.kr > MAX_ARGUMENT);
        let (a, op) = point.coupled(c);
        (a_re[i], a_im[i], op_re[i], op_im[i]) = (a[0], a[1], op[0], op[1]);
    }
    LIBM || beyond == 0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::BoundaryMesh;
    use crate::kernels::Kernels;

    /// A point and its normal.
    type Observer = ([f64; 3], [f64; 3]);
    /// A source point, its normal and weight.
    type Source = ([f64; 3], [f64; 3], f64);

    /// Points around `x` at distances 1 mm – 1 m (k·r up to ≈ 400), each
    /// gathered twice, seen from `x` and from a second observer.
    fn gathered(observers: [Observer; 2]) -> (SourcePoints, Vec<Source>) {
        let mut pts = SourcePoints::default();
        let mut sources = Vec::new();
        for i in 0..37 {
            let t = i as f64;
            let r = 0.001 * 1.2f64.powf(t);
            let x = observers[0].0;
            let y = [x[0] + r * (0.7 * t).cos(), x[1] + r * (0.7 * t).sin(), x[2] + 0.3 * r];
            let ny = [(0.3 * t).sin(), (0.3 * t).cos(), 0.0];
            let w = 1e-6 * (1.0 + t);
            for (o, observer) in observers.iter().enumerate() {
                pts.push(*observer, y, ny, w, i % 5 + o, i);
            }
            sources.push((y, ny, w));
        }
        (pts, sources)
    }

    fn close(got: c64, want: c64, what: &str) {
        assert!((got - want).norm() <= 1e-13 * want.norm(), "{what}: {got} vs {want}");
    }

    /// `(a, op)` from the four kernels of [`Kernels::point`], combined:
    /// the independent reference of the coupled formula.
    fn combined(k: f64, alpha: c64, (x, nx): Observer, (y, ny, w): Source) -> (c64, c64) {
        let ints = Kernels::new(k).point(x, nx, y, ny, w);
        (-ints.dg_dny - alpha * ints.d2g, -(ints.g + alpha * ints.dg_dnx))
    }

    #[test]
    fn coupled_weights_equal_the_kernels_combined_in_every_lane_width() {
        let (k, alpha) = (300.0, c64::new(0.0, 1.0 / 300.0));
        let kernels = CoupledKernels::new(k, alpha);
        let observers = [([0.01, -0.02, 0.03], [0.0, 0.6, 0.8]), ([0.2, 0.1, -0.1], [1.0, 0.0, 0.0])];
        let (mut pts, sources) = gathered(observers);
        pts.evaluate(&kernels, Formula::Coupled);
        let wide = (0..pts.len()).map(|p| pts.weights(p)).collect::<Vec<_>>();
        // The portable loop (two lanes) gives the same bits as the run-time choice.
        pts.evaluate_by(&kernels, Formula::Coupled, Trig::PolynomialPortable);
        for (p, (a, op)) in wide.iter().enumerate() {
            assert_eq!((*a, *op), pts.weights(p), "point {p}");
            let (a0, op0) = combined(k, alpha, observers[p % 2], sources[p / 2]);
            close(*a, a0, &format!("a at point {p}"));
            close(*op, op0, &format!("op at point {p}"));
        }
        assert_eq!(pts.owners().nth(73), Some((2, 36)));
        // libm's sin_cos agrees too.
        pts.evaluate_by(&kernels, Formula::Coupled, Trig::Libm);
        for (p, (a, op)) in wide.iter().enumerate() {
            let (a1, op1) = pts.weights(p);
            close(a1, *a, &format!("libm a at point {p}"));
            close(op1, *op, &format!("libm op at point {p}"));
        }
    }

    #[test]
    fn columns_seen_from_one_point_give_the_gathered_bits() {
        // SourceColumns (the far panels of a cluster, read in place) against
        // the same points gathered one by one: equal bits, in order, across
        // several chunks and a ragged last one.
        let (k, alpha) = (275.0, c64::new(0.0, 1.0 / 275.0));
        let kernels = CoupledKernels::new(k, alpha);
        let observer = ([0.01, -0.02, 0.03], [0.0, 0.6, 0.8]);
        let (mut pts, mut columns) = (SourcePoints::default(), SourceColumns::default());
        for i in 0..150 {
            let t = i as f64;
            let y = [0.05 * (0.37 * t).cos(), 0.04 * (0.53 * t).sin(), 0.002 * t - 0.1];
            let n = [(0.3 * t).sin(), (0.3 * t).cos(), 0.0];
            let w = 1e-6 * (1.0 + 0.1 * t);
            pts.push(observer, y, n, w, 0, i);
            columns.push(y, n, w);
        }
        pts.evaluate(&kernels, Formula::Coupled);
        let mut seen = Vec::new();
        columns.for_each_coupled(&kernels, observer, 7..150, |p, a, op| seen.push((p, a, op)));
        assert_eq!(seen.len(), 143);
        for (p, a, op) in seen {
            assert_eq!((a, op), pts.weights(p), "point {p}");
        }
    }

    #[test]
    fn coupled_weights_of_random_pairs_equal_the_kernels_combined() {
        // Random pairs at kr from 0.05 to 60, any orientation, and pairs 1 km
        // apart (k·r beyond the polynomial sin_cos: the block takes libm's).
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut rand = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let unit = |v: [f64; 3]| v.map(|c| c / crate::geometry::norm(v));
        let mut fallbacks = 0;
        for case in 0..300 {
            let k = [1.0, 30.0, 300.0][case % 3];
            let alpha = c64::new(0.0, 1.0 / k) * (1.0 + rand());
            let x = [rand(), rand(), rand()];
            let reach = if case >= 200 { 1000.0 } else { 0.2 };
            let y = [0, 1, 2].map(|i| x[i] + reach * rand());
            let (nx, ny) = (unit([rand(), rand(), rand()]), unit([rand(), rand(), rand()]));
            let w = 1e-4 * (1.0 + rand());
            let mut pts = SourcePoints::default();
            pts.push((x, nx), y, ny, w, 0, 0);
            let kernels = CoupledKernels::new(k, alpha);
            let beyond = k * crate::geometry::norm(crate::geometry::sub(y, x)) > MAX_ARGUMENT;
            pts.evaluate(&kernels, Formula::Coupled);
            // The polynomial pass reports the argument out of its range.
            assert_eq!(pts.evaluate_block(&kernels, Formula::Coupled, Trig::Polynomial, 0..1), !beyond);
            if beyond {
                fallbacks += 1;
                pts.evaluate(&kernels, Formula::Coupled);
            }
            let (got, want) = (pts.weights(0), combined(k, alpha, (x, nx), (y, ny, w)));
            for (g, e) in [(got.0, want.0), (got.1, want.1)] {
                assert!((g - e).norm() <= 1e-13 * e.norm(), "case {case}: {g} vs {e}");
            }
        }
        assert!(fallbacks > 10, "{fallbacks} pairs beyond the polynomial's range");
    }

    #[test]
    fn linear_coefficients_give_the_point_kernel_for_any_normal() {
        let (k, alpha) = (250.0, c64::new(0.0, 1.0 / 250.0));
        let kernels = CoupledKernels::new(k, alpha);
        let observers = [([0.01, -0.02, 0.03], [0.0, 0.6, 0.8]), ([0.2, 0.1, -0.1], [1.0, 0.0, 0.0])];
        let (mut pts, sources) = gathered(observers);
        pts.evaluate(&kernels, Formula::Linear);
        for p in 0..pts.len() {
            let (x, nx) = observers[p % 2];
            let (y, ny, w) = sources[p / 2];
            let (dn, nn, op) = pts.linear_weights(p);
            let pk = crate::kernels::PointKernel::new(k, x, nx, y);
            let d = crate::geometry::sub(y, x);
            // A summed normal and a dipole moment are not unit vectors.
            for n in [ny, [0.3, -2.0, 0.7]] {
                let a = (dn * crate::geometry::dot(d, n) + nn * crate::geometry::dot(nx, n)) / w;
                close(a, -(pk.dg_dny(n) + alpha * pk.d2g(n)), &format!("a at point {p}"));
            }
            close(op / w, -(pk.g + alpha * pk.dg_dnx), &format!("op at point {p}"));
        }
    }

    #[test]
    fn remainder_weights_equal_the_remainder_integrals() {
        // One panel's 7-point remainder (k·h ≤ 2: not split) seen from points
        // off it, against Kernels::remainder combined as the assembly does.
        let (k, alpha) = (380.0, c64::new(0.0, 1.0 / 380.0));
        let t = [[0.0, 0.0, 0.0], [0.004, 0.0, 0.0], [0.0, 0.003, 0.0005]];
        let mesh = BoundaryMesh::new(t.to_vec(), &[[0, 1, 2]]).expect("one panel");
        let panel = &mesh.panels[0];
        assert!(k * panel.diameter <= crate::kernels::REMAINDER_MAX_KH, "the rule must not split");
        let kernels = CoupledKernels::new(k, alpha);
        for (x, nx) in [([0.001, 0.001, 0.004], [0.0, 0.0, 1.0]), ([0.01, -0.003, 0.002], [0.6, 0.0, 0.8])] {
            let mut pts = SourcePoints::default();
            for (b, w) in crate::quadrature::TRIANGLE_7 {
                pts.push((x, nx), crate::quadrature::on_triangle(b, t), panel.normal, w * panel.area, 0, 0);
            }
            pts.evaluate(&kernels, Formula::Remainder);
            let (mut a, mut op) = (c64::new(0.0, 0.0), c64::new(0.0, 0.0));
            for p in 0..pts.len() {
                let (da, dop) = pts.weights(p);
                a += da;
                op += dop;
            }
            let ints = Kernels::new(k).remainder(&mesh, panel, x, nx);
            close(a, -ints.dg_dny - alpha * ints.d2g, "a");
            close(op, -(ints.g + alpha * ints.dg_dnx), "op");
        }
    }
}
