//! Offline convenience: strike a bank a few times and render the whole sound.
//!
//! Automatic duration: with per-mode output amplitudes `A_k` of every
//! impulse (taken at its own time `t_k`) the output envelope is bounded by
//! `E(t) = Σ_k A_k e^{−d_k (t − t_k)}` (terms start at `t_k`). The sound ends
//! at the first `t ≥` the last impulse where `E(t) ≤ 10^{−60/20} · max_k E(t_k)`
//! (60 dB below the peak bound); if that exceeds the cap, the render stops at
//! the cap with a [`FADE_S`] raised-cosine fade-out.

use crate::contact::DEFAULT_CONTACT_TIME_S;
use crate::error::SynthError;
use crate::options::SynthOptions;
use crate::surface::SurfacePoint;
use crate::voice::{ModalVoice, VoiceStats, BLOCK};
use modal_bank::ModeBank;

/// Longest offline render \[s\] (bounds the output allocation).
pub const MAX_DURATION_S: f64 = 3600.0;
/// Fade-out applied when the automatic duration hits its cap \[s\].
pub const FADE_S: f64 = 0.05;
/// Shortest automatic duration \[s\].
pub const MIN_AUTO_DURATION_S: f64 = 0.1;
/// Decay (dB below the peak envelope) at which the automatic duration ends.
pub const AUTO_DECAY_DB: f64 = 60.0;

/// One strike of an offline render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strike {
    /// Contact start \[s\].
    pub time_s: f64,
    /// Point \[m\] in the bank frame, snapped to the surface.
    pub at: [f64; 3],
    /// Impulse vector [N·s].
    pub impulse_ns: [f64; 3],
    /// Contact time \[s\] (0 = ideal impulse).
    pub contact_time_s: f64,
}

impl Strike {
    /// An impulse `impulse_ns` at `at`, time 0, default contact time.
    pub fn new(at: [f64; 3], impulse_ns: [f64; 3]) -> Strike {
        Strike { time_s: 0.0, at, impulse_ns, contact_time_s: DEFAULT_CONTACT_TIME_S }
    }
}

/// How long to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RenderLength {
    /// Exactly this many seconds.
    Fixed(f64),
    /// Until the output decayed by 60 dB (module doc), at most `cap_s`.
    Auto {
        /// Longest duration \[s\].
        cap_s: f64,
    },
}

/// Result of [`render_strikes`].
#[derive(Clone, Debug)]
pub struct Rendered {
    /// Mono samples (output units, m/s for the default contact microphone).
    pub samples: Vec<f32>,
    /// Sample rate \[Hz\].
    pub sample_rate: f64,
    /// The surface point each strike snapped to.
    pub points: Vec<SurfacePoint>,
    /// Rendered duration \[s\].
    pub duration_s: f64,
    /// True when the automatic duration hit its cap (a fade-out was applied).
    pub capped: bool,
    /// Voice counters.
    pub stats: VoiceStats,
}

fn check_duration(name: &'static str, d: f64) -> Result<(), SynthError> {
    if d.is_finite() && (0.0..=MAX_DURATION_S).contains(&d) {
        Ok(())
    } else {
        Err(SynthError::InvalidOption { name, value: d })
    }
}

/// Strikes `bank` and renders the result (see module doc).
pub fn render_strikes(
    bank: &ModeBank,
    strikes: &[Strike],
    opts: &SynthOptions,
    length: RenderLength,
) -> Result<Rendered, SynthError> {
    let mut voice = ModalVoice::new(bank, opts.clone())?;
    let mut points = Vec::with_capacity(strikes.len());
    for s in strikes {
        points.push(voice.add_impulse(s.time_s, s.at, s.impulse_ns, s.contact_time_s)?);
    }
    let (duration_s, capped) = match length {
        RenderLength::Fixed(d) => {
            check_duration("duration", d)?;
            (d, false)
        }
        RenderLength::Auto { cap_s } => {
            check_duration("duration cap", cap_s)?;
            auto_duration(&mut voice, cap_s)
        }
    };
    let n = (duration_s * voice.sample_rate()).round() as usize;
    let mut samples = vec![0.0f32; n];
    for (k, block) in samples.chunks_mut(16 * BLOCK).enumerate() {
        voice.render(block, (k * 16 * BLOCK) as u64);
    }
    if capped {
        fade_out(&mut samples, (FADE_S * voice.sample_rate()) as usize);
    }
    Ok(Rendered {
        samples,
        sample_rate: voice.sample_rate(),
        points,
        duration_s,
        capped,
        stats: voice.stats(),
    })
}

/// Time \[s\] at which `voice`'s output (current state plus pending impulses)
/// has decayed by [`AUTO_DECAY_DB`], at least [`MIN_AUTO_DURATION_S`] and at
/// most `cap_s`; the flag tells whether the cap was hit.
pub fn auto_duration(voice: &mut ModalVoice, cap_s: f64) -> (f64, bool) {
    let terms = voice.envelope_terms();
    let envelope = |t: f64| -> f64 {
        terms.iter().filter(|(t0, _, _)| *t0 <= t).map(|&(t0, d, a)| a * (-d * (t - t0)).exp()).sum()
    };
    let t_last = terms.iter().map(|t| t.0).fold(0.0, f64::max);
    let peak = terms.iter().map(|t| envelope(t.0)).fold(0.0, f64::max);
    let target = peak * 10f64.powf(-AUTO_DECAY_DB / 20.0);
    let floor = MIN_AUTO_DURATION_S.min(cap_s);
    if peak == 0.0 {
        return (t_last.max(floor).min(cap_s), false);
    }
    if envelope(cap_s) > target {
        return (cap_s, true);
    }
    let (mut lo, mut hi) = (t_last.min(cap_s), cap_s);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if envelope(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (hi.max(floor), false)
}

/// Raised-cosine fade over the last `n` samples (all of them if fewer).
pub fn fade_out(samples: &mut [f32], n: usize) {
    let n = n.min(samples.len());
    let start = samples.len() - n;
    for (k, x) in samples[start..].iter_mut().enumerate() {
        let t = (k + 1) as f64 / n as f64;
        *x *= (0.5 * (1.0 + (std::f64::consts::PI * t).cos())) as f32;
    }
}
