//! [`DrivenVoice`]: modes driven by a continuous force (first-order hold).
//!
//! Mode `i` obeys `q̈ + 2ξω q̇ + ω² q = g(t)`, `g(t) = φ_i(x)ᵀ f(t)` (shapes
//! mass-normalized, so `g` is the modal force [N/√kg]). With the voice's
//! complex state `z` (`q = Im z`, `q̇ = Im(s z)`, `s = −d + iω_d`, see
//! [`crate::ModalVoice`]) this is the first-order equation
//!
//! `ż = s z + g(t)/ω_d`,
//!
//! whose solution over a step of length `h` is
//! `z(t + h) = e^{sh} z(t) + (1/ω_d) ∫₀^h g(t + σ) e^{s(h − σ)} dσ`.
//! For a force that is linear between knots `g_k` at `t` and `g_{k+1}` at
//! `t + h` (first-order hold) the integral is exact:
//!
//! `z_{k+1} = e^{sh} z_k + a g_k + b g_{k+1}`,
//! `a = h (φ₁(sh) − φ₂(sh)) / ω_d`,  `b = h φ₂(sh) / ω_d`,
//!
//! with `φ₁(x) = (eˣ − 1)/x` and `φ₂(x) = (eˣ − 1 − x)/x²` (evaluated by
//! their Taylor series for `|x| < 1/2`, so no cancellation at low
//! frequencies). Since only the force is interpolated and every step is
//! integrated exactly, the result is the same at any block size and is the
//! exact response to the piecewise-linear force at any sample rate. A force
//! pulse of vanishing length `ε` and area `J` tends to the impulse response
//! `(φᵀJ/ω_d) e^{s(t − t₀)}` of [`crate::ModalVoice`] (error `O((sε)²)`).
//!
//! Force input: [`ForceSegment`]s, each a run of knots at a fixed surface
//! point with spacing `1/(m·fs)` (`m` = `oversample`, 1 for one knot per
//! output sample). The force of a segment is zero outside its knots and
//! linear between consecutive knots; overlapping segments add (superposition).
//! A contact point that moves is a sequence of segments (one per physics
//! step) sharing their boundary knot; at that knot the modal force may jump
//! by `(φ(x₂) − φ(x₁))ᵀ f`, which is harmless for points that move little
//! per step.
//!
//! Output: sample `n` holds `y(t_n) = Σ_i Re(W_i z_i(t_n))` with the output
//! weights `W` of [`crate::ModalVoice`] (velocity or displacement, per-mode
//! gains). A mode's recurrence costs one complex multiply, two
//! complex-by-real multiply-adds and the modal force (`3` multiply-adds per
//! segment) per sample.
//!
//! Kernels (`SynthOptions::kernel`): `Reference` runs the recurrence in f64,
//! mode by mode. `Auto` and `Portable` run it in f32 on tiles of
//! [`crate::force_kernel::FT`] modes ([`crate::force_kernel`]) and keep the
//! f64 state `z` as an anchor at every multiple of [`crate::BLOCK`] samples:
//! with `P = e^{sBh}` (f64) and `Q = p̃^B` (the f32-rounded pole `p̃` raised in
//! f64), the anchor moves by
//!
//! `z ← P z + (v − Q z̃)`,
//!
//! where `z̃` is `z` rounded to f32 (the f32 run's start) and `v` the f32 state
//! reached after the block: `v − Q z̃` is the forced part of the block (zero
//! without force, when the update is the exact `z ← P z`), so the f32 pole's
//! rounding (≈ 6e-8 rad per sample) never accumulates beyond one block. The
//! measured error against `Reference` is in the tests (`tests/force.rs`).
//!
//! Silence: at every grid point (multiple of [`crate::BLOCK`] samples) with
//! no force acting, modes whose amplitude `|W z|` is below the absolute floor
//! [`crate::ABSOLUTE_FLOOR`] or `cull_db` below the loudest are dropped for
//! good (a later segment re-excites them). Without force, each mode's energy
//! `½(q̇² + ω²q²)` never grows (its state is multiplied by `|e^{sh}| < 1`).

use std::sync::Arc;

use crate::complex::C64;
use crate::error::SynthError;
use crate::force_kernel::{self as fk, Lanes, SpanForce, TileConsts, FT};
use crate::kernel::SimdPath;
use crate::model::SynthModel;
use crate::options::{check_phase_count, classify_mode, phase_of, Kernel, SynthOptions};
use crate::surface::SurfacePoint;
use crate::voice::{weight, ImpactPoint, ABSOLUTE_FLOOR, BLOCK};

