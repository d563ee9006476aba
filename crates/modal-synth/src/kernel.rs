//! The per-sample kernel: a bank of complex one-pole resonators.
//!
//! Each active mode holds its output-weighted complex state `u_k` and pole
//! `p_k = e^{(−d_k + iω_k)/fs}`. Per sample: `y += Re u_k`, then `u_k ← p_k u_k`
//! (4 multiplies, 2 adds, 1 accumulate). Layout is structure-of-arrays in f32:
//! tiles of [`TILE`] modes are kept in registers for a whole segment of up to
//! one block of samples, and each sample folds the tile's real parts into a
//! [`LANES`]-wide partial sum per sample (`lanes[s]`), reduced once per sample
//! per chunk of [`CHUNK`] modes by a fixed pairwise tree. The fixed tile,
//! chunk and reduction order make the result independent of the thread count.
//!
//! Paths: AVX-512F (4 × 16 lanes per tile) and AVX2 + FMA (8 × 8 lanes),
//! written with explicit `core::arch` intrinsics and chosen at run time with
//! `is_x86_feature_detected!` (bit-identical to the generic fused tile, which a
//! test checks), and a portable path (the generic tile with separate multiply
//! and add, auto-vectorized for whatever the compile target allows). A tile
//! of 64 keeps four independent complex-multiply chains per vector width in
//! flight, which hides the multiply → FMA latency. The f64 scalar reference
//! [`render_reference`] implements the same recurrence in double precision.

/// Modes per register tile.
pub const TILE: usize = 64;
/// Width of the per-sample partial sums.
pub const LANES: usize = 16;
/// Modes per chunk: the unit of parallel work and of the fixed summation order.
pub const CHUNK: usize = 1024;

const _: () = assert!(TILE == 4 * LANES && CHUNK.is_multiple_of(TILE));

/// Which f32 kernel variant runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimdPath {
    /// AVX-512F (512-bit vectors, fused multiply-add).
    Avx512,
    /// AVX2 with FMA.
    Avx2Fma,
    /// Baseline target features, separate multiply and add.
    Portable,
}

impl SimdPath {
    /// The best path this CPU supports.
    pub fn detect() -> SimdPath {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("fma") {
                return SimdPath::Avx512;
            }
            if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
                return SimdPath::Avx2Fma;
            }
        }
        SimdPath::Portable
    }
}

/// `a·b + c`, plain (two roundings) or fused; shared with `force_kernel`.
pub(crate) trait MulAdd {
    fn mul_add(a: f32, b: f32, c: f32) -> f32;
}

pub(crate) struct Plain;
impl MulAdd for Plain {
    #[inline(always)]
    fn mul_add(a: f32, b: f32, c: f32) -> f32 {
        a * b + c
    }
}

#[cfg_attr(not(test), allow(dead_code))]
pub(crate) struct Fused;
impl MulAdd for Fused {
    #[inline(always)]
    fn mul_add(a: f32, b: f32, c: f32) -> f32 {
        a.mul_add(b, c)
    }
}

/// Scratch partial sums of one chunk: one `[f32; LANES]` per sample.
pub type LaneBuf = [f32; LANES];

#[inline(always)]
fn tile<M: MulAdd>(ur: &mut [f32], ui: &mut [f32], pr: &[f32], pi: &[f32], lanes: &mut [LaneBuf]) {
    let mut r: [f32; TILE] = ur.try_into().expect("tile length");
    let mut i: [f32; TILE] = ui.try_into().expect("tile length");
    let pr: [f32; TILE] = pr.try_into().expect("tile length");
    let pi: [f32; TILE] = pi.try_into().expect("tile length");
    for acc in lanes.iter_mut() {
        let mut sum = *acc;
        for l in 0..LANES {
            sum[l] += (r[l] + r[l + LANES]) + (r[l + 2 * LANES] + r[l + 3 * LANES]);
        }
        *acc = sum;
        for l in 0..TILE {
            let nr = M::mul_add(pr[l], r[l], -(pi[l] * i[l]));
            let ni = M::mul_add(pr[l], i[l], pi[l] * r[l]);
            r[l] = nr;
            i[l] = ni;
        }
    }
    ur.copy_from_slice(&r);
    ui.copy_from_slice(&i);
}

#[inline(always)]
fn hsum(v: &LaneBuf) -> f32 {
    let mut w = *v;
    let mut width = LANES / 2;
    while width > 0 {
        for k in 0..width {
            w[k] += w[k + width];
        }
        width /= 2;
    }
    w[0]
}

