//! The f32 tile kernel of [`crate::DrivenVoice`] (sustained contact).
//!
//! Per mode (lane) and sample `j` it evaluates, as the f64 path of
//! [`crate::force`] does,
//!
//! `y_j += Re(w z)`,  `z ← p z + a g_j + b g_{j+1}`,
//! `g_j = c · f_j` (the modal force: mode shape at the contact point `c`
//! dotted with the force knot `f_j`, summed over the segments acting),
//!
//! in single precision, [`FT`] modes per tile held in registers for a whole
//! span (the samples between two force-segment or block boundaries): the
//! modal force knots of a tile are computed first (3 multiply-adds per lane,
//! knot and segment), then the recurrence runs with the tile's constants in
//! registers, folding `Re(w z)` into a per-sample [`FT`]-wide partial sum.
//! Partial sums are reduced once per sample by a fixed pairwise tree after
//! the last tile, so the result depends neither on how a span is cut into
//! calls nor on threads. Paths: AVX-512F and AVX2 + FMA (the generic tile
//! compiled with those features, fused multiply-adds, chosen at run time as
//! [`crate::kernel::SimdPath`]), and a portable path (separate multiply and
//! add).
//!
//! Precision: the f32 recurrence drifts in phase by the pole's rounding
//! (≈ 6e-8 rad per sample), so [`crate::DrivenVoice`] re-anchors every
//! [`crate::BLOCK`] samples from its f64 state and keeps only the forced part
//! of the f32 run (module doc of [`crate::force`]).

use crate::kernel::{MulAdd, Plain, SimdPath};

/// Modes per tile (one AVX-512 vector, two AVX2 vectors).
pub const FT: usize = 16;

/// One tile's lanes.
pub type Lanes = [f32; FT];

/// A tile's per-mode constants (padding lanes are all zero).
#[derive(Clone, Copy, Debug, Default)]
pub struct TileConsts {
    /// Pole `p = e^{s/fs}`, real and imaginary parts.
    pub pr: Lanes,
    /// See [`TileConsts::pr`].
    pub pi: Lanes,
    /// First-order-hold coefficient `a` (of `g_j`).
    pub ar: Lanes,
    /// See [`TileConsts::ar`].
    pub ai: Lanes,
    /// First-order-hold coefficient `b` (of `g_{j+1}`).
    pub br: Lanes,
    /// See [`TileConsts::br`].
    pub bi: Lanes,
    /// Output weight `w`.
    pub wr: Lanes,
    /// See [`TileConsts::wr`].
    pub wi: Lanes,
}

/// One force segment acting over a span: its mode-shape coefficients per
/// tile (`c[t]` = x, y, z lanes of tile `t`) and its force knots over the
/// span (`len + 1` of them).
pub struct SpanForce<'a> {
    /// Per tile: the mode shapes at the contact point, per component.
    pub c: &'a [[Lanes; 3]],
    /// Force knots [N] at the span's samples `0 ..= len`.
    pub f: &'a [[f32; 3]],
}

/// Scratch buffers of [`render_span`], reused across calls.
#[derive(Default, Debug, Clone)]
pub struct Scratch {
    g: Vec<Lanes>,
    lanes: Vec<Lanes>,
}