/// Largest accepted force-knot oversampling factor.
pub const MAX_OVERSAMPLE: u32 = 1 << 16;
/// Largest accepted force component [N].
pub const MAX_FORCE_N: f64 = 1e9;

/// `φ₁(x) = (eˣ − 1)/x` and `φ₂(x) = (eˣ − 1 − x)/x²` for complex `x`.
pub fn phi12(x: C64) -> (C64, C64) {
    if x.abs() < 0.5 {
        // Σ x^k/(k+1)! and Σ x^k/(k+2)!, Horner from k = 20 (error < 1e-25).
        let (mut p1, mut p2) = (C64::ZERO, C64::ZERO);
        let mut fact = [1.0f64; 23];
        for k in 1..23 {
            fact[k] = fact[k - 1] * k as f64;
        }
        for k in (0..=20).rev() {
            p1 = p1 * x + C64::new(1.0 / fact[k + 1], 0.0);
            p2 = p2 * x + C64::new(1.0 / fact[k + 2], 0.0);
        }
        (p1, p2)
    } else {
        let em1 = x.exp() - C64::new(1.0, 0.0);
        let p1 = em1.quot(x);
        let p2 = (em1 - x).quot(x * x);
        (p1, p2)
    }
}

/// First-order-hold coefficients `(a, b)` of a mode with complex frequency
/// `s` over a step `h` [s] (module doc): `z ← e^{sh} z + a g_k + b g_{k+1}`.
pub fn foh_coefficients(s: C64, h: f64) -> (C64, C64) {
    let (p1, p2) = phi12(s.scale(h));
    let k = h / s.im;
    ((p1 - p2).scale(k), p2.scale(k))
}

/// A run of force knots at one surface point.
#[derive(Clone, Debug, PartialEq)]
pub struct ForceSegment {
    /// Index of the first knot on the knot grid `t = k / (oversample · fs)`.
    pub start: u64,
    /// Knots per output sample (1 = one knot per sample).
    pub oversample: u32,
    /// Where the force acts (a position in the bank frame is snapped to the surface).
    pub point: ImpactPoint,
    /// Force vectors [N] (bank frame) at consecutive knots.
    pub forces: Vec<[f64; 3]>,
}

/// A segment whose modal coefficients are computed.
#[derive(Clone, Debug)]
struct Live {
    seq: u64,
    start: u64,
    m: u64,
    forces: Vec<[f64; 3]>,
    /// Per mode: `φ_i(x)` (3 components).
    coef: Vec<[f64; 3]>,
    /// First and one-past-last sample interval it touches.
    first: u64,
    end: u64,
    /// For `m > 1`: per mode `e^{sh}`, `a`, `b` with `h = 1/(m fs)`.
    fine: Vec<(C64, C64, C64)>,
}

/// Counters of a driven voice.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrivenStats {
    /// Segments added.
    pub segments: u64,
    /// Σ over rendered samples of the modes advanced (the synthesis work).
    pub mode_samples: u64,
    /// Samples on which modes were advanced.
    pub samples_rendered: u64,
}

/// Modes driven by piecewise-linear forces (module doc).
#[derive(Clone, Debug)]
pub struct DrivenVoice {
    model: Arc<SynthModel>,
    opts: SynthOptions,
    fs: f64,
    enabled: Vec<bool>,
    s: Vec<C64>,
    pole: Vec<C64>,
    a: Vec<C64>,
    b: Vec<C64>,
    w: Vec<C64>,
    gains_set: bool,
    z: Vec<C64>,
    /// Modes advanced by the kernel (ascending).
    active: Vec<usize>,
    is_active: Vec<bool>,
    /// Segments not yet live; when `pending_sorted`, by DESCENDING (first interval, seq).
    pending: Vec<(u64, u64, ForceSegment, SurfacePoint)>,
    pending_sorted: bool,
    live: Vec<Live>,
    seq: u64,
    pos: u64,
    culled_at: Option<u64>,
    stats: DrivenStats,
    /// Scratch: modal force knots and fine-grid contributions of a span, output.
    g: Vec<f64>,
    e: Vec<C64>,
    acc: Vec<f64>,
    phi: Vec<f64>,
    /// The f32 tile kernel's state (`None`: the f64 reference kernel).
    simd: Option<Box<Tiles>>,
}

