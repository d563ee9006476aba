//! f64 closed-form reference of a set of strikes, and signal error metrics.
//!
//! For strikes `k` (impulse `j_k` at surface point `p_k`, contact `τ_k`,
//! force centroid `t_k = time_k + τ_k/2`) and every synthesized mode `i`
//! (`s_i = −d_i + iω_{d,i}`, same skip rule as the voice:
//! [`crate::classify_mode`]) the exact output is
//!
//! `y(t) = Σ_k Σ_i g_i · Im(K_{k,i} e^{s_i (t − t_k)})` for `t ≥ t_k`, with
//! `z_{k,i} = (φ_i(p_k)·j_k) C(s_i τ_k) / ω_{d,i}` (so `q = Im z`) and
//! `K = s z` for velocity output (`q̇ = Im(s z)`), `K = z` for displacement.
//!
//! Each term is evaluated directly in f64 at every sample `n` (time `n/fs`,
//! included from `n = ⌈t_k fs⌉` on, the voice's sampling rule) as
//! `e^{−d τ}(K_re sin ω_d τ + K_im cos ω_d τ)`, `τ = n/fs − t_k`: one `exp`
//! and one `sin_cos` per term and sample, no recurrence, so no error grows
//! with time (phase error ≈ ε·ω_d τ, 1e-8 rad after 10 min at 20 kHz). A
//! term is dropped once `d τ > 50` (`e^{−50} ≈ 2e-22` of its own initial
//! amplitude, far below the f64 rounding of the sum). No culling, no budget.
//!
//! [`SignalError`] compares a rendered signal with the reference: relative
//! RMS error over the render and the largest absolute error relative to the
//! reference's peak.

use crate::complex::C64;
use crate::contact::{half_sine_spectrum, MAX_CONTACT_TIME_S};
use crate::error::SynthError;
use crate::model::SynthModel;
use crate::offline::Strike;
use crate::options::{check_phase_count, classify_mode, phase_of, OutputGain, OutputQuantity, SynthOptions};
use crate::surface::SurfacePoint;
use crate::voice::MAX_TIME_S;
use modal_bank::ModeBank;
use rayon::prelude::*;

/// Terms are dropped once their envelope fell by `e^{−TRUNCATE_DECAY}`.
const TRUNCATE_DECAY: f64 = 50.0;
/// Terms per unit of parallel work (fixed, so the sum order never changes).
const TERMS_PER_JOB: usize = 128;
/// Samples rendered per pass of [`ClosedForm::render`] (bounds scratch memory).
const SEGMENT: usize = 1 << 15;

/// One damped sinusoid: `e^{−d τ} Im(k e^{iωτ})`, `τ = n/fs − tc`, for `n ≥ first`.
#[derive(Clone, Copy, Debug)]
struct Term {
    first: u64,
    tc: f64,
    decay: f64,
    omega: f64,
    k: C64,
}

impl Term {
    #[inline]
    fn at(&self, n: u64, fs: f64) -> f64 {
        if n < self.first {
            return 0.0;
        }
        let tau = n as f64 / fs - self.tc;
        let dt = self.decay * tau;
        if dt > TRUNCATE_DECAY {
            return 0.0;
        }
        let (s, c) = (self.omega * tau).sin_cos();
        (-dt).exp() * (self.k.re * s + self.k.im * c)
    }
}

/// The exact sampled output of a set of strikes (module doc).
#[derive(Clone, Debug)]
pub struct ClosedForm {
    sample_rate: f64,
    terms: Vec<Term>,
    points: Vec<SurfacePoint>,
}

impl ClosedForm {
    /// Reference for `strikes` on `bank` with the gain model, output
    /// quantity and sample rate of `opts` (culling, budget and kernel are
    /// ignored). Errors as [`crate::ModalVoice::add_impulse`] does.
    pub fn new(bank: &ModeBank, strikes: &[Strike], opts: &SynthOptions) -> Result<ClosedForm, SynthError> {
        ClosedForm::from_model(&SynthModel::new(bank)?, strikes, opts)
    }

    /// As [`ClosedForm::new`] with an already checked model.
    pub fn from_model(
        model: &SynthModel,
        strikes: &[Strike],
        opts: &SynthOptions,
    ) -> Result<ClosedForm, SynthError> {
        opts.validate()?;
        let fs = opts.sample_rate;
        let points = strikes.iter().map(|s| check_strike(model, s)).collect::<Result<Vec<_>, _>>()?;
        let gains = resolve_gains(model, &opts.gain, points.first())?;
        let n = model.mode_count();
        check_phase_count(opts.phases.as_ref(), n)?;
        let mut a = vec![0.0; n];
        let mut terms = Vec::new();
        for (strike, point) in strikes.iter().zip(&points) {
            model.shapes_dot(point, strike.impulse_ns, &mut a);
            let tc = strike.time_s + 0.5 * strike.contact_time_s;
            let first = (tc * fs).ceil() as u64;
            for i in 0..n {
                let (f, d, xi) = (model.frequencies_hz[i], model.decay_rates[i], model.damping_ratios[i]);
                let Ok(s) = classify_mode(f, d, xi, fs) else { continue };
                if a[i] == 0.0 || gains[i] == 0.0 {
                    continue;
                }
                let z = half_sine_spectrum(s, strike.contact_time_s).scale(a[i] / s.im);
                // y = Re(c W z) = g Im(c s z) (velocity), g Im(c z) (displacement).
                let k = phase_of(opts.phases.as_ref(), i)
                    * match opts.quantity {
                        OutputQuantity::Velocity => (s * z).scale(gains[i]),
                        OutputQuantity::Displacement => z.scale(gains[i]),
                    };
                terms.push(Term { first, tc, decay: -s.re, omega: s.im, k });
            }
        }
        Ok(ClosedForm { sample_rate: fs, terms, points })
    }