/// The modal force knots of tile `t` over the span into `g[..=len]`.
#[inline(always)]
fn modal_force<M: MulAdd>(t: usize, forces: &[SpanForce<'_>], g: &mut [Lanes]) {
    g.iter_mut().for_each(|x| *x = [0.0; FT]);
    for s in forces {
        let [cx, cy, cz] = s.c[t];
        for (gj, f) in g.iter_mut().zip(s.f) {
            for l in 0..FT {
                gj[l] = M::mul_add(cx[l], f[0], M::mul_add(cy[l], f[1], M::mul_add(cz[l], f[2], gj[l])));
            }
        }
    }
}

/// Advances one tile over `lanes.len()` samples, adding `Re(w z)` (before
/// each update) to `lanes`. `g` (`len + 1` knots) is `None` when no force acts.
#[inline(always)]
fn tile<M: MulAdd>(k: &TileConsts, zr: &mut Lanes, zi: &mut Lanes, g: Option<&[Lanes]>, lanes: &mut [Lanes]) {
    let (mut r, mut i) = (*zr, *zi);
    match g {
        Some(g) => {
            for (j, acc) in lanes.iter_mut().enumerate() {
                let (g0, g1) = (&g[j], &g[j + 1]);
                for l in 0..FT {
                    acc[l] = M::mul_add(k.wr[l], r[l], M::mul_add(-k.wi[l], i[l], acc[l]));
                    let dr = M::mul_add(k.ar[l], g0[l], k.br[l] * g1[l]);
                    let di = M::mul_add(k.ai[l], g0[l], k.bi[l] * g1[l]);
                    let nr = M::mul_add(k.pr[l], r[l], M::mul_add(-k.pi[l], i[l], dr));
                    let ni = M::mul_add(k.pr[l], i[l], M::mul_add(k.pi[l], r[l], di));
                    (r[l], i[l]) = (nr, ni);
                }
            }
        }
        None => {
            for acc in lanes.iter_mut() {
                for l in 0..FT {
                    acc[l] = M::mul_add(k.wr[l], r[l], M::mul_add(-k.wi[l], i[l], acc[l]));
                    let nr = M::mul_add(k.pr[l], r[l], -(k.pi[l] * i[l]));
                    let ni = M::mul_add(k.pr[l], i[l], k.pi[l] * r[l]);
                    (r[l], i[l]) = (nr, ni);
                }
            }
        }
    }
    (*zr, *zi) = (r, i);
}

#[inline(always)]
fn hsum(v: &Lanes) -> f32 {
    let mut w = *v;
    let mut width = FT / 2;
    while width > 0 {
        for k in 0..width {
            w[k] += w[k + width];
        }
        width /= 2;
    }
    w[0]
}

/// Arguments of one span.
pub struct Span<'a> {
    /// Per tile constants.
    pub consts: &'a [TileConsts],
    /// Per tile state, real and imaginary parts (advanced in place).
    pub zr: &'a mut [Lanes],
    /// See [`Span::zr`].
    pub zi: &'a mut [Lanes],
    /// The segments acting (empty: free decay).
    pub forces: &'a [SpanForce<'a>],
    /// Per tile and sample: an extra state increment added after each
    /// update (oversampled segments), `extra[t * len + j]`, real and imaginary.
    pub extra: Option<(&'a [Lanes], &'a [Lanes])>,
}

/// The tile update, modal force and span loop of one SIMD width, written
/// with explicit intrinsics: the same arithmetic as `tile::<Fused>` and
/// `modal_force::<Fused>` (so bit-identical to them, and AVX-512 to AVX2).
#[cfg(target_arch = "x86_64")]
macro_rules! simd_span {
    ($name:ident, $feature:literal, $v:ty, $width:expr, $load:ident, $store:ident, $set1:ident, $fmadd:ident,
     $mul:ident, $xor:ident, $add:ident) => {
        #[target_feature(enable = $feature)]
        fn $name(span: Span<'_>, scratch: &mut Scratch, out: &mut [f32]) {
            use std::arch::x86_64::*;
            const V: usize = FT / $width;
            type T = [$v; V];
            let len = out.len();
            scratch.lanes.clear();
            scratch.lanes.resize(len, [0.0; FT]);
            scratch.g.resize(len + 1, [0.0; FT]);
            // SAFETY: every load/store below addresses one `Lanes` (FT f32)
            // split into V vectors of $width; unaligned accesses.
            unsafe {
                let ld = |p: &Lanes| -> T { std::array::from_fn(|k| $load(p.as_ptr().add($width * k))) };
                let st = |p: &mut Lanes, x: T| {
                    for (k, v) in x.iter().enumerate() {
                        $store(p.as_mut_ptr().add($width * k), *v);
                    }
                };
                let sign = $set1(-0.0);
                let neg = |x: T| -> T { x.map(|v| $xor(v, sign)) };
                let forced = !span.forces.is_empty();
                for t in 0..span.consts.len() {
                    let k = &span.consts[t];
                    if forced {
                        let g = &mut scratch.g[..=len];
                        g.iter_mut().for_each(|x| *x = [0.0; FT]);
                        for s in span.forces {
                            let [cx, cy, cz] = s.c[t].map(|c| ld(&c));
                            for (gj, f) in g.iter_mut().zip(s.f) {
                                let (fx, fy, fz) = ($set1(f[0]), $set1(f[1]), $set1(f[2]));
                                let acc = ld(gj);
                                let x: T = std::array::from_fn(|q| {
                                    $fmadd(cx[q], fx, $fmadd(cy[q], fy, $fmadd(cz[q], fz, acc[q])))
                                });
                                st(gj, x);
                            }
                        }
                    }
                    let (pr, pi, ar, ai, br, bi, wr, wi) = (
                        ld(&k.pr),
                        ld(&k.pi),
                        ld(&k.ar),
                        ld(&k.ai),
                        ld(&k.br),
                        ld(&k.bi),
                        ld(&k.wr),
                        ld(&k.wi),
                    );
                    let (npi, nwi) = (neg(pi), neg(wi));
                    let (mut r, mut i) = (ld(&span.zr[t]), ld(&span.zi[t]));
                    for j in 0..len {
                        let acc = ld(&scratch.lanes[j]);
                        let y: T = std::array::from_fn(|q| $fmadd(wr[q], r[q], $fmadd(nwi[q], i[q], acc[q])));
                        st(&mut scratch.lanes[j], y);
                        let (nr, ni): (T, T) = if forced {
                            let (g0, g1) = (ld(&scratch.g[j]), ld(&scratch.g[j + 1]));
                            let dr: T = std::array::from_fn(|q| $fmadd(ar[q], g0[q], $mul(br[q], g1[q])));
                            let di: T = std::array::from_fn(|q| $fmadd(ai[q], g0[q], $mul(bi[q], g1[q])));
                            (
                                std::array::from_fn(|q| $fmadd(pr[q], r[q], $fmadd(npi[q], i[q], dr[q]))),
                                std::array::from_fn(|q| $fmadd(pr[q], i[q], $fmadd(pi[q], r[q], di[q]))),
                            )
                        } else {
                            (
                                std::array::from_fn(|q| $fmadd(pr[q], r[q], $xor($mul(pi[q], i[q]), sign))),
                                std::array::from_fn(|q| $fmadd(pr[q], i[q], $mul(pi[q], r[q]))),
                            )
                        };
                        (r, i) = (nr, ni);
                        if let Some((er, ei)) = span.extra {
                            let (a, b) = (ld(&er[t * len + j]), ld(&ei[t * len + j]));
                            r = std::array::from_fn(|q| $add(r[q], a[q]));
                            i = std::array::from_fn(|q| $add(i[q], b[q]));
                        }
                    }
                    st(&mut span.zr[t], r);
                    st(&mut span.zi[t], i);
                }
            }
            for (o, l) in out.iter_mut().zip(&scratch.lanes) {
                *o += hsum(l);
            }
        }
    };
}

