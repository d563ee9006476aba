//! Options of a voice: sample rate, culling, output gain model, kernel.

use crate::complex::C64;
use crate::error::SynthError;

/// Lowest accepted sample rate \[Hz\].
pub const MIN_SAMPLE_RATE: f64 = 8_000.0;
/// Highest accepted sample rate \[Hz\].
pub const MAX_SAMPLE_RATE: f64 = 192_000.0;
/// Modes whose damped frequency is below this are not synthesized \[Hz\].
pub const MIN_FREQUENCY_HZ: f64 = 20.0;
/// Modes whose damped frequency is at or above this fraction of the sample
/// rate are not synthesized (no aliasing).
pub const MAX_FREQUENCY_FRACTION: f64 = 0.45;

/// Why a bank mode is not synthesized (see [`classify_mode`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SkipReason {
    /// Frequency, decay rate or damping ratio is NaN or infinite, or the
    /// decay rate is negative (a growing mode).
    NonFinite,
    /// Damping ratio ξ ≥ 1: no oscillation.
    Overdamped,
    /// Damped frequency below [`MIN_FREQUENCY_HZ`] (inaudible, incl. rigid modes at 0 Hz).
    BelowMinFrequency,
    /// Damped frequency at or above [`MAX_FREQUENCY_FRACTION`] × the sample
    /// rate: would alias (this includes every mode at or above Nyquist).
    AboveBand,
}

impl std::fmt::Display for SkipReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SkipReason::NonFinite => "non-finite or negative damping data",
            SkipReason::Overdamped => "overdamped (damping ratio >= 1)",
            SkipReason::BelowMinFrequency => "damped frequency below 20 Hz",
            SkipReason::AboveBand => "damped frequency at or above 0.45 x sample rate",
        })
    }
}

/// Complex frequency `s = −d + iω_d` [1/s] of a mode with undamped frequency
/// `f_hz`, decay rate `d` [1/s] and damping ratio `xi` at sample rate
/// `fs_hz`, with `ω_d = 2π f √(1 − ξ²)`; or why the mode is not synthesized.
pub fn classify_mode(f_hz: f64, d: f64, xi: f64, fs_hz: f64) -> Result<C64, SkipReason> {
    if !(f_hz.is_finite() && d.is_finite()) || d < 0.0 {
        return Err(SkipReason::NonFinite);
    }
    // f_d ≤ f: rigid (0 Hz) modes are "below 20 Hz" whatever their (then
    // undefined) damping ratio.
    if f_hz < MIN_FREQUENCY_HZ {
        return Err(SkipReason::BelowMinFrequency);
    }
    if !xi.is_finite() {
        return Err(SkipReason::NonFinite);
    }
    if xi >= 1.0 {
        return Err(SkipReason::Overdamped);
    }
    let fd = f_hz * (1.0 - xi * xi).max(0.0).sqrt();
    if fd < MIN_FREQUENCY_HZ {
        return Err(SkipReason::BelowMinFrequency);
    }
    if fd >= MAX_FREQUENCY_FRACTION * fs_hz {
        return Err(SkipReason::AboveBand);
    }
    Ok(C64::new(-d, 2.0 * std::f64::consts::PI * fd))
}

/// What the output measures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OutputQuantity {
    /// `y = Σ g_i q̇_i`: with contact-mic gains, normal surface velocity [m/s].
    #[default]
    Velocity,
    /// `y = Σ g_i q_i`: with contact-mic gains, normal surface displacement \[m\].
    Displacement,
}

/// Per-mode output gains `g_i` (see `docs/synthesis.md`).
#[derive(Clone, Debug, PartialEq)]
pub enum OutputGain {
    /// Contact microphone: `g_i = φ_i(p_mic)·n(p_mic)` [1/√kg], the normal
    /// surface motion at a point. `at: None` puts the microphone at the first
    /// struck point (the first `add_impulse` call); `Some(x)` snaps `x` \[m\] to
    /// the surface.
    ContactMic {
        /// Microphone position \[m\], or `None` for the first struck point.
        at: Option<[f64; 3]>,
    },
    /// Radiation/listener proxy: `g_i` = area-weighted RMS over the surface of
    /// `φ_i·n` [1/√kg], so the output is the RMS normal surface velocity [m/s]
    /// (or displacement) that a mode's motion produces; distance attenuation
    /// and delay belong to the listener (scene).
    RadiationProxy,
    /// Explicit gains, one per bank mode.
    PerMode(Vec<f64>),
}

