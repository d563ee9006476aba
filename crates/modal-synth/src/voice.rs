//! [`ModalVoice`]: one sounding object, driven by impulses, rendered in blocks.
//!
//! Mode `i` (undamped ω_i, decay rate d_i, damping ratio ξ_i) has complex
//! frequency `s_i = −d_i + iω_{d,i}`, `ω_d = ω√(1 − ξ²)`. Its modal
//! displacement is `q_i = Im z_i`, where an impulse with modal velocity `a_i`
//! at time `t_e` contributes `z_i(t) = (a_i/ω_{d,i}) e^{s_i (t − t_e)}` for
//! `t ≥ t_e` (so `q_i = a_i/ω_d e^{−d t} sin ω_d t`). The output is
//! `y = Σ_i Re(W_i z_i)` with `W_i = g_i(ω_d + i d)` for velocity
//! (`Re(W z) = g q̇`) and `W_i = −i g_i` for displacement (`Re(W z) = g q`).
//! The voice stores `u_i = W_i z_i`, so the kernel only sums real parts.
//!
//! Time is sampled at `t_n = n/fs`; sample `n` holds `y(t_n)`.
//!
//! Precision: the f32 kernel runs for at most one block ([`BLOCK`] samples);
//! at each block start (grid point `n = kB`) the state is reloaded from an
//! f64 value: every [`REANCHOR_BLOCKS`] blocks, and after any event, exactly
//! from the per-mode f64 anchor (the sum of all applied events at the time of
//! the last event, `u(t) = anchor · e^{s (t − t_anchor)}`), and in between by
//! one f64 complex multiply with `e^{sB/fs}`. So f32 rounding never
//! accumulates beyond one block, and f64 rounding beyond 16 blocks.
//!
//! An event at (centroid) time `t_e` is applied at the first sample
//! `n_e = ⌈t_e fs⌉` by adding `u e^{s (n_e/fs − t_e)}` — exact for fractional
//! times. Events may be added in any order; they are exact whenever
//! `n_e ≥` the render position, otherwise applied late (at the current
//! position, with the phase and decay they would have had; the part of the
//! output before the current position is lost).
//!
//! Modulation ([`ModalVoice::set_modulation`], module `modulation`): the
//! output weights may carry time-varying complex factors `m_i(t)`,
//! `y = Σ_i Re(m_i W_i z_i)`, evaluated at block edges and interpolated
//! geometrically inside a block (the kernel then runs `m u` with pole `ρ p`).
//! The f64 anchors, the grid states and the culling stay unmodulated; the
//! current state at an event is then taken exactly from the anchor.
//!
//! Culling: at every grid point a mode whose amplitude `|u|` there is below
//! `10^{cull_db/20}` times the loudest active mode, or below the absolute
//! floor [`ABSOLUTE_FLOOR`], leaves the active set for good (its state is
//! zeroed; a later event re-excites it). With a budget only the loudest
//! `budget` modes stay. The amplitude at the START of the block decides: a
//! heavily damped mode (d·B/fs ≫ 1) is loud at the start of a block and
//! silent at its end, and must still be rendered (judging by the end, as an
//! earlier version did, dropped such modes while audible: 4e-4 of the peak
//! for ξ = 0.9 at 15 kHz). A mode that decays through the f32 denormal range
//! inside a block (d > ≈ 3 500/s at 48 kHz) does so for at most that one
//! block: at the next grid point it is below the floor and dropped, so
//! denormal arithmetic never persists.

use crate::complex::C64;
use crate::contact::{half_sine_spectrum, MAX_CONTACT_TIME_S};
use crate::error::SynthError;
use crate::kernel::{self, LaneBuf, SimdPath, CHUNK, LANES, TILE};
use crate::model::SynthModel;
use crate::modulation::{Modulation, OutputModulation};
use crate::options::{
    check_phase_count, classify_mode, phase_of, Kernel, OutputQuantity, SkipReason, SynthOptions,
};
use crate::surface::SurfacePoint;
use modal_bank::ModeBank;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::Arc;