/// `a ^ b` on the bits of two AVX-512 float vectors (AVX-512F only: the
/// float form needs AVX-512DQ).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
#[inline]
fn xor512(a: std::arch::x86_64::__m512, b: std::arch::x86_64::__m512) -> std::arch::x86_64::__m512 {
    use std::arch::x86_64::*;
    _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(a), _mm512_castps_si512(b)))
}

#[cfg(target_arch = "x86_64")]
simd_span!(
    span_avx512,
    "avx512f,fma",
    __m512,
    16,
    _mm512_loadu_ps,
    _mm512_storeu_ps,
    _mm512_set1_ps,
    _mm512_fmadd_ps,
    _mm512_mul_ps,
    xor512,
    _mm512_add_ps
);

#[cfg(target_arch = "x86_64")]
simd_span!(
    span_avx2,
    "avx2,fma",
    __m256,
    8,
    _mm256_loadu_ps,
    _mm256_storeu_ps,
    _mm256_set1_ps,
    _mm256_fmadd_ps,
    _mm256_mul_ps,
    _mm256_xor_ps,
    _mm256_add_ps
);

#[inline(always)]
fn span_with<M: MulAdd>(span: Span<'_>, scratch: &mut Scratch, out: &mut [f32]) {
    let len = out.len();
    scratch.lanes.clear();
    scratch.lanes.resize(len, [0.0; FT]);
    scratch.g.resize(len + 1, [0.0; FT]);
    let forced = !span.forces.is_empty();
    for t in 0..span.consts.len() {
        let g = if forced {
            modal_force::<M>(t, span.forces, &mut scratch.g[..=len]);
            Some(&scratch.g[..=len])
        } else {
            None
        };
        let (zr, zi) = (&mut span.zr[t], &mut span.zi[t]);
        match span.extra {
            None => tile::<M>(&span.consts[t], zr, zi, g, &mut scratch.lanes),
            Some((er, ei)) => {
                // Oversampled segments: one sample at a time, then the increment.
                for j in 0..len {
                    let gj = g.map(|g| &g[j..j + 2]);
                    tile::<M>(&span.consts[t], zr, zi, gj, &mut scratch.lanes[j..j + 1]);
                    for l in 0..FT {
                        zr[l] += er[t * len + j][l];
                        zi[l] += ei[t * len + j][l];
                    }
                }
            }
        }
    }
    for (o, l) in out.iter_mut().zip(&scratch.lanes) {
        *o += hsum(l);
    }
}

