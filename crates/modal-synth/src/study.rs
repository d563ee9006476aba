//! Synthesis error versus cost (issue 7): the same strikes rendered by each
//! kernel / culling / budget setting, compared with the f64 closed form
//! ([`crate::reference`]) and timed.
//!
//! Cost is the wall time of the whole render on one thread (voice set-up,
//! impulses, kernel), reported as mode-samples per second (active modes ×
//! samples, the work the kernel did) and as the real-time factor (audio
//! seconds per wall second). Error is the relative RMS error over the render
//! and the largest error relative to the reference peak
//! ([`SignalError`]). The realistic scenario: a bank of `n` modes
//! log-spaced over 50 Hz – 20 kHz with Rayleigh damping of a material
//! preset, seeded random shapes and random per-mode output gains, struck
//! four times — two strikes whose contacts overlap at the start, one at a
//! fractional sample time while the first ones still ring, one late.

use crate::error::SynthError;
use crate::offline::Strike;
use crate::options::{Kernel, OutputGain, SynthOptions};
use crate::reference::{ClosedForm, SignalError};
use crate::synthetic::{random_gains, SyntheticBank};
use crate::voice::{ModalVoice, BLOCK};
use modal_bank::ModeBank;
use std::time::Instant;

/// A bank, strikes, base options and a duration: what every variant renders.
#[derive(Clone, Debug)]
pub struct Scenario {
    /// The bank.
    pub bank: ModeBank,
    /// The strikes.
    pub strikes: Vec<Strike>,
    /// Base options (sample rate, gains); variants override kernel, culling, budget.
    pub options: SynthOptions,
    /// Rendered duration \[s\].
    pub seconds: f64,
}

impl Scenario {
    /// The realistic scenario of the module doc for material preset
    /// `material` (e.g. `"steel"`, `"glass"`), `modes` modes, `seconds` of
    /// audio at 48 kHz, shapes and gains from `seed`.
    ///
    /// # Panics
    /// When `material` is not a preset name (a caller bug).
    pub fn realistic(material: &str, modes: usize, seconds: f64, seed: u64) -> Scenario {
        let bank = SyntheticBank { seed, ..SyntheticBank::preset(material, modes) }.build();
        let t = seconds.max(0.0);
        let strikes = vec![
            Strike {
                time_s: 0.0,
                at: [0.05, 0.1, 0.03],
                impulse_ns: [0.0, 0.01, -0.002],
                contact_time_s: 1e-4,
            },
            Strike {
                time_s: 5e-5,
                at: [0.15, 0.0, 0.02],
                impulse_ns: [0.003, -0.006, 0.0],
                contact_time_s: 2e-4,
            },
            Strike {
                time_s: 0.3 * t + 1.234_567e-5,
                at: [0.2, 0.05, 0.01],
                impulse_ns: [-0.004, 0.0, 0.002],
                contact_time_s: 5e-5,
            },
            Strike {
                time_s: 0.7 * t,
                at: [0.1, 0.05, 0.05],
                impulse_ns: [0.0, 0.0, -0.003],
                contact_time_s: 0.0,
            },
        ];
        let options = SynthOptions {
            gain: OutputGain::PerMode(random_gains(modes, seed)),
            parallel: false,
            ..SynthOptions::default()
        };
        Scenario { bank, strikes, options, seconds }
    }

    /// Number of output samples.
    pub fn samples(&self) -> usize {
        (self.seconds * self.options.sample_rate).round() as usize
    }

    /// The f64 closed-form output of the scenario.
    pub fn reference(&self) -> Result<Vec<f64>, SynthError> {
        let cf = ClosedForm::new(&self.bank, &self.strikes, &self.options)?;
        let mut y = vec![0.0; self.samples()];
        cf.render(0, &mut y);
        Ok(y)
    }
}

/// One synthesis setting to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct Variant {
    /// Short name for tables and plots.
    pub label: String,
    /// Kernel.
    pub kernel: Kernel,
    /// Culling threshold \[dB\] re the loudest active mode (`None`: off).
    pub cull_db: Option<f64>,
    /// Mode budget (`None`: unlimited).
    pub budget: Option<usize>,
}