/// Samples per block (grid spacing of the f64 re-anchoring).
pub const BLOCK: usize = 256;
/// Exact re-anchoring from the f64 anchor at least every this many blocks.
pub const REANCHOR_BLOCKS: u64 = 16;
/// Modes whose envelope falls below this (output units) are dropped even
/// with culling off, so nothing reaches f32 denormal range.
pub const ABSOLUTE_FLOOR: f64 = 1e-30;
/// Active modes from which chunks are rendered in parallel.
pub const PARALLEL_MIN_MODES: usize = 2 * CHUNK;
/// Largest accepted bound on the output magnitude (output units): the sum
/// over all impulses of a voice of their per-mode initial amplitudes. Far
/// inside the f32 range (3.4e38), so the f32 kernel and its partial sums
/// can never overflow; an impulse that would exceed it is refused with
/// [`SynthError::OutputOverflow`] instead of rendering `inf`/NaN.
pub const MAX_OUTPUT: f64 = 1e30;
/// Largest accepted event time \[s\] (about 31 years).
pub const MAX_TIME_S: f64 = 1e9;

/// Output weight `W` with `Re(W z) = g q̇` (velocity) or `g q` (displacement),
/// for `q = Im z` and `q̇ = Im(s z)`.
pub(crate) fn weight(quantity: OutputQuantity, s: C64, g: f64) -> C64 {
    match quantity {
        OutputQuantity::Velocity => C64::new(g * s.im, -g * s.re),
        OutputQuantity::Displacement => C64::new(0.0, -g),
    }
}

/// Where an impulse lands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ImpactPoint {
    /// A position \[m\] in the bank's frame, snapped to the nearest surface point.
    Position([f64; 3]),
    /// An already located surface point.
    Surface(SurfacePoint),
}

impl From<[f64; 3]> for ImpactPoint {
    fn from(p: [f64; 3]) -> Self {
        ImpactPoint::Position(p)
    }
}

impl From<SurfacePoint> for ImpactPoint {
    fn from(p: SurfacePoint) -> Self {
        ImpactPoint::Surface(p)
    }
}

/// Counters of a voice (cumulative since creation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VoiceStats {
    /// Modes in the bank.
    pub modes_total: usize,
    /// Modes never synthesized: overdamped, damped frequency < 20 Hz or
    /// ≥ 0.45·fs, or non-finite data.
    pub modes_skipped: usize,
    /// Of the skipped modes, those at or above 0.45·fs (incl. Nyquist and
    /// beyond): dropped so that nothing aliases.
    pub modes_above_band: usize,
    /// Modes active right now.
    pub modes_active: usize,
    /// Times a mode left the active set (culling or budget).
    pub modes_culled: u64,
    /// Σ over rendered samples of the active mode count.
    pub mode_samples: u64,
    /// Samples on which the kernel ran.
    pub samples_rendered: u64,
    /// Samples skipped because the voice was silent.
    pub samples_silent: u64,
    /// Impulses applied.
    pub events: u64,
}

/// One mode's response to an impulse (see [`ModalVoice::excitation`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExcitedMode {
    /// Index of the mode in the bank.
    pub mode: usize,
    /// Damped frequency \[Hz\].
    pub frequency_hz: f64,
    /// Decay rate d [1/s].
    pub decay_rate: f64,
    /// Initial amplitude of the mode's output contribution (output units,
    /// m/s for a contact mic).
    pub amplitude: f64,
}

#[derive(Clone, Debug)]
struct Event {
    /// Force centroid time \[s\].
    tc: f64,
    /// First sample at or after `tc`.
    sample: u64,
    seq: u64,
    point: SurfacePoint,
    impulse: [f64; 3],
    tau: f64,
}

/// Per-mode constants and f64 state (full bank size).
#[derive(Clone, Debug, Default)]
struct Modes {
    enabled: Vec<bool>,
    /// `s = −d + iω_d` [1/s].
    s: Vec<C64>,
    /// `e^{s/fs}`.
    pole: Vec<C64>,
    /// `e^{sB/fs}`.
    pole_block: Vec<C64>,
    /// Output weight `W`.
    w: Vec<C64>,
    /// Weighted state at `t_anchor` (zero for inactive modes).
    anchor: Vec<C64>,
    /// Weighted state at the last grid point (valid for active modes).
    grid: Vec<C64>,
}