/// Renders one span: ADDS `Σ_modes Re(w z)` per sample to `out` and
/// advances the tiles' states by `out.len()` samples.
pub fn render_span(path: SimdPath, span: Span<'_>, scratch: &mut Scratch, out: &mut [f32]) {
    let tiles = span.consts.len();
    assert!(span.zr.len() == tiles && span.zi.len() == tiles, "tile state");
    assert!(span.forces.iter().all(|s| s.c.len() == tiles && s.f.len() > out.len()), "span forces");
    if let Some((er, ei)) = span.extra {
        assert!(er.len() == tiles * out.len() && ei.len() == er.len(), "span increments");
    }
    match path {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the features were checked by this arm's guard.
        SimdPath::Avx512 if is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("fma") => unsafe {
            span_avx512(span, scratch, out)
        },
        #[cfg(target_arch = "x86_64")]
        SimdPath::Avx512 | SimdPath::Avx2Fma
            if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") =>
        {
            // SAFETY: the features were checked on the line above.
            unsafe { span_avx2(span, scratch, out) }
        }
        _ => span_with::<Plain>(span, scratch, out),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic value in [−1, 1).
    fn rnd(seed: &mut u64) -> f32 {
        *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((*seed >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    }

    /// Runs one span of 3 tiles through `run`, returning output and state.
    fn run_span(
        segments: usize,
        extra: bool,
        run: &dyn Fn(Span<'_>, &mut Scratch, &mut [f32]),
    ) -> (Vec<f32>, Vec<Lanes>, Vec<Lanes>) {
        let (tiles, len) = (3, 37);
        let mut seed = 11u64;
        let mut consts = vec![TileConsts::default(); tiles];
        for (t, k) in consts.iter_mut().enumerate() {
            for l in 0..FT {
                let th = 0.01 + 0.05 * (t * FT + l) as f32;
                let m = 0.9999 - 1e-4 * l as f32;
                (k.pr[l], k.pi[l]) = (m * th.cos(), m * th.sin());
                (k.ar[l], k.ai[l], k.br[l], k.bi[l]) =
                    (rnd(&mut seed), rnd(&mut seed), rnd(&mut seed), rnd(&mut seed));
                (k.wr[l], k.wi[l]) = (rnd(&mut seed), rnd(&mut seed));
            }
        }
        let lanes = |seed: &mut u64| -> Lanes { std::array::from_fn(|_| rnd(seed)) };
        let mut zr: Vec<Lanes> = (0..tiles).map(|_| lanes(&mut seed)).collect();
        let mut zi: Vec<Lanes> = (0..tiles).map(|_| lanes(&mut seed)).collect();
        let coef: Vec<Vec<[Lanes; 3]>> = (0..segments)
            .map(|_| (0..tiles).map(|_| [lanes(&mut seed), lanes(&mut seed), lanes(&mut seed)]).collect())
            .collect();
        let knots: Vec<Vec<[f32; 3]>> = (0..segments)
            .map(|_| (0..=len).map(|_| [rnd(&mut seed), rnd(&mut seed), rnd(&mut seed)]).collect())
            .collect();
        let forces: Vec<SpanForce<'_>> =
            (0..segments).map(|k| SpanForce { c: &coef[k], f: &knots[k] }).collect();
        let er: Vec<Lanes> = (0..tiles * len).map(|_| lanes(&mut seed)).collect();
        let ei: Vec<Lanes> = (0..tiles * len).map(|_| lanes(&mut seed)).collect();
        let mut out = vec![0.5f32; len];
        let span = Span {
            consts: &consts,
            zr: &mut zr,
            zi: &mut zi,
            forces: &forces,
            extra: extra.then_some((&er[..], &ei[..])),
        };
        run(span, &mut Scratch::default(), &mut out);
        (out, zr, zi)
    }

    #[test]
    fn simd_spans_equal_the_generic_fused_span_bit_for_bit() {
        let path = SimdPath::detect();
        for (segments, extra) in [(0, false), (1, false), (2, false), (1, true), (0, true)] {
            let want = run_span(segments, extra, &|s, sc, o| span_with::<crate::kernel::Fused>(s, sc, o));
            let got = run_span(segments, extra, &|s, sc, o| render_span(path, s, sc, o));
            assert!(got == want, "{path:?}, {segments} segments, extra {extra}");
            // The portable path rounds differently, within f32 precision.
            let plain = run_span(segments, extra, &|s, sc, o| render_span(SimdPath::Portable, s, sc, o));
            let err = plain.0.iter().zip(&want.0).fold(0f32, |m, (a, b)| m.max((a - b).abs()));
            let scale = want.0.iter().fold(0f32, |m, x| m.max(x.abs()));
            assert!(err < 1e-5 * scale, "portable: {err} of {scale}");
        }
    }
}
