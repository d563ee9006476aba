//! Typed errors of the synthesizer; each message is one line naming the bad value.

use modal_mesh::readable;

/// Everything that can go wrong when striking a bank or writing audio.
#[derive(Debug, thiserror::Error)]
pub enum SynthError {
    /// Sample rate not finite or outside 8 kHz ..= 192 kHz.
    #[error("sample rate {} Hz is outside 8000..=192000 Hz", readable(*.0))]
    SampleRate(f64),
    /// An event time that is NaN, infinite or negative.
    #[error("invalid time {} s for {} (must be finite and >= 0)", readable(*.0), .1)]
    InvalidTime(f64, &'static str),
    /// An impulse vector with a NaN or infinite component.
    #[error("impulse [{}, {}, {}] N·s is not finite", readable(.0[0]), readable(.0[1]), readable(.0[2]))]
    InvalidImpulse([f64; 3]),
    /// An impulse whose response could exceed the f32 output range.
    #[error(
        "impulse [{}, {}, {}] N·s would drive the output up to {bound:e} (limit {limit:e} output units, f32 range)",
        readable(impulse[0]), readable(impulse[1]), readable(impulse[2])
    )]
    OutputOverflow {
        /// The offending impulse [N·s].
        impulse: [f64; 3],
        /// Bound on |output| with this impulse added (sum of mode amplitudes of all impulses so far).
        bound: f64,
        /// Largest accepted bound.
        limit: f64,
    },
    /// A force knot with a NaN, infinite or absurdly large component.
    #[error("force [{}, {}, {}] N is not finite or exceeds 1e9 N", readable(.0[0]), readable(.0[1]), readable(.0[2]))]
    InvalidForce([f64; 3]),
    /// A contact time that is NaN, negative or longer than the allowed maximum.
    #[error("contact time {} s must be finite and within 0..={max} s", readable(*.0), max = crate::contact::MAX_CONTACT_TIME_S)]
    InvalidContactTime(f64),
    /// A query point with a NaN or infinite coordinate.
    #[error("point [{}, {}, {}] m is not finite", readable(.0[0]), readable(.0[1]), readable(.0[2]))]
    InvalidPoint([f64; 3]),
    /// A query point farther from the surface than 10 % of the bounding-box diagonal.
    #[error(
        "point [{:?}, {:?}, {:?}] m is {distance:.4} m from the surface (limit {limit:.4} m = 10 % of the bounding-box diagonal)",
        point[0], point[1], point[2]
    )]
    PointFarFromSurface {
        /// The query point \[m\].
        point: [f64; 3],
        /// Distance to the nearest surface point \[m\].
        distance: f64,
        /// Largest accepted distance \[m\].
        limit: f64,
    },
    /// The bank has modes but no surface triangles to strike.
    #[error("the mode bank has no surface triangles to strike")]
    EmptySurface,
    /// The bank's arrays disagree in length.
    #[error("inconsistent mode bank: {0}")]
    InconsistentBank(String),
    /// Per-mode gains whose count differs from the bank's mode count.
    #[error("per-mode gain list has {got} entries, the bank has {expected} modes")]
    GainCount {
        /// Entries given.
        got: usize,
        /// Modes in the bank.
        expected: usize,
    },
    /// A non-finite option value (cull threshold, gain, duration...).
    #[error("invalid option {name} = {}", readable(*value))]
    InvalidOption {
        /// Option name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// WAV channel layout problems (no channel, channels of different lengths, > 2 channels).
    #[error("invalid WAV channels: {0}")]
    WavChannels(String),
    /// I/O or encoding failure while writing a WAV file.
    #[error("cannot write WAV file {path}: {message}")]
    WavWrite {
        /// Destination path.
        path: String,
        /// Cause.
        message: String,
    },
}