/// Compacted active modes in kernel layout.
#[derive(Clone, Debug, Default)]
struct Active {
    idx: Vec<usize>,
    r32: Vec<f32>,
    i32: Vec<f32>,
    pr32: Vec<f32>,
    pi32: Vec<f32>,
    r64: Vec<f64>,
    i64: Vec<f64>,
    pr64: Vec<f64>,
    pi64: Vec<f64>,
}

/// One chunk's kernel arguments as zipped by the (parallel) iterators.
type ChunkJob<'a> = ((((&'a mut [f32], &'a mut [f32]), &'a [f32]), &'a [f32]), &'a mut ChunkScratch);

#[derive(Clone, Debug)]
struct ChunkScratch {
    lanes: Vec<LaneBuf>,
    out: Vec<f32>,
}

/// A struck object: modal state, pending impulses and the render position.
#[derive(Clone, Debug)]
pub struct ModalVoice {
    model: Arc<SynthModel>,
    opts: SynthOptions,
    fs: f64,
    path: Option<SimdPath>,
    modes: Modes,
    active: Active,
    gains_set: bool,
    /// Next sample to render.
    pos: u64,
    t_anchor: f64,
    exact_next: bool,
    blocks_since_exact: u64,
    synced: Option<u64>,
    /// Pending events, sorted by DESCENDING (sample, tc, seq): the next is last.
    events: Vec<Event>,
    seq: u64,
    stats: VoiceStats,
    /// Why each bank mode is not synthesized (`None`: synthesized).
    skip: Vec<Option<SkipReason>>,
    /// Sum over scheduled impulses of `Σ_i |u_i|`: a bound on `|y|`.
    output_bound: f64,
    /// Scratch full-size state, zero between operations.
    cur: Vec<C64>,
    /// Scratch candidate and kept index lists.
    cand: Vec<usize>,
    keep: Vec<usize>,
    modal: Vec<f64>,
    chunks: Vec<ChunkScratch>,
    seg64: Vec<f64>,
    /// Time-varying complex factors on the output weights.
    modulation: Option<Modulation>,
    ramp: Vec<(C64, C64)>,
}

impl ModalVoice {
    /// A silent voice for `bank`.
    pub fn new(bank: &ModeBank, opts: SynthOptions) -> Result<ModalVoice, SynthError> {
        ModalVoice::from_model(Arc::new(SynthModel::new(bank)?), opts)
    }

    /// A silent voice sharing an already checked model.
    pub fn from_model(model: Arc<SynthModel>, opts: SynthOptions) -> Result<ModalVoice, SynthError> {
        opts.validate()?;
        let n = model.mode_count();
        let fs = opts.sample_rate;
        let mut modes = Modes {
            enabled: vec![false; n],
            s: vec![C64::ZERO; n],
            pole: vec![C64::ZERO; n],
            pole_block: vec![C64::ZERO; n],
            w: vec![C64::ZERO; n],
            anchor: vec![C64::ZERO; n],
            grid: vec![C64::ZERO; n],
        };
        let skip: Vec<Option<SkipReason>> = (0..n)
            .map(|i| {
                let (f, d, xi) = (model.frequencies_hz[i], model.decay_rates[i], model.damping_ratios[i]);
                let s = match classify_mode(f, d, xi, fs) {
                    Ok(s) => s,
                    Err(reason) => return Some(reason),
                };
                modes.enabled[i] = true;
                modes.s[i] = s;
                modes.pole[i] = s.scale(1.0 / fs).exp();
                modes.pole_block[i] = s.scale(BLOCK as f64 / fs).exp();
                None
            })
            .collect();
        let path = match opts.kernel {
            Kernel::Auto => Some(SimdPath::detect()),
            Kernel::Portable => Some(SimdPath::Portable),
            Kernel::Reference => None,
        };
        let mut voice = ModalVoice {
            model,
            fs,
            path,
            modes,
            active: Active::default(),
            gains_set: false,
            pos: 0,
            t_anchor: 0.0,
            exact_next: true,
            blocks_since_exact: 0,
            synced: None,
            events: Vec::new(),
            seq: 0,
            stats: VoiceStats {
                modes_total: n,
                modes_skipped: skip.iter().filter(|r| r.is_some()).count(),
                modes_above_band: skip.iter().filter(|r| **r == Some(SkipReason::AboveBand)).count(),
                ..VoiceStats::default()
            },
            skip,
            output_bound: 0.0,
            cur: vec![C64::ZERO; n],
            cand: Vec::new(),
            keep: Vec::new(),
            modal: vec![0.0; n],
            chunks: Vec::new(),
            seg64: Vec::new(),
            modulation: None,
            ramp: Vec::new(),
            opts,
        };
        check_phase_count(voice.opts.phases.as_ref(), voice.model.mode_count())?;
        if let Some(g) = voice.model.initial_gains(&voice.opts.gain)? {
            voice.set_gains(&g);
        }
        Ok(voice)
    }