/// Explicit-intrinsics tiles: the same arithmetic as `tile::<Fused>` (so
/// bit-identical to it), written out so that no compiler cost model can
/// decide against vectorizing the per-sample fold.
#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{LaneBuf, TILE};
    use std::arch::x86_64::*;

    #[target_feature(enable = "avx512f")]
    pub(super) fn tile_avx512(ur: &mut [f32], ui: &mut [f32], pr: &[f32], pi: &[f32], lanes: &mut [LaneBuf]) {
        assert!(ur.len() == TILE && ui.len() == TILE && pr.len() == TILE && pi.len() == TILE);
        // SAFETY: every pointer below addresses TILE = 64 valid f32 (asserted
        // above, 4 vectors of 16) or one LaneBuf of 16 f32; unaligned loads/stores.
        unsafe {
            let ld = |p: *const f32| std::array::from_fn::<__m512, 4, _>(|k| _mm512_loadu_ps(p.add(16 * k)));
            let (mut r, mut i) = (ld(ur.as_ptr()), ld(ui.as_ptr()));
            let (p, q) = (ld(pr.as_ptr()), ld(pi.as_ptr()));
            for acc in lanes.iter_mut() {
                let a = _mm512_loadu_ps(acc.as_ptr());
                let fold = _mm512_add_ps(_mm512_add_ps(r[0], r[1]), _mm512_add_ps(r[2], r[3]));
                _mm512_storeu_ps(acc.as_mut_ptr(), _mm512_add_ps(a, fold));
                for k in 0..4 {
                    let nr = _mm512_fmsub_ps(p[k], r[k], _mm512_mul_ps(q[k], i[k]));
                    let ni = _mm512_fmadd_ps(p[k], i[k], _mm512_mul_ps(q[k], r[k]));
                    (r[k], i[k]) = (nr, ni);
                }
            }
            for k in 0..4 {
                _mm512_storeu_ps(ur.as_mut_ptr().add(16 * k), r[k]);
                _mm512_storeu_ps(ui.as_mut_ptr().add(16 * k), i[k]);
            }
        }
    }

    #[target_feature(enable = "avx2,fma")]
    pub(super) fn tile_avx2(ur: &mut [f32], ui: &mut [f32], pr: &[f32], pi: &[f32], lanes: &mut [LaneBuf]) {
        assert!(ur.len() == TILE && ui.len() == TILE && pr.len() == TILE && pi.len() == TILE);
        // SAFETY: as in `tile_avx512`: 8 × 8 f32 per mode slice, 2 × 8 per LaneBuf.
        unsafe {
            let ld = |p: *const f32| std::array::from_fn::<__m256, 8, _>(|k| _mm256_loadu_ps(p.add(8 * k)));
            let (mut r, mut i) = (ld(ur.as_ptr()), ld(ui.as_ptr()));
            let (p, q) = (ld(pr.as_ptr()), ld(pi.as_ptr()));
            for acc in lanes.iter_mut() {
                for h in 0..2 {
                    let a = _mm256_loadu_ps(acc.as_ptr().add(8 * h));
                    let fold =
                        _mm256_add_ps(_mm256_add_ps(r[h], r[h + 2]), _mm256_add_ps(r[h + 4], r[h + 6]));
                    _mm256_storeu_ps(acc.as_mut_ptr().add(8 * h), _mm256_add_ps(a, fold));
                }
                for k in 0..8 {
                    let nr = _mm256_fmsub_ps(p[k], r[k], _mm256_mul_ps(q[k], i[k]));
                    let ni = _mm256_fmadd_ps(p[k], i[k], _mm256_mul_ps(q[k], r[k]));
                    (r[k], i[k]) = (nr, ni);
                }
            }
            for k in 0..8 {
                _mm256_storeu_ps(ur.as_mut_ptr().add(8 * k), r[k]);
                _mm256_storeu_ps(ui.as_mut_ptr().add(8 * k), i[k]);
            }
        }
    }
}

