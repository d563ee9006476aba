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

use crate::kernel::SimdPath;

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

trait MulAdd {
    fn mul_add(a: f32, b: f32, c: f32) -> f32;
}

struct Plain;
impl MulAdd for Plain {
    #[inline(always)]
    fn mul_add(a: f32, b: f32, c: f32) -> f32 {
        a * b + c
    }
}

struct Fused;
impl MulAdd for Fused {
    #[inline(always)]
    fn mul_add(a: f32, b: f32, c: f32) -> f32 {
        a.mul_add(b, c)
    }
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

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2,fma")]
fn span_avx512(span: Span<'_>, scratch: &mut Scratch, out: &mut [f32]) {
    span_with::<Fused>(span, scratch, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn span_avx2(span: Span<'_>, scratch: &mut Scratch, out: &mut [f32]) {
    span_with::<Fused>(span, scratch, out)
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