    fn set_mic(&mut self, p: &SurfacePoint) {
        let g = self.model.mic_gains(p);
        self.set_gains(&g);
    }

    fn set_gains(&mut self, g: &[f64]) {
        for (i, &gi) in g.iter().enumerate() {
            let phase = phase_of(self.opts.phases.as_ref(), i);
            self.modes.w[i] = phase * weight(self.opts.quantity, self.modes.s[i], gi);
        }
        self.gains_set = true;
    }

    /// Multiplies each mode's output weight by the complex factor
    /// `source` gives as a function of time (module doc; e.g. the acoustic
    /// transfer to an ear of a moving body). Takes effect at the current
    /// position: the active modes are reloaded.
    pub fn set_modulation(&mut self, source: Arc<dyn OutputModulation>) {
        self.modulation = Some(Modulation::new(source));
        let pos = self.pos;
        self.jump_to_sample(pos);
    }

    /// The shared model.
    pub fn model(&self) -> &Arc<SynthModel> {
        &self.model
    }

    /// Sample rate \[Hz\].
    pub fn sample_rate(&self) -> f64 {
        self.fs
    }

    /// Next sample index to render.
    pub fn position(&self) -> u64 {
        self.pos
    }

    /// Counters.
    pub fn stats(&self) -> VoiceStats {
        VoiceStats { modes_active: self.active.idx.len(), ..self.stats }
    }

    /// True when no mode is active and no impulse is pending: rendering costs nothing.
    pub fn is_silent(&self) -> bool {
        self.active.idx.is_empty() && self.events.is_empty()
    }

    /// Why bank mode `mode` is not synthesized, or `None` when it is (or
    /// when `mode` is out of range).
    pub fn skip_reason(&self, mode: usize) -> Option<SkipReason> {
        self.skip.get(mode).copied().flatten()
    }

    /// Which f32 path renders (`None` for the f64 reference kernel).
    pub fn simd_path(&self) -> Option<SimdPath> {
        self.path
    }

    /// Snaps `at` to the surface (no-op for an already located point).
    pub fn locate(&self, at: ImpactPoint) -> Result<SurfacePoint, SynthError> {
        match at {
            ImpactPoint::Position(p) => self.model.locate(p),
            ImpactPoint::Surface(p) => {
                if p.triangle < self.model.surface().triangles.len() && p.bary.iter().all(|x| x.is_finite()) {
                    Ok(p)
                } else {
                    Err(SynthError::InvalidPoint(p.position))
                }
            }
        }
    }