#[inline(always)]
fn chunk_with(
    tile_fn: impl Fn(&mut [f32], &mut [f32], &[f32], &[f32], &mut [LaneBuf]),
    ur: &mut [f32],
    ui: &mut [f32],
    pr: &[f32],
    pi: &[f32],
    lanes: &mut [LaneBuf],
    out: &mut [f32],
) {
    let lanes = &mut lanes[..out.len()];
    lanes.iter_mut().for_each(|l| *l = [0.0; LANES]);
    let tiles = ur
        .chunks_exact_mut(TILE)
        .zip(ui.chunks_exact_mut(TILE))
        .zip(pr.chunks_exact(TILE).zip(pi.chunks_exact(TILE)));
    for ((r, i), (p, q)) in tiles {
        tile_fn(r, i, p, q, lanes);
    }
    for (o, l) in out.iter_mut().zip(lanes.iter()) {
        *o = hsum(l);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn chunk_avx512(
    ur: &mut [f32],
    ui: &mut [f32],
    pr: &[f32],
    pi: &[f32],
    lanes: &mut [LaneBuf],
    out: &mut [f32],
) {
    // The closure inherits this function's target features.
    chunk_with(|a, b, c, d, e| x86::tile_avx512(a, b, c, d, e), ur, ui, pr, pi, lanes, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn chunk_avx2(
    ur: &mut [f32],
    ui: &mut [f32],
    pr: &[f32],
    pi: &[f32],
    lanes: &mut [LaneBuf],
    out: &mut [f32],
) {
    // The closure inherits this function's target features.
    chunk_with(|a, b, c, d, e| x86::tile_avx2(a, b, c, d, e), ur, ui, pr, pi, lanes, out)
}

fn chunk_portable(
    ur: &mut [f32],
    ui: &mut [f32],
    pr: &[f32],
    pi: &[f32],
    lanes: &mut [LaneBuf],
    out: &mut [f32],
) {
    chunk_with(tile::<Plain>, ur, ui, pr, pi, lanes, out)
}

/// Renders one chunk of modes for `out.len()` samples, OVERWRITING `out`
/// with `Σ_k Re u_k` per sample and advancing the states.
///
/// Contract: all four mode slices have the same length, a multiple of
/// [`TILE`] and at most [`CHUNK`]; `lanes.len() >= out.len()`.
pub fn render_chunk(
    path: SimdPath,
    ur: &mut [f32],
    ui: &mut [f32],
    pr: &[f32],
    pi: &[f32],
    lanes: &mut [LaneBuf],
    out: &mut [f32],
) {
    assert!(ur.len().is_multiple_of(TILE) && ur.len() <= CHUNK, "chunk length");
    assert!(ui.len() == ur.len() && pr.len() == ur.len() && pi.len() == ur.len(), "chunk slices");
    assert!(lanes.len() >= out.len(), "lane scratch");
    match path {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: avx512f was checked by the guard of this arm.
        SimdPath::Avx512 if is_x86_feature_detected!("avx512f") => unsafe {
            chunk_avx512(ur, ui, pr, pi, lanes, out)
        },
        #[cfg(target_arch = "x86_64")]
        SimdPath::Avx512 | SimdPath::Avx2Fma
            if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") =>
        {
            // SAFETY: the features were checked on the line above.
            unsafe { chunk_avx2(ur, ui, pr, pi, lanes, out) }
        }
        _ => chunk_portable(ur, ui, pr, pi, lanes, out),
    }
}

/// Scalar f64 reference: ADDS `Σ_k Re u_k` per sample to `out` and advances
/// the states `u_k ← p_k u_k`, mode by mode.
pub fn render_reference(ur: &mut [f64], ui: &mut [f64], pr: &[f64], pi: &[f64], out: &mut [f64]) {
    for k in 0..ur.len() {
        let (mut r, mut i) = (ur[k], ui[k]);
        for o in out.iter_mut() {
            *o += r;
            (r, i) = (pr[k] * r - pi[k] * i, pr[k] * i + pi[k] * r);
        }
        ur[k] = r;
        ui[k] = i;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_paths_match_reference() {
        let n = 3 * TILE;
        let (mut pr, mut pi, mut ur, mut ui) = (vec![0f32; n], vec![0f32; n], vec![0f32; n], vec![0f32; n]);
        for k in 0..n {
            let w = 0.01 + 0.02 * k as f64;
            let m = (-1e-4 * k as f64).exp();
            pr[k] = (m * w.cos()) as f32;
            pi[k] = (m * w.sin()) as f32;
            ur[k] = (1.0 / (1.0 + k as f64)) as f32;
            ui[k] = (0.3 - 0.01 * k as f64) as f32;
        }
        let len = 200;
        let mut want = vec![0f64; len];
        let to64 = |v: &[f32]| v.iter().map(|&x| x as f64).collect::<Vec<_>>();
        render_reference(&mut to64(&ur), &mut to64(&ui), &to64(&pr), &to64(&pi), &mut want);
        let peak = want.iter().fold(0f64, |a, &b| a.max(b.abs()));
        for path in [SimdPath::Portable, SimdPath::detect()] {
            let (mut r, mut i) = (ur.clone(), ui.clone());
            let mut lanes = vec![[0f32; LANES]; len];
            let mut out = vec![0f32; len];
            render_chunk(path, &mut r, &mut i, &pr, &pi, &mut lanes, &mut out);
            let err = out.iter().zip(&want).fold(0f64, |a, (&x, &y)| a.max((x as f64 - y).abs()));
            assert!(err < 2e-6 * peak, "{path:?}: {err} vs peak {peak}");
        }
        // The intrinsics tiles are bit-identical to the generic fused tile.
        let path = SimdPath::detect();
        if path != SimdPath::Portable {
            let (mut r, mut i, mut r2, mut i2) = (ur.clone(), ui.clone(), ur.clone(), ui.clone());
            let mut lanes = vec![[0f32; LANES]; len];
            let (mut a, mut b) = (vec![0f32; len], vec![0f32; len]);
            render_chunk(path, &mut r, &mut i, &pr, &pi, &mut lanes, &mut a);
            chunk_with(tile::<Fused>, &mut r2, &mut i2, &pr, &pi, &mut lanes, &mut b);
            assert!(a == b && r == r2 && i == i2, "{path:?} differs from tile::<Fused>");
        }
    }
}