/// The f32 tile kernel's layout, state and scratch (module doc).
#[derive(Clone, Debug)]
struct Tiles {
    path: SimdPath,
    /// Per mode: `P = p^BLOCK` and `Q = p̃^BLOCK` (module doc).
    blk_p: Vec<C64>,
    blk_q: Vec<C64>,
    /// A force acted since the last anchor.
    forced: bool,
    /// The active set or the weights changed since the layout was built.
    dirty: bool,
    /// Mode of each lane (`q = t·FT + l`), the active modes when laid out.
    modes: Vec<usize>,
    consts: Vec<TileConsts>,
    /// Running f32 state per tile.
    zr: Vec<Lanes>,
    zi: Vec<Lanes>,
    /// Scratch: per acting segment its coefficients and knots; increments.
    coef: Vec<Vec<[Lanes; 3]>>,
    knots: Vec<Vec<[f32; 3]>>,
    er: Vec<Lanes>,
    ei: Vec<Lanes>,
    e64: Vec<C64>,
    cur: Vec<(f32, f32)>,
    scratch: fk::Scratch,
}

/// `x^(2^k)` by `k` squarings.
fn pow2k(mut x: C64, k: u32) -> C64 {
    for _ in 0..k {
        x = x * x;
    }
    x
}

fn round32(z: C64) -> C64 {
    C64::new(z.re as f32 as f64, z.im as f32 as f64)
}

impl DrivenVoice {
    /// A silent driven voice sharing a checked model. `opts.kernel` picks
    /// the f64 reference or the f32 tile kernel (module doc); `budget` and
    /// `parallel` do not apply (single-threaded).
    pub fn from_model(model: Arc<SynthModel>, opts: SynthOptions) -> Result<DrivenVoice, SynthError> {
        opts.validate()?;
        let n = model.mode_count();
        let fs = opts.sample_rate;
        let mut v = DrivenVoice {
            fs,
            enabled: vec![false; n],
            s: vec![C64::ZERO; n],
            pole: vec![C64::ZERO; n],
            a: vec![C64::ZERO; n],
            b: vec![C64::ZERO; n],
            w: vec![C64::ZERO; n],
            gains_set: false,
            z: vec![C64::ZERO; n],
            active: Vec::new(),
            is_active: vec![false; n],
            pending: Vec::new(),
            pending_sorted: true,
            live: Vec::new(),
            seq: 0,
            pos: 0,
            culled_at: None,
            stats: DrivenStats::default(),
            g: Vec::new(),
            e: Vec::new(),
            acc: Vec::new(),
            phi: vec![0.0; n],
            simd: None,
            model,
            opts,
        };
        for i in 0..n {
            let m = &v.model;
            if let Ok(s) = classify_mode(m.frequencies_hz[i], m.decay_rates[i], m.damping_ratios[i], fs) {
                v.enabled[i] = true;
                v.s[i] = s;
                v.pole[i] = s.scale(1.0 / fs).exp();
                (v.a[i], v.b[i]) = foh_coefficients(s, 1.0 / fs);
            }
        }
        let path = match v.opts.kernel {
            Kernel::Reference => None,
            Kernel::Portable => Some(SimdPath::Portable),
            Kernel::Auto => Some(SimdPath::detect()),
        };
        if let Some(path) = path {
            let log2_block = BLOCK.trailing_zeros();
            v.simd = Some(Box::new(Tiles {
                path,
                blk_p: v.pole.iter().map(|&p| pow2k(p, log2_block)).collect(),
                blk_q: v.pole.iter().map(|&p| pow2k(round32(p), log2_block)).collect(),
                forced: false,
                dirty: true,
                modes: Vec::new(),
                consts: Vec::new(),
                zr: Vec::new(),
                zi: Vec::new(),
                coef: Vec::new(),
                knots: Vec::new(),
                er: Vec::new(),
                ei: Vec::new(),
                e64: Vec::new(),
                cur: vec![(0.0, 0.0); n],
                scratch: fk::Scratch::default(),
            }));
        }
        check_phase_count(v.opts.phases.as_ref(), v.model.mode_count())?;
        if let Some(g) = v.model.initial_gains(&v.opts.gain)? {
            v.set_gains(&g);
        }
        Ok(v)
    }