    /// Schedules an impulse `impulse_ns` [N·s] (bank frame) at `at`, with the
    /// contact starting at `time_s` \[s\] and lasting `contact_time_s` \[s\]
    /// (0 = ideal impulse; the response is applied at the force centroid
    /// `time_s + contact_time_s/2`, see `contact`). Returns the struck surface
    /// point. The first call fixes a `ContactMic { at: None }` microphone.
    pub fn add_impulse(
        &mut self,
        time_s: f64,
        at: impl Into<ImpactPoint>,
        impulse_ns: [f64; 3],
        contact_time_s: f64,
    ) -> Result<SurfacePoint, SynthError> {
        if !time_s.is_finite() || !(0.0..=MAX_TIME_S).contains(&time_s) {
            return Err(SynthError::InvalidTime(time_s, "impulse"));
        }
        if !impulse_ns.iter().all(|x| x.is_finite()) {
            return Err(SynthError::InvalidImpulse(impulse_ns));
        }
        if !contact_time_s.is_finite() || !(0.0..=MAX_CONTACT_TIME_S).contains(&contact_time_s) {
            return Err(SynthError::InvalidContactTime(contact_time_s));
        }
        let point = self.locate(at.into())?;
        let bound = self.output_bound
            + self.excitation(&point, impulse_ns, contact_time_s).iter().map(|m| m.amplitude).sum::<f64>();
        if bound.is_nan() || bound > MAX_OUTPUT {
            return Err(SynthError::OutputOverflow { impulse: impulse_ns, bound, limit: MAX_OUTPUT });
        }
        self.output_bound = bound;
        if !self.gains_set {
            self.set_mic(&point);
        }
        let tc = time_s + 0.5 * contact_time_s;
        let sample = (tc * self.fs).ceil() as u64;
        let ev = Event { tc, sample, seq: self.seq, point, impulse: impulse_ns, tau: contact_time_s };
        self.seq += 1;
        if sample < self.pos {
            self.apply_event(&ev);
        } else {
            let key = |e: &Event| (e.sample, e.tc, e.seq);
            let at = self.events.partition_point(|e| {
                let (a, b) = (key(e), key(&ev));
                a.0 > b.0 || (a.0 == b.0 && (a.1 > b.1 || (a.1 == b.1 && a.2 > b.2)))
            });
            self.events.insert(at, ev);
        }
        Ok(point)
    }

    /// Output amplitude per mode that an impulse would excite, loudest first
    /// (modes with zero amplitude omitted). Uses this point as microphone if
    /// none is fixed yet.
    pub fn excitation(
        &self,
        point: &SurfacePoint,
        impulse_ns: [f64; 3],
        contact_time_s: f64,
    ) -> Vec<ExcitedMode> {
        let n = self.model.mode_count();
        let mut a = vec![0.0; n];
        self.model.shapes_dot(point, impulse_ns, &mut a);
        let mut w = self.modes.w.clone();
        if !self.gains_set {
            let mut g = vec![0.0; n];
            self.model.shapes_dot(point, point.normal, &mut g);
            for i in 0..n {
                w[i] = weight(self.opts.quantity, self.modes.s[i], g[i]);
            }
        }
        let mut out: Vec<ExcitedMode> = (0..n)
            .filter(|&i| self.modes.enabled[i])
            .map(|i| {
                let s = self.modes.s[i];
                let c = (w[i] * half_sine_spectrum(s, contact_time_s)).scale(a[i] / s.im);
                ExcitedMode {
                    mode: i,
                    frequency_hz: s.im / (2.0 * PI),
                    decay_rate: -s.re,
                    amplitude: c.abs(),
                }
            })
            .filter(|m| m.amplitude > 0.0)
            .collect();
        out.sort_by(|x, y| y.amplitude.total_cmp(&x.amplitude).then(x.mode.cmp(&y.mode)));
        out
    }

    /// Per-mode weighted contribution `W_i (a_i/ω_d) C(s_i τ)` of `ev` at its centroid time.
    fn contributions(&mut self, ev: &Event) {
        self.model.shapes_dot(&ev.point, ev.impulse, &mut self.modal);
    }

    fn contribution(&self, i: usize, ev: &Event) -> C64 {
        let s = self.modes.s[i];
        (self.modes.w[i] * half_sine_spectrum(s, ev.tau)).scale(self.modal[i] / s.im)
    }