    /// Sample rate \[Hz\].
    pub fn sample_rate(&self) -> f64 {
        self.sample_rate
    }

    /// The surface point each strike snapped to.
    pub fn points(&self) -> &[SurfacePoint] {
        &self.points
    }

    /// Number of damped sinusoids summed (strikes × excited modes).
    pub fn term_count(&self) -> usize {
        self.terms.len()
    }

    /// Output at sample `n` (time `n/fs`).
    pub fn sample(&self, n: u64) -> f64 {
        self.terms.iter().map(|t| t.at(n, self.sample_rate)).sum()
    }

    /// OVERWRITES `out` with samples `start .. start + out.len()`. Terms are
    /// evaluated in parallel in fixed groups summed in a fixed order, so the
    /// result does not depend on the thread count.
    pub fn render(&self, start: u64, out: &mut [f64]) {
        let fs = self.sample_rate;
        for (k, seg) in out.chunks_mut(SEGMENT).enumerate() {
            let s0 = start + (k * SEGMENT) as u64;
            let partials: Vec<Vec<f64>> = self
                .terms
                .par_chunks(TERMS_PER_JOB)
                .map(|group| {
                    let mut acc = vec![0.0; seg.len()];
                    for t in group {
                        for (m, y) in acc.iter_mut().enumerate() {
                            *y += t.at(s0 + m as u64, fs);
                        }
                    }
                    acc
                })
                .collect();
            seg.iter_mut().for_each(|y| *y = 0.0);
            for p in &partials {
                seg.iter_mut().zip(p).for_each(|(y, x)| *y += x);
            }
        }
    }
}

/// Validates a strike like [`crate::ModalVoice::add_impulse`] and locates it.
fn check_strike(model: &SynthModel, s: &Strike) -> Result<SurfacePoint, SynthError> {
    if !s.time_s.is_finite() || !(0.0..=MAX_TIME_S).contains(&s.time_s) {
        return Err(SynthError::InvalidTime(s.time_s, "impulse"));
    }
    if !s.impulse_ns.iter().all(|x| x.is_finite()) {
        return Err(SynthError::InvalidImpulse(s.impulse_ns));
    }
    if !s.contact_time_s.is_finite() || !(0.0..=MAX_CONTACT_TIME_S).contains(&s.contact_time_s) {
        return Err(SynthError::InvalidContactTime(s.contact_time_s));
    }
    model.locate(s.at)
}

/// Per-mode output gains `g_i` of a gain model; a `ContactMic { at: None }`
/// sits at `first_point` (all gains zero when there is none).
fn resolve_gains(
    model: &SynthModel,
    gain: &OutputGain,
    first_point: Option<&SurfacePoint>,
) -> Result<Vec<f64>, SynthError> {
    let n = model.mode_count();
    let mut g = vec![0.0; n];
    match gain {
        OutputGain::ContactMic { at } => {
            let mic = match at {
                Some(p) => Some(model.locate(*p)?),
                None => first_point.copied(),
            };
            if let Some(m) = mic {
                model.shapes_dot(&m, m.normal, &mut g);
            }
        }
        OutputGain::RadiationProxy => g = model.rms_normal_shapes(),
        OutputGain::PerMode(v) => {
            if v.len() != n {
                return Err(SynthError::GainCount { got: v.len(), expected: n });
            }
            g.copy_from_slice(v);
        }
    }
    Ok(g)
}

/// Error of a rendered signal against a reference of the same length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SignalError {
    /// `‖y − y_ref‖₂ / ‖y_ref‖₂` over the whole render.
    pub rel_rms: f64,
    /// `max |y − y_ref| / max |y_ref|`.
    pub max_rel: f64,
    /// `max |y_ref|` (output units).
    pub peak: f64,
}

impl SignalError {
    /// Compares `rendered` with `reference`. A zero reference gives 0 when
    /// `rendered` is zero too and infinity otherwise.
    ///
    /// # Panics
    /// When the lengths differ (a broken caller contract).
    pub fn between(rendered: &[f32], reference: &[f64]) -> SignalError {
        assert_eq!(rendered.len(), reference.len(), "SignalError: signal lengths differ");
        let (mut e2, mut r2, mut emax, mut peak) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for (&y, &r) in rendered.iter().zip(reference) {
            let e = y as f64 - r;
            e2 += e * e;
            r2 += r * r;
            emax = emax.max(e.abs());
            peak = peak.max(r.abs());
        }
        let ratio = |num: f64, den: f64| {
            if num == 0.0 {
                0.0
            } else if den == 0.0 {
                f64::INFINITY
            } else {
                num / den
            }
        };
        SignalError { rel_rms: ratio(e2.sqrt(), r2.sqrt()), max_rel: ratio(emax, peak), peak }
    }

    /// [`Self::rel_rms`] in dB (`20 log10`; −inf for an exact match).
    pub fn rel_rms_db(&self) -> f64 {
        20.0 * self.rel_rms.log10()
    }

    /// [`Self::max_rel`] in dB (`20 log10`; −inf for an exact match).
    pub fn max_rel_db(&self) -> f64 {
        20.0 * self.max_rel.log10()
    }
}