impl Variant {
    /// A variant; the label is derived from the settings.
    pub fn new(kernel: Kernel, cull_db: Option<f64>, budget: Option<usize>) -> Variant {
        let k = match kernel {
            Kernel::Reference => "f64 scalar",
            Kernel::Portable => "f32 portable",
            Kernel::Auto => "f32 SIMD",
        };
        let c = cull_db.map_or("cull off".to_string(), |db| format!("cull {db} dB"));
        let b = budget.map_or(String::new(), |n| format!(", budget {n}"));
        Variant { label: format!("{k}, {c}{b}"), kernel, cull_db, budget }
    }
}

/// The standard sweep for a bank of `modes` modes: the f64 scalar path
/// (culling off and −100 dB), the f32 SIMD and portable kernels with
/// culling off, the f32 SIMD kernel at −60/−80/−100 dB, and budgets of
/// 1/2, 1/4 and 1/10 of the modes at −100 dB.
pub fn standard_variants(modes: usize) -> Vec<Variant> {
    let mut v = vec![
        Variant::new(Kernel::Reference, None, None),
        Variant::new(Kernel::Reference, Some(-100.0), None),
        Variant::new(Kernel::Auto, None, None),
        Variant::new(Kernel::Portable, None, None),
    ];
    for db in [-60.0, -80.0, -100.0] {
        v.push(Variant::new(Kernel::Auto, Some(db), None));
    }
    for div in [2, 4, 10] {
        let b = (modes / div).max(1);
        if b < modes {
            v.push(Variant::new(Kernel::Auto, Some(-100.0), Some(b)));
        }
    }
    v
}

/// Error and cost of one variant.
#[derive(Clone, Debug, PartialEq)]
pub struct Measurement {
    /// The variant.
    pub variant: Variant,
    /// Error against the closed form.
    pub error: SignalError,
    /// Fastest wall time of the repeats \[s\].
    pub wall_s: f64,
    /// Active modes × samples computed by the kernel.
    pub mode_samples: u64,
    /// Times a mode left the active set.
    pub modes_culled: u64,
    /// Rendered audio \[s\].
    pub audio_s: f64,
}

impl Measurement {
    /// Kernel work per wall second.
    pub fn mode_samples_per_s(&self) -> f64 {
        self.mode_samples as f64 / self.wall_s
    }

    /// Audio seconds rendered per wall second.
    pub fn realtime_factor(&self) -> f64 {
        self.audio_s / self.wall_s
    }
}

/// Renders `scenario` with `variant` (`repeats` ≥ 1 times, the fastest
/// counts) and compares the output with `reference` (from
/// [`Scenario::reference`]).
///
/// # Panics
/// When `reference` does not hold [`Scenario::samples`] values (a caller bug).
pub fn measure(
    scenario: &Scenario,
    reference: &[f64],
    variant: &Variant,
    repeats: usize,
) -> Result<Measurement, SynthError> {
    let opts = SynthOptions {
        kernel: variant.kernel,
        cull_db: variant.cull_db,
        budget: variant.budget,
        ..scenario.options.clone()
    };
    let n = scenario.samples();
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        let mut voice = ModalVoice::new(&scenario.bank, opts.clone())?;
        for s in &scenario.strikes {
            voice.add_impulse(s.time_s, s.at, s.impulse_ns, s.contact_time_s)?;
        }
        let mut y = vec![0.0f32; n];
        for (k, block) in y.chunks_mut(16 * BLOCK).enumerate() {
            voice.render(block, (k * 16 * BLOCK) as u64);
        }
        best = best.min(start.elapsed().as_secs_f64());
        last = Some((y, voice.stats()));
    }
    let (y, stats) = last.expect("at least one repeat");
    let error = SignalError::between(&y, reference);
    Ok(Measurement {
        variant: variant.clone(),
        error,
        wall_s: best.max(1e-9),
        mode_samples: stats.mode_samples,
        modes_culled: stats.modes_culled,
        audio_s: n as f64 / opts.sample_rate,
    })
}