    /// Adds `ev` to the f64 anchors (exact, any time order).
    fn anchor_event(&mut self, ev: &Event) {
        self.contributions(ev);
        let n = self.model.mode_count();
        if ev.tc >= self.t_anchor {
            let dt = ev.tc - self.t_anchor;
            for i in 0..n {
                if self.modes.anchor[i] != C64::ZERO {
                    self.modes.anchor[i] = self.modes.anchor[i] * self.modes.s[i].scale(dt).exp();
                }
            }
            self.t_anchor = ev.tc;
        }
        let back = self.t_anchor - ev.tc;
        for i in 0..n {
            if self.modes.enabled[i] && self.modal[i] != 0.0 {
                let c = self.contribution(i, ev);
                self.modes.anchor[i] += if back == 0.0 { c } else { c * self.modes.s[i].scale(back).exp() };
            }
        }
        self.stats.events += 1;
    }

    /// Applies `ev` at the current position: anchors plus current state.
    fn apply_event(&mut self, ev: &Event) {
        self.anchor_event(ev);
        if self.modulation.is_some() {
            // The kernel state is modulated: take the current state exactly
            // from the anchors (which now include `ev`).
            self.current_from_anchor();
            self.all_candidates();
            self.select_active();
            self.exact_next = true;
            return;
        }
        self.scatter_current();
        let dt = self.pos as f64 / self.fs - ev.tc;
        for i in 0..self.model.mode_count() {
            if self.modes.enabled[i] && self.modal[i] != 0.0 {
                let c = self.contribution(i, ev);
                self.cur[i] += c * self.modes.s[i].scale(dt).exp();
            }
        }
        self.all_candidates();
        self.select_active();
        self.exact_next = true;
    }

    /// `cur = anchor · e^{s (t − t_anchor)}` at the current position for
    /// every mode with a nonzero anchor (exact in f64).
    fn current_from_anchor(&mut self) {
        let t = self.pos as f64 / self.fs - self.t_anchor;
        for i in 0..self.model.mode_count() {
            let a = self.modes.anchor[i];
            self.cur[i] = if a == C64::ZERO { a } else { a * self.modes.s[i].scale(t).exp() };
        }
    }

    /// Copies the kernel state of active modes into `cur` (all other
    /// entries of `cur` are zero between operations).
    fn scatter_current(&mut self) {
        let a = &self.active;
        for (k, &i) in a.idx.iter().enumerate() {
            self.cur[i] = if self.path.is_some() {
                C64::new(a.r32[k] as f64, a.i32[k] as f64)
            } else {
                C64::new(a.r64[k], a.i64[k])
            };
        }
    }

    /// Enabled modes whose `cur` or anchor is nonzero, ascending, into `self.cand`.
    fn all_candidates(&mut self) {
        self.cand.clear();
        for i in 0..self.model.mode_count() {
            if self.modes.enabled[i] && (self.cur[i] != C64::ZERO || self.modes.anchor[i] != C64::ZERO) {
                self.cand.push(i);
            }
        }
    }

    /// Chooses the active set among `self.cand` (ascending; the only modes
    /// whose `cur` may be nonzero) from `|cur|`; zeroes the anchors of
    /// dropped modes, loads the kernel arrays and clears `cur` again.
    fn select_active(&mut self) {
        let cand = std::mem::take(&mut self.cand);
        let cur = &self.cur;
        let amp2 = |i: usize| cur[i].norm2();
        let loudest2 = cand.iter().map(|&i| amp2(i)).fold(0.0, f64::max);
        let mut threshold2 = ABSOLUTE_FLOOR * ABSOLUTE_FLOOR;
        if let Some(db) = self.opts.cull_db {
            threshold2 = threshold2.max(loudest2 * 10f64.powf(db / 10.0));
        }
        let mut keep = std::mem::take(&mut self.keep);
        keep.clear();
        keep.extend(cand.iter().copied().filter(|&i| amp2(i) >= threshold2));
        if let Some(b) = self.opts.budget {
            if keep.len() > b {
                keep.sort_by(|&x, &y| amp2(y).total_cmp(&amp2(x)).then(x.cmp(&y)));
                keep.truncate(b);
                keep.sort_unstable();
            }
        }
        // Drop (zero the anchors of) every candidate not kept.
        let mut kept = keep.iter().peekable();
        for &i in &cand {
            if kept.peek() == Some(&&i) {
                kept.next();
            } else if self.modes.anchor[i] != C64::ZERO {
                self.modes.anchor[i] = C64::ZERO;
                self.modes.grid[i] = C64::ZERO;
                self.stats.modes_culled += 1;
            }
        }
        self.load_active(keep);
        for &i in &cand {
            self.cur[i] = C64::ZERO;
        }
        self.cand = cand;
    }

