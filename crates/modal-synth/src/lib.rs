//! `modal-synth`: modal synthesis — strike a mode bank, render audio, write WAV.
//!
//! Input: a [`modal_bank::ModeBank`] (frequencies, Rayleigh decay rates,
//! damping ratios, mass-normalized surface mode shapes) and impulses (time,
//! surface point, N·s vector, contact time). Output: mono f32 samples (m/s of
//! normal surface velocity for the default contact microphone) and WAV files.
//!
//! Each mode is a damped complex exponential advanced by one complex multiply
//! per sample ([`kernel`]: f32 structure-of-arrays SIMD with an f64 scalar
//! reference), re-anchored in f64 every block so the error never grows with
//! duration, excited phase-exactly at fractional sample times with the exact
//! half-sine contact spectrum ([`contact`]), and dropped once inaudible.
//! [`DrivenVoice`] ([`force`]) renders modes driven by a continuous,
//! piecewise-linear force (sustained contact), exactly discretized.
//! [`ModalVoice`] is the streaming engine the scene mixes; [`render_strikes`]
//! and [`write_wav`] serve the `modal strike` command. [`reference`] is the
//! f64 closed form every path is measured against, [`study`] the
//! error-versus-cost measurement of `modal bench synth`, and [`synthetic`]
//! builds seeded synthetic banks for both. The math, units and conventions
//! are in `docs/synthesis.md`.

mod complex;
pub mod contact;
pub mod degenerate;
mod error;
pub mod force;
pub mod force_kernel;
pub mod kernel;
mod model;
pub mod modulation;
mod offline;
mod options;
pub mod reference;
pub mod study;
pub mod surface;
pub mod synthetic;
mod voice;
mod wav;

pub use complex::C64;
pub use contact::{
    default_contact_time_s, effective_modulus, harmonic, hertz_contact_time, DEFAULT_CONTACT_TIME_S,
    MAX_CONTACT_TIME_S,
};
pub use degenerate::degenerate_phases;
pub use error::SynthError;
pub use force::{DrivenStats, DrivenVoice, ForceSegment};
pub use model::{SynthModel, MAX_SNAP_FRACTION, RINGING_MODES};
pub use modulation::OutputModulation;
pub use offline::{
    auto_duration, fade_out, render_strikes, RenderLength, Rendered, Strike, AUTO_DECAY_DB, FADE_S,
    MAX_DURATION_S, MIN_AUTO_DURATION_S,
};
pub use options::{
    check_sample_rate, classify_mode, Kernel, OutputGain, OutputQuantity, SkipReason, SynthOptions,
    MAX_FREQUENCY_FRACTION, MAX_SAMPLE_RATE, MIN_FREQUENCY_HZ, MIN_SAMPLE_RATE,
};
pub use reference::{ClosedForm, SignalError};
pub use surface::SurfacePoint;
pub use voice::{
    ExcitedMode, ImpactPoint, ModalVoice, VoiceStats, ABSOLUTE_FLOOR, BLOCK, MAX_OUTPUT, PARALLEL_MIN_MODES,
    REANCHOR_BLOCKS,
};
pub use wav::{write_wav, WavFormat, WavGain, WavReport, DEFAULT_WAV_GAIN, PCM16_SMALLEST_NONZERO};