    fn set_mic(&mut self, p: &SurfacePoint) {
        let g = self.model.mic_gains(p);
        self.set_gains(&g);
    }

    fn set_gains(&mut self, g: &[f64]) {
        for (i, &gi) in g.iter().enumerate() {
            self.w[i] = phase_of(self.opts.phases.as_ref(), i) * weight(self.opts.quantity, self.s[i], gi);
        }
        self.gains_set = true;
        if let Some(t) = self.simd.as_mut() {
            t.dirty = true;
        }
    }

    /// Sample rate \[Hz\].
    pub fn sample_rate(&self) -> f64 {
        self.fs
    }

    /// Next sample to render.
    pub fn position(&self) -> u64 {
        self.pos
    }

    /// Counters.
    pub fn stats(&self) -> DrivenStats {
        self.stats
    }

    /// True when no force is pending or acting and no mode is active.
    pub fn is_silent(&self) -> bool {
        self.active.is_empty() && self.live.is_empty() && self.pending.is_empty()
    }

    /// Complex state `z_i` of bank mode `i` now (`q = Im z`, `q̇ = Im(s z)`);
    /// zero for modes not synthesized or out of range.
    pub fn modal_state(&self, i: usize) -> C64 {
        // Between anchors the f32 kernel's running state is the state.
        if let Some(t) = self.simd.as_ref().filter(|_| !self.pos.is_multiple_of(BLOCK as u64)) {
            if let Some(q) = t.modes.iter().position(|&m| m == i) {
                let (t_, l) = (q / FT, q % FT);
                return C64::new(t.zr[t_][l] as f64, t.zi[t_][l] as f64);
            }
        }
        self.z.get(i).copied().unwrap_or(C64::ZERO)
    }

    /// Complex frequency `s_i = −d + iω_d` of bank mode `i` (zero when not synthesized).
    pub fn complex_frequency(&self, i: usize) -> C64 {
        self.s.get(i).copied().unwrap_or(C64::ZERO)
    }

    /// Mechanical energy `½(q̇² + ω² q²)` of each mode now [J/kg-normalized]
    /// (`ω² = |s|²`); zero for modes not synthesized.
    pub fn mode_energies(&self) -> Vec<f64> {
        (0..self.z.len())
            .map(|i| {
                let (s, z) = (self.s[i], self.modal_state(i));
                let q = z.im;
                let qd = (s * z).im;
                0.5 * (qd * qd + s.norm2() * q * q)
            })
            .collect()
    }

    /// Adds a force segment. Knots before the render position are refused
    /// (the output there is already written). The first call fixes a
    /// `ContactMic { at: None }` microphone at the segment's point.
    pub fn add_segment(&mut self, seg: ForceSegment) -> Result<SurfacePoint, SynthError> {
        if seg.oversample == 0 || seg.oversample > MAX_OVERSAMPLE {
            return Err(SynthError::InvalidOption { name: "oversample", value: seg.oversample as f64 });
        }
        if let Some(f) =
            seg.forces.iter().find(|f| !f.iter().all(|x| x.is_finite() && x.abs() <= MAX_FORCE_N))
        {
            return Err(SynthError::InvalidForce(*f));
        }
        let m = seg.oversample as u64;
        let first = seg.start / m;
        if first < self.pos {
            let t = seg.start as f64 / (m as f64 * self.fs);
            return Err(SynthError::InvalidTime(t, "force segment before the render position"));
        }
        let point = match seg.point {
            ImpactPoint::Position(p) => self.model.locate(p)?,
            ImpactPoint::Surface(p) => {
                if p.triangle < self.model.surface().triangles.len() && p.bary.iter().all(|x| x.is_finite()) {
                    p
                } else {
                    return Err(SynthError::InvalidPoint(p.position));
                }
            }
        };
        if !self.gains_set {
            self.set_mic(&point);
        }
        self.stats.segments += 1;
        if seg.forces.len() < 2 {
            return Ok(point);
        }
        self.pending.push((first, self.seq, seg, point));
        self.pending_sorted = false;
        self.seq += 1;
        Ok(point)
    }