    fn load_active(&mut self, idx: Vec<usize>) {
        let old = std::mem::take(&mut self.active.idx);
        self.keep = old;
        let padded = idx.len().div_ceil(TILE) * TILE;
        let a = &mut self.active;
        for v in [&mut a.r32, &mut a.i32, &mut a.pr32, &mut a.pi32] {
            v.clear();
            v.resize(padded, 0.0);
        }
        for v in [&mut a.r64, &mut a.i64, &mut a.pr64, &mut a.pi64] {
            v.clear();
        }
        let reference = self.path.is_none();
        if let Some(m) = self.modulation.as_mut() {
            m.ramp(self.pos, self.fs, &idx, &mut self.ramp);
        }
        let modulated = self.modulation.is_some();
        for (k, &i) in idx.iter().enumerate() {
            let (mut u, mut p) = (self.cur[i], self.modes.pole[i]);
            if modulated {
                let (m, rho) = self.ramp[k];
                (u, p) = (m * u, p * rho);
            }
            a.r32[k] = u.re as f32;
            a.i32[k] = u.im as f32;
            a.pr32[k] = p.re as f32;
            a.pi32[k] = p.im as f32;
            if reference {
                a.r64.push(u.re);
                a.i64.push(u.im);
                a.pr64.push(p.re);
                a.pi64.push(p.im);
            }
        }
        a.idx = idx;
    }

    /// Re-anchors the active modes at grid point `g` (module doc) and culls.
    fn grid_sync(&mut self, g: u64) {
        self.blocks_since_exact += 1;
        let exact = self.exact_next || self.blocks_since_exact >= REANCHOR_BLOCKS;
        let t = g as f64 / self.fs;
        self.cand.clear();
        self.cand.extend_from_slice(&self.active.idx);
        for &i in &self.active.idx {
            let u = if exact {
                self.modes.anchor[i] * self.modes.s[i].scale(t - self.t_anchor).exp()
            } else {
                self.modes.grid[i] * self.modes.pole_block[i]
            };
            self.modes.grid[i] = u;
            self.cur[i] = u;
        }
        if exact {
            self.blocks_since_exact = 0;
            self.exact_next = false;
        }
        self.select_active();
        self.synced = Some(g);
    }

    /// Moves the render position to `time_s` \[s\] (rounded up to a sample) in
    /// closed form: pending impulses before it are applied to the state
    /// exactly, their output before `time_s` is skipped.
    pub fn jump_to(&mut self, time_s: f64) -> Result<(), SynthError> {
        if !time_s.is_finite() || !(0.0..=MAX_TIME_S).contains(&time_s) {
            return Err(SynthError::InvalidTime(time_s, "jump"));
        }
        self.jump_to_sample((time_s * self.fs).ceil() as u64);
        Ok(())
    }

    /// Moves the render position to sample `n` in closed form (see [`Self::jump_to`]).
    /// Jumping backwards extrapolates the current free vibration backwards
    /// (applied impulses stay applied).
    pub fn jump_to_sample(&mut self, n: u64) {
        while self.events.last().is_some_and(|e| e.sample < n) {
            if let Some(ev) = self.events.pop() {
                self.anchor_event(&ev);
            }
        }
        self.pos = n;
        self.current_from_anchor();
        self.all_candidates();
        self.select_active();
        self.exact_next = true;
        self.synced = None;
    }