impl Default for OutputGain {
    fn default() -> Self {
        OutputGain::ContactMic { at: None }
    }
}

/// Which kernel renders the samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Kernel {
    /// f32 SIMD kernel with run-time CPU feature dispatch (AVX-512/AVX2+FMA).
    #[default]
    Auto,
    /// f32 kernel without run-time dispatch (baseline target features).
    Portable,
    /// Scalar f64 reference recurrence (slow; for tests and error bounds).
    Reference,
}

/// Options of a [`crate::ModalVoice`].
#[derive(Clone, Debug, PartialEq)]
pub struct SynthOptions {
    /// Sample rate \[Hz\], 8 000 ..= 192 000.
    pub sample_rate: f64,
    /// A mode leaves the active set when its envelope falls this many dB
    /// below the loudest active mode (negative, e.g. −100); `None` disables
    /// relative culling (an absolute floor of 1e-30 output units remains so
    /// that nothing reaches denormal range).
    pub cull_db: Option<f64>,
    /// Keep at most this many modes active, the loudest by current amplitude.
    pub budget: Option<usize>,
    /// Per-mode output gains.
    pub gain: OutputGain,
    /// A constant complex factor `c_i` on each mode's output weight,
    /// `y = Σ_i Re(c_i W_i z_i)`, one per bank mode (normally of modulus 1: a
    /// phase). A listener's per-mode transfer has a phase as well as a level;
    /// with the level alone, modes of one frequency (the pairs of symmetric
    /// bodies) add or cancel by how the eigensolver happened to turn them.
    /// `None`: every `c_i = 1`.
    pub phases: Option<Vec<C64>>,
    /// Velocity or displacement output.
    pub quantity: OutputQuantity,
    /// Kernel choice.
    pub kernel: Kernel,
    /// Render chunks of modes on the rayon pool when a voice has at least
    /// [`crate::PARALLEL_MIN_MODES`] active modes. Results are bit-identical
    /// either way.
    pub parallel: bool,
}

impl Default for SynthOptions {
    fn default() -> Self {
        SynthOptions {
            sample_rate: 48_000.0,
            cull_db: Some(-100.0),
            budget: None,
            gain: OutputGain::default(),
            phases: None,
            quantity: OutputQuantity::Velocity,
            kernel: Kernel::Auto,
            parallel: true,
        }
    }
}

/// Checks that `phases`, when given, has one factor per mode of a bank of
/// `modes` modes.
pub(crate) fn check_phase_count(phases: Option<&Vec<C64>>, modes: usize) -> Result<(), SynthError> {
    match phases {
        Some(p) if p.len() != modes => Err(SynthError::GainCount { got: p.len(), expected: modes }),
        _ => Ok(()),
    }
}

/// Mode `i`'s factor of [`SynthOptions::phases`] (1 without them).
pub(crate) fn phase_of(phases: Option<&Vec<C64>>, i: usize) -> C64 {
    phases.map_or(C64::new(1.0, 0.0), |p| p[i])
}

/// Checks a sample rate: finite and within 8 kHz ..= 192 kHz.
pub fn check_sample_rate(rate: f64) -> Result<(), SynthError> {
    if rate.is_finite() && (MIN_SAMPLE_RATE..=MAX_SAMPLE_RATE).contains(&rate) {
        Ok(())
    } else {
        Err(SynthError::SampleRate(rate))
    }
}

impl SynthOptions {
    /// Validates the options.
    pub fn validate(&self) -> Result<(), SynthError> {
        check_sample_rate(self.sample_rate)?;
        if let Some(db) = self.cull_db {
            if !db.is_finite() || db > 0.0 {
                return Err(SynthError::InvalidOption { name: "cull_db", value: db });
            }
        }
        if let OutputGain::ContactMic { at: Some(p) } = self.gain {
            if !p.iter().all(|x| x.is_finite()) {
                return Err(SynthError::InvalidPoint(p));
            }
        }
        if let OutputGain::PerMode(g) = &self.gain {
            if let Some(&bad) = g.iter().find(|x| !x.is_finite()) {
                return Err(SynthError::InvalidOption { name: "gain", value: bad });
            }
        }
        if let Some(bad) = self.phases.iter().flatten().find(|c| !c.is_finite()) {
            return Err(SynthError::InvalidOption { name: "phase", value: bad.re + bad.im });
        }
        Ok(())
    }
}