    fn activate(&mut self, seq: u64, seg: ForceSegment, point: SurfacePoint) {
        let n = self.model.mode_count();
        let m = seg.oversample as u64;
        let mut coef = vec![[0.0; 3]; n];
        for (c, e) in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].into_iter().enumerate() {
            self.model.shapes_dot(&point, e, &mut self.phi);
            for (k, x) in coef.iter_mut().zip(&self.phi) {
                k[c] = *x;
            }
        }
        let last_knot = seg.start + seg.forces.len() as u64 - 1;
        let first = seg.start / m;
        let end = (last_knot - 1) / m + 1;
        let fine = if m > 1 {
            let h = 1.0 / (m as f64 * self.fs);
            (0..n)
                .map(|i| {
                    if self.enabled[i] {
                        let (a, b) = foh_coefficients(self.s[i], h);
                        (self.s[i].scale(h).exp(), a, b)
                    } else {
                        (C64::ZERO, C64::ZERO, C64::ZERO)
                    }
                })
                .collect()
        } else {
            Vec::new()
        };
        for (i, c) in coef.iter().enumerate() {
            if self.enabled[i] && *c != [0.0; 3] && !self.is_active[i] {
                self.is_active[i] = true;
                self.active.push(i);
            }
        }
        self.active.sort_unstable();
        if let Some(t) = self.simd.as_mut() {
            t.dirty = true;
        }
        let live = Live { seq, start: seg.start, m, forces: seg.forces, coef, first, end, fine };
        let at = self.live.partition_point(|l| l.seq < seq);
        self.live.insert(at, live);
    }

    /// Drops quiet modes at grid point `self.pos` when no force acts.
    fn cull(&mut self) {
        self.culled_at = Some(self.pos);
        let amp2: Vec<f64> = self.active.iter().map(|&i| (self.w[i] * self.z[i]).norm2()).collect();
        let loudest = amp2.iter().cloned().fold(0.0, f64::max);
        let mut t2 = ABSOLUTE_FLOOR * ABSOLUTE_FLOOR;
        if let Some(db) = self.opts.cull_db {
            t2 = t2.max(loudest * 10f64.powf(db / 10.0));
        }
        let mut keep = Vec::with_capacity(self.active.len());
        for (k, &i) in self.active.iter().enumerate() {
            if amp2[k] >= t2 && amp2[k] > 0.0 {
                keep.push(i);
            } else {
                self.is_active[i] = false;
                self.z[i] = C64::ZERO;
            }
        }
        self.active = keep;
        if let Some(t) = self.simd.as_mut() {
            t.dirty = true;
        }
    }

    /// ADDS the output for samples `start_sample .. start_sample + out.len()`
    /// to `out`. `start_sample` must not lie before [`Self::position`]; a
    /// later start renders (and discards) the samples in between. The
    /// result does not depend on how a span is split into calls.
    pub fn render(&mut self, out: &mut [f32], start_sample: u64) {
        assert!(start_sample >= self.pos, "DrivenVoice::render: start before the render position");
        let mut skip = vec![0.0f32; (start_sample - self.pos).min(1 << 16) as usize];
        while self.pos < start_sample {
            let len = ((start_sample - self.pos) as usize).min(skip.len());
            let at = self.pos;
            self.render_span_into(&mut skip[..len], at);
        }
        self.render_span_into(out, start_sample);
    }

    fn render_span_into(&mut self, out: &mut [f32], start_sample: u64) {
        if !self.pending_sorted {
            self.pending.sort_unstable_by_key(|p| std::cmp::Reverse((p.0, p.1)));
            self.pending_sorted = true;
        }
        let end = start_sample + out.len() as u64;
        let b = BLOCK as u64;
        while self.pos < end {
            while self.pending.last().is_some_and(|p| p.0 <= self.pos) {
                if let Some((_, seq, seg, point)) = self.pending.pop() {
                    self.activate(seq, seg, point);
                }
            }
            let pos = self.pos;
            self.live.retain(|l| l.end > pos);
            if self.live.is_empty() && pos.is_multiple_of(b) && self.culled_at != Some(pos) {
                self.cull();
            }
            let next_pending = self.pending.last().map_or(u64::MAX, |p| p.0);
            if self.active.is_empty() && self.live.is_empty() {
                self.pos = end.min(next_pending);
                continue;
            }
            let mut stop = end.min(next_pending).min((pos / b + 1) * b);
            for l in &self.live {
                stop = stop.min(if l.first > pos { l.first } else { l.end });
            }
            let (lo, hi) = ((pos - start_sample) as usize, (stop - start_sample) as usize);
            if self.simd.is_some() {
                self.span_tiles(&mut out[lo..hi]);
            } else {
                self.span(&mut out[lo..hi]);
            }
            let len = stop - pos;
            self.stats.samples_rendered += len;
            self.stats.mode_samples += len * self.active.len() as u64;
            self.pos = stop;
            if self.simd.is_some() && stop.is_multiple_of(b) {
                self.anchor();
            }
        }
    }

    /// Lays the active modes out in tiles (f32 constants), carrying the
    /// running state of modes already laid out; new modes (and all, at a
    /// grid point) start from `z`.
    fn relayout(&mut self) {
        let Some(t) = self.simd.as_deref_mut() else { return };
        for (q, &i) in t.modes.iter().enumerate() {
            t.cur[i] = (t.zr[q / FT][q % FT], t.zi[q / FT][q % FT]);
        }
        let laid: Vec<bool> = {
            let mut m = vec![false; self.z.len()];
            t.modes.iter().for_each(|&i| m[i] = true);
            m
        };
        t.modes.clear();
        t.modes.extend_from_slice(&self.active);
        let tiles = t.modes.len().div_ceil(FT);
        t.consts.clear();
        t.consts.resize(tiles, TileConsts::default());
        t.zr.clear();
        t.zr.resize(tiles, [0.0; FT]);
        t.zi.clear();
        t.zi.resize(tiles, [0.0; FT]);
        for (q, &i) in t.modes.iter().enumerate() {
            let (k, l) = (&mut t.consts[q / FT], q % FT);
            let (p, a, b, w) = (self.pole[i], self.a[i], self.b[i], self.w[i]);
            (k.pr[l], k.pi[l]) = (p.re as f32, p.im as f32);
            (k.ar[l], k.ai[l]) = (a.re as f32, a.im as f32);
            (k.br[l], k.bi[l]) = (b.re as f32, b.im as f32);
            (k.wr[l], k.wi[l]) = (w.re as f32, w.im as f32);
            // At a grid point the running state is the (anchored or culled) `z`.
            let fresh = !laid[i] || self.pos.is_multiple_of(BLOCK as u64);
            let (r, im) = if fresh { (self.z[i].re as f32, self.z[i].im as f32) } else { t.cur[i] };
            (t.zr[q / FT][l], t.zi[q / FT][l]) = (r, im);
        }
        t.dirty = false;
    }

    /// [`Self::span`] with the f32 tile kernel.
    fn span_tiles(&mut self, out: &mut [f32]) {
        if self.simd.as_ref().is_some_and(|t| t.dirty) {
            self.relayout();
        }
        let Some(t) = self.simd.as_deref_mut() else { return };
        let len = out.len();
        let n0 = self.pos;
        let tiles = t.consts.len();
        let covering: Vec<&Live> = self.live.iter().filter(|l| l.first <= n0).collect();
        let mut acting = 0;
        for l in covering.iter().filter(|l| l.m == 1) {
            if t.coef.len() <= acting {
                t.coef.push(Vec::new());
                t.knots.push(Vec::new());
            }
            let c = &mut t.coef[acting];
            c.clear();
            c.resize(tiles, [[0.0; FT]; 3]);
            for (q, &i) in t.modes.iter().enumerate() {
                for (comp, x) in l.coef[i].iter().enumerate() {
                    c[q / FT][comp][q % FT] = *x as f32;
                }
            }
            let off = (n0 - l.start) as usize;
            let k = &mut t.knots[acting];
            k.clear();
            k.extend(l.forces[off..=off + len].iter().map(|f| f.map(|x| x as f32)));
            acting += 1;
        }
        let any_fine = covering.iter().any(|l| l.m > 1);
        if any_fine {
            t.er.clear();
            t.er.resize(tiles * len, [0.0; FT]);
            t.ei.clear();
            t.ei.resize(tiles * len, [0.0; FT]);
            for (q, &i) in t.modes.iter().enumerate() {
                t.e64.clear();
                t.e64.resize(len, C64::ZERO);
                for l in covering.iter().filter(|l| l.m > 1) {
                    fine_contributions(l, i, n0, &mut t.e64);
                }
                for (j, e) in t.e64.iter().enumerate() {
                    t.er[(q / FT) * len + j][q % FT] = e.re as f32;
                    t.ei[(q / FT) * len + j][q % FT] = e.im as f32;
                }
            }
        }
        let forces: Vec<SpanForce<'_>> =
            (0..acting).map(|k| SpanForce { c: &t.coef[k], f: &t.knots[k] }).collect();
        let span = fk::Span {
            consts: &t.consts,
            zr: &mut t.zr,
            zi: &mut t.zi,
            forces: &forces,
            extra: any_fine.then_some((&t.er[..], &t.ei[..])),
        };
        fk::render_span(t.path, span, &mut t.scratch, out);
        t.forced |= acting > 0 || any_fine;
    }

    /// Moves the f64 anchor to this grid point (module doc) and restarts
    /// the f32 run from it.
    fn anchor(&mut self) {
        let Some(t) = self.simd.as_deref_mut() else { return };
        for (q, &i) in t.modes.iter().enumerate() {
            let (k, l) = (q / FT, q % FT);
            let z = self.z[i];
            let mut next = t.blk_p[i] * z;
            if t.forced {
                let v = C64::new(t.zr[k][l] as f64, t.zi[k][l] as f64);
                next += v - t.blk_q[i] * round32(z);
            }
            self.z[i] = next;
            (t.zr[k][l], t.zi[k][l]) = (next.re as f32, next.im as f32);
        }
        t.forced = false;
    }

    /// Advances the active modes over `out.len()` samples from `self.pos`
    /// (the set of live segments covering each interval is constant), adding
    /// the output.
    fn span(&mut self, out: &mut [f32]) {
        let len = out.len();
        let n0 = self.pos;
        self.acc.clear();
        self.acc.resize(len, 0.0);
        self.g.resize(len + 1, 0.0);
        self.e.resize(len, C64::ZERO);
        let covering: Vec<usize> = (0..self.live.len()).filter(|&k| self.live[k].first <= n0).collect();
        let any_fine = covering.iter().any(|&k| self.live[k].m > 1);
        for &i in &self.active {
            // Modal force knots g[j] at samples n0 + j (m = 1 segments).
            self.g.iter_mut().for_each(|x| *x = 0.0);
            for &k in &covering {
                let l = &self.live[k];
                if l.m != 1 {
                    continue;
                }
                let c = l.coef[i];
                let off = (n0 - l.start) as usize;
                for (j, g) in self.g.iter_mut().enumerate() {
                    let f = l.forces[off + j];
                    *g += c[0] * f[0] + c[1] * f[1] + c[2] * f[2];
                }
            }
            if any_fine {
                self.e.iter_mut().for_each(|x| *x = C64::ZERO);
                for &k in &covering {
                    let l = &self.live[k];
                    if l.m > 1 {
                        fine_contributions(l, i, n0, &mut self.e);
                    }
                }
            }
            let (p, a, b, w) = (self.pole[i], self.a[i], self.b[i], self.w[i]);
            let mut z = self.z[i];
            for j in 0..len {
                self.acc[j] += w.re * z.re - w.im * z.im;
                let (g0, g1) = (self.g[j], self.g[j + 1]);
                z = C64::new(
                    p.re * z.re - p.im * z.im + a.re * g0 + b.re * g1,
                    p.re * z.im + p.im * z.re + a.im * g0 + b.im * g1,
                );
                if any_fine {
                    z += self.e[j];
                }
            }
            self.z[i] = z;
        }
        for (o, y) in out.iter_mut().zip(&self.acc) {
            *o += *y as f32;
        }
    }
}

/// Contribution of an oversampled segment `l` to mode `i` over the sample
/// intervals `n0 .. n0 + e.len()` (the state change at each interval's end),
/// added to `e`.
fn fine_contributions(l: &Live, i: usize, n0: u64, e: &mut [C64]) {
    let (p, a, b) = l.fine[i];
    let c = l.coef[i];
    let g = |k: u64| {
        let f = l.forces[(k - l.start) as usize];
        c[0] * f[0] + c[1] * f[1] + c[2] * f[2]
    };
    let last = l.start + l.forces.len() as u64 - 1;
    for (j, ej) in e.iter_mut().enumerate() {
        let n = n0 + j as u64;
        let (lo, hi) = (n * l.m, (n + 1) * l.m);
        let (k0, k1) = (lo.max(l.start), hi.min(last));
        if k0 >= k1 {
            continue;
        }
        // Fine steps k0..k1, then free decay to the interval's end.
        let mut acc = C64::ZERO;
        for k in k0..k1 {
            acc = acc * p + (a.scale(g(k)) + b.scale(g(k + 1)));
        }
        for _ in k1..hi {
            acc = acc * p;
        }
        *ej += acc;
    }
}