    /// ADDS the voice's output for samples `start_sample .. start_sample +
    /// out.len()` to `out`. When `start_sample` differs from
    /// [`Self::position`] the voice first jumps there ([`Self::jump_to_sample`]).
    /// The result does not depend on how a span is split into calls.
    pub fn render(&mut self, out: &mut [f32], start_sample: u64) {
        if start_sample != self.pos {
            self.jump_to_sample(start_sample);
        }
        let end = start_sample + out.len() as u64;
        while self.pos < end {
            while self.events.last().is_some_and(|e| e.sample <= self.pos) {
                if let Some(ev) = self.events.pop() {
                    self.apply_event(&ev);
                }
            }
            let next_event = self.events.last().map_or(u64::MAX, |e| e.sample);
            if self.active.idx.is_empty() {
                let next = end.min(next_event);
                self.stats.samples_silent += next - self.pos;
                self.pos = next;
                self.exact_next = true;
                continue;
            }
            let b = BLOCK as u64;
            if self.pos.is_multiple_of(b) && self.synced != Some(self.pos) {
                self.grid_sync(self.pos);
                continue;
            }
            let stop = end.min(next_event).min((self.pos / b + 1) * b);
            let (lo, hi) = ((self.pos - start_sample) as usize, (stop - start_sample) as usize);
            self.render_segment(&mut out[lo..hi]);
            self.stats.samples_rendered += stop - self.pos;
            self.stats.mode_samples += (stop - self.pos) * self.active.idx.len() as u64;
            self.pos = stop;
        }
    }

    fn render_segment(&mut self, out: &mut [f32]) {
        let len = out.len();
        let Some(path) = self.path else {
            self.seg64.clear();
            self.seg64.resize(len, 0.0);
            let a = &mut self.active;
            kernel::render_reference(&mut a.r64, &mut a.i64, &a.pr64, &a.pi64, &mut self.seg64);
            for (o, y) in out.iter_mut().zip(&self.seg64) {
                *o += *y as f32;
            }
            return;
        };
        let a = &mut self.active;
        let n_chunks = a.r32.len().div_ceil(CHUNK);
        while self.chunks.len() < n_chunks {
            self.chunks.push(ChunkScratch { lanes: vec![[0.0; LANES]; BLOCK], out: vec![0.0; BLOCK] });
        }
        let work = |((((r, i), p), q), sc): ChunkJob<'_>| {
            kernel::render_chunk(path, r, i, p, q, &mut sc.lanes, &mut sc.out[..len]);
        };
        if self.opts.parallel && a.idx.len() >= PARALLEL_MIN_MODES {
            a.r32
                .par_chunks_mut(CHUNK)
                .zip(a.i32.par_chunks_mut(CHUNK))
                .zip(a.pr32.par_chunks(CHUNK))
                .zip(a.pi32.par_chunks(CHUNK))
                .zip(self.chunks[..n_chunks].par_iter_mut())
                .for_each(work);
        } else {
            a.r32
                .chunks_mut(CHUNK)
                .zip(a.i32.chunks_mut(CHUNK))
                .zip(a.pr32.chunks(CHUNK))
                .zip(a.pi32.chunks(CHUNK))
                .zip(self.chunks[..n_chunks].iter_mut())
                .for_each(work);
        }
        for (s, o) in out.iter_mut().enumerate() {
            let mut acc = 0.0f32;
            for c in &self.chunks[..n_chunks] {
                acc += c.out[s];
            }
            *o += acc;
        }
    }

    /// Per-mode `(decay rate d [1/s], |u|)` of the current state plus every
    /// pending impulse taken at its own time, with the time it refers to:
    /// used to predict when the output has decayed.
    pub(crate) fn envelope_terms(&mut self) -> Vec<(f64, f64, f64)> {
        let mut terms = Vec::new();
        let t_now = self.pos as f64 / self.fs;
        if self.modulation.is_some() {
            // Every nonzero anchor belongs to an active mode (select_active).
            self.current_from_anchor();
        } else {
            self.scatter_current();
        }
        for &i in &self.active.idx {
            terms.push((t_now, -self.modes.s[i].re, self.cur[i].abs()));
            self.cur[i] = C64::ZERO;
        }
        let events = self.events.clone();
        for ev in &events {
            self.contributions(ev);
            for i in 0..self.model.mode_count() {
                if self.modes.enabled[i] && self.modal[i] != 0.0 {
                    terms.push((ev.tc, -self.modes.s[i].re, self.contribution(i, ev).abs()));
                }
            }
        }
        terms
    }
}
