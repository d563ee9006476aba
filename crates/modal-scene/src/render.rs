//! The render pipeline: banks → physics + excitation → synthesis → listener mix.
//!
//! Stages (each timed in the [`RenderReport`]):
//! 1. **banks**: one provider call per distinct asset ([`crate::BankProvider`]);
//! 2. **physics + excitation**: fixed-rate rapier steps; after each step the
//!    contacts become strikes ([`crate::excite`]); trajectories are kept for
//!    the listener; once every body sleeps the remaining steps are skipped;
//! 3. **synthesis**: one [`modal_synth::ModalVoice`] per object that was
//!    struck (objects never hit cost nothing), in parallel over objects, each
//!    rendered from its first strike until it has decayed below
//!    [`SILENCE_DB`] of its own peak with no strike pending;
//! 4. **mix**: per object and ear, 1/r gain and r/c delay ([`crate::listener`]).
//!
//! **Level.** Mode `i` radiates like a pulsating sphere of radius
//! `a = √(A/4π)` (the sphere with the object's surface area `A`) whose
//! surface moves with the mode's RMS normal surface velocity `v_i`
//! (`modal_synth::SynthModel::rms_normal_shapes`):
//! `p_i(r) = ρ₀ c · (a / r) · (k_i a / √(1 + (k_i a)²)) · v_i`, `k_i = ω_i / c`,
//! `ρ₀ c` = [`AIR_IMPEDANCE_PA_S_M`]. The factor `k a/√(1 + (ka)²)` is the
//! sphere's radiation roll-off: small, slow modes radiate poorly. It is an
//! estimate of the level (good to a factor of a few), not a radiation solve. A sample value of 1.0 (full scale) is [`FULL_SCALE_PA`] times
//! `listener.gain`⁻¹. There is no normalization; samples beyond ±1 are
//! counted as clipped. The last [`FADE_OUT_S`] of the file fade out with a
//! raised cosine so a cut-off ring never ends in a click.
//!
//! **Determinism.** Physics is single-threaded; voices are independent and
//! mixed in object order, so the output is bit-identical for any thread count.

use std::sync::Arc;
use std::time::Instant;

use modal_bank::ModeBank;
use modal_synth::{ModalVoice, OutputGain, SynthModel, SynthOptions};
use rayon::prelude::*;
use serde::Serialize;

use crate::excite::{Exciter, ImpactEvent, StepInput, StepStrikes, Strike};
use crate::listener::{add_heard, Trajectory};
use crate::physics::{check_ground_clearance, PairContacts, World};
use crate::provider::resolve_banks;
use crate::spec::{Channels, Scene};
use crate::{BankProvider, SceneError};

/// Characteristic impedance of air ρ₀c [Pa·s/m] (20 °C).
pub const AIR_IMPEDANCE_PA_S_M: f64 = 413.0;
/// Sound pressure that maps to a sample value of 1.0 [Pa] (120 dB SPL).
pub const FULL_SCALE_PA: f64 = 20.0;
/// Length of the raised-cosine fade at the end of the output [s].
pub const FADE_OUT_S: f64 = 0.005;
/// A voice stops once a block is this far below the object's peak [dB].
pub const SILENCE_DB: f64 = -140.0;
/// Samples rendered per voice call.
const RENDER_CHUNK: usize = 4096;

/// Options of [`render`].
#[derive(Clone, Debug, Default)]
pub struct RenderOptions {
    /// Keep one [`ImpactEvent`] per impact (for `--events`).
    pub collect_events: bool,
}

/// Per-object statistics.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ObjectReport {
    /// Object name.
    pub name: String,
    /// Impacts (contact-pair excitations) the object took part in.
    pub impacts: usize,
    /// Strikes (contact points) applied to its modes.
    pub strikes: usize,
    /// Strikes dropped because the contact point lay off the bank's surface.
    pub strikes_dropped: usize,
    /// Modes in the bank.
    pub modes_total: usize,
    /// Modes that can sound (not overdamped, inside 20 Hz .. 0.45 fs).
    pub modes_synthesized: usize,
    /// Σ over samples of active modes (the synthesis work).
    pub mode_samples: u64,
    /// Samples of the object's signal computed (0 if never hit).
    pub samples_computed: u64,
    /// Peak of the object's radiated pressure at 1 m [Pa].
    pub peak_pa_at_1m: f64,
}

/// What a render did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RenderReport {
    /// Per object, in scene order.
    pub objects: Vec<ObjectReport>,
    /// Distinct banks asked from the provider.
    pub banks_requested: usize,
    /// Physics steps simulated (the rest were skipped: everything asleep).
    pub physics_steps: usize,
    /// Total impacts.
    pub impacts: usize,
    /// Seconds getting banks.
    pub banks_s: f64,
    /// Seconds in rapier.
    pub physics_s: f64,
    /// Seconds turning contacts into strikes.
    pub excitation_s: f64,
    /// Seconds in modal synthesis.
    pub synthesis_s: f64,
    /// Seconds in the listener mix.
    pub mix_s: f64,
    /// Output length [s].
    pub duration_s: f64,
    /// Output sample rate [Hz].
    pub sample_rate: u32,
    /// Largest |sample| (full scale = 1).
    pub peak: f64,
    /// Samples beyond full scale.
    pub clipped_samples: usize,
}

impl RenderReport {
    /// Audio seconds per wall-clock second of physics + excitation + synthesis + mix.
    pub fn real_time_factor(&self) -> f64 {
        let wall = self.physics_s + self.excitation_s + self.synthesis_s + self.mix_s;
        if wall > 0.0 {
            self.duration_s / wall
        } else {
            f64::INFINITY
        }
    }
}

/// The output of [`render`].
#[derive(Clone, Debug)]
pub struct Rendered {
    /// One (mono) or two (left, right) channels of equal length, full scale = 1.
    pub channels: Vec<Vec<f32>>,
    /// Sample rate [Hz].
    pub sample_rate: u32,
    /// Statistics and timings.
    pub report: RenderReport,
    /// Impacts, if [`RenderOptions::collect_events`].
    pub events: Vec<ImpactEvent>,
}

/// Simulates `scene` and renders what its listener hears.
pub fn render(
    scene: &Scene,
    provider: &mut dyn BankProvider,
    opts: &RenderOptions,
) -> Result<Rendered, SceneError> {
    let mut report = RenderReport {
        duration_s: scene.duration_s,
        sample_rate: scene.sample_rate_hz,
        ..Default::default()
    };
    let t = Instant::now();
    let (banks, requested) = resolve_banks(scene, provider)?;
    report.banks_requested = requested;
    report.banks_s = t.elapsed().as_secs_f64();
    check_ground_clearance(scene, &banks)?;

    let names: Vec<String> = (0..scene.objects.len()).map(|i| scene.object_name(i)).collect();
    let sim = simulate(scene, &banks, &names, opts, &mut report)?;

    let t = Instant::now();
    let fs = scene.sample_rate_hz as f64;
    let total = (scene.duration_s * fs).round() as usize;
    let signals = synthesize(scene, &banks, &names, &sim.strikes, total)?;
    report.synthesis_s = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let mut channels = mix(scene, &signals, &sim.trajectories, total);
    fade_out(&mut channels, (FADE_OUT_S * fs) as usize);
    report.mix_s = t.elapsed().as_secs_f64();

    for (i, s) in signals.iter().enumerate() {
        report.objects.push(ObjectReport {
            name: names[i].clone(),
            impacts: sim.impacts[i],
            strikes: sim.strikes[i].len(),
            ..s.report.clone()
        });
    }
    report.impacts = sim.events_total;
    report.peak = channels.iter().flatten().fold(0.0f64, |m, x| m.max((*x as f64).abs()));
    report.clipped_samples = channels.iter().flatten().filter(|x| x.abs() > 1.0).count();
    Ok(Rendered { channels, sample_rate: scene.sample_rate_hz, report, events: sim.events })
}

struct Simulation {
    strikes: Vec<Vec<Strike>>,
    impacts: Vec<usize>,
    trajectories: Vec<Trajectory>,
    events: Vec<ImpactEvent>,
    events_total: usize,
}

fn simulate(
    scene: &Scene,
    banks: &[Arc<ModeBank>],
    names: &[String],
    opts: &RenderOptions,
    report: &mut RenderReport,
) -> Result<Simulation, SceneError> {
    let n = banks.len();
    let mut world = World::new(scene, banks)?;
    let dt = 1.0 / scene.physics_rate_hz;
    let steps = (scene.duration_s * scene.physics_rate_hz).ceil() as usize;
    let mut sim = Simulation {
        strikes: vec![Vec::new(); n],
        impacts: vec![0; n],
        trajectories: vec![Trajectory { dt, positions: Vec::new() }; n],
        events: Vec::new(),
        events_total: 0,
    };
    let record = |world: &World, sim: &mut Simulation| {
        for (i, path) in sim.trajectories.iter_mut().enumerate() {
            path.positions.push(world.center_of_mass(i).map(|x| x as f32));
        }
    };
    record(&world, &mut sim);
    let mut exciter = Exciter::default();
    let mut pairs: Vec<PairContacts> = Vec::new();
    let mut impacts_before = 0;
    for k in 0..steps {
        if k > 0 && world.all_asleep() {
            break;
        }
        let t = Instant::now();
        world.step();
        world.contacts(&mut pairs);
        report.physics_s += t.elapsed().as_secs_f64();
        report.physics_steps += 1;
        let t = Instant::now();
        let to_body = |i: usize, v: [f64; 3]| world.to_body(i, v);
        let mut out = StepStrikes {
            strikes: &mut sim.strikes,
            impacts: &mut sim.impacts,
            events: if opts.collect_events { Some(&mut sim.events) } else { None },
            pair_impacts: &mut impacts_before,
        };
        let input =
            StepInput { t0: k as f64 * dt, dt, pairs: &pairs, sides: &world.sides, names, to_body: &to_body };
        exciter.step(&input, &mut out);
        record(&world, &mut sim);
        report.excitation_s += t.elapsed().as_secs_f64();
    }
    sim.events_total = impacts_before;
    Ok(sim)
}

/// One object's radiated signal at 1 m and its statistics.
struct Signal {
    /// Output sample index of `samples[0]`.
    start: usize,
    /// Pressure at 1 m divided by [`FULL_SCALE_PA`].
    samples: Vec<f32>,
    report: ObjectReport,
}

/// A checked synthesis model and its radiation gains, shared by instances.
type SharedModel = (Arc<SynthModel>, Arc<Vec<f64>>);

fn synthesize(
    scene: &Scene,
    banks: &[Arc<ModeBank>],
    names: &[String],
    strikes: &[Vec<Strike>],
    total: usize,
) -> Result<Vec<Signal>, SceneError> {
    // One checked model and one set of radiation gains per distinct bank.
    let mut models: Vec<(*const ModeBank, SharedModel)> = Vec::new();
    let mut per_object = Vec::with_capacity(banks.len());
    for (i, bank) in banks.iter().enumerate() {
        let key = Arc::as_ptr(bank);
        let found = models.iter().position(|m| m.0 == key);
        let idx = match found {
            Some(idx) => idx,
            None if strikes[i].is_empty() => {
                per_object.push(None);
                continue;
            }
            None => {
                let model = SynthModel::new(bank).map_err(|e| SceneError::Synthesis {
                    object: names[i].clone(),
                    message: e.to_string(),
                })?;
                let gains = radiation_gains(&model, bank);
                models.push((key, (Arc::new(model), Arc::new(gains))));
                models.len() - 1
            }
        };
        let (model, gains) = &models[idx].1;
        per_object.push(Some((Arc::clone(model), Arc::clone(gains))));
    }
    let fs = scene.sample_rate_hz as f64;
    (0..banks.len())
        .into_par_iter()
        .map(|i| {
            let report = ObjectReport { modes_total: banks[i].mode_count(), ..Default::default() };
            let Some((model, gains)) = &per_object[i] else {
                return Ok(Signal { start: 0, samples: Vec::new(), report });
            };
            let opts = SynthOptions {
                sample_rate: fs,
                gain: OutputGain::PerMode(gains.to_vec()),
                parallel: false,
                ..SynthOptions::default()
            };
            let voice = ModalVoice::from_model(Arc::clone(model), opts)
                .map_err(|e| SceneError::Synthesis { object: names[i].clone(), message: e.to_string() })?;
            let scale = AIR_IMPEDANCE_PA_S_M * equivalent_radius(&banks[i]) / FULL_SCALE_PA;
            Ok(render_voice(voice, &strikes[i], total, fs, scale, report))
        })
        .collect()
}

/// Per-mode output gains: RMS normal shape × the sphere's radiation roll-off.
fn radiation_gains(model: &SynthModel, bank: &ModeBank) -> Vec<f64> {
    let a = equivalent_radius(bank);
    let c = crate::listener::SPEED_OF_SOUND_M_S;
    model
        .rms_normal_shapes()
        .iter()
        .zip(&bank.frequencies_hz)
        .map(|(g, f)| {
            let ka = 2.0 * std::f64::consts::PI * f / c * a;
            g * ka / (1.0 + ka * ka).sqrt()
        })
        .collect()
}

/// Radius of the sphere with the same surface area [m].
fn equivalent_radius(bank: &ModeBank) -> f64 {
    let p = &bank.surface.positions;
    let area: f64 = bank
        .surface
        .triangles
        .iter()
        .map(|t| {
            let (a, b, c) = (p[t[0]], p[t[1]], p[t[2]]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let w = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
            0.5 * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt()
        })
        .sum();
    (area / (4.0 * std::f64::consts::PI)).sqrt()
}

fn render_voice(
    mut voice: ModalVoice,
    strikes: &[Strike],
    total: usize,
    fs: f64,
    scale: f64,
    mut report: ObjectReport,
) -> Signal {
    let mut last = 0.0f64;
    let mut first = f64::INFINITY;
    for s in strikes {
        match voice.add_impulse(s.time_s, s.point_m, s.impulse_ns, s.contact_time_s) {
            Ok(_) => {
                first = first.min(s.time_s);
                last = last.max(s.time_s + s.contact_time_s);
            }
            Err(_) => report.strikes_dropped += 1,
        }
    }
    if !first.is_finite() {
        return Signal { start: 0, samples: Vec::new(), report };
    }
    let start = ((first * fs).floor() as usize).min(total);
    let last_sample = (last * fs).ceil() as usize + 1;
    let mut samples: Vec<f32> = Vec::new();
    let mut peak = 0.0f32;
    let floor = 10f32.powf((SILENCE_DB / 20.0) as f32);
    let mut pos = start;
    while pos < total {
        let len = RENDER_CHUNK.min(total - pos);
        let at = samples.len();
        samples.resize(at + len, 0.0);
        voice.render(&mut samples[at..], pos as u64);
        let block_peak = samples[at..].iter().fold(0.0f32, |m, x| m.max(x.abs()));
        peak = peak.max(block_peak);
        pos += len;
        if pos > last_sample && (voice.is_silent() || block_peak <= floor * peak) {
            break;
        }
    }
    for x in &mut samples {
        *x = (*x as f64 * scale) as f32;
    }
    let stats = voice.stats();
    report.modes_synthesized = stats.modes_total - stats.modes_skipped;
    report.mode_samples = stats.mode_samples;
    report.samples_computed = samples.len() as u64;
    report.peak_pa_at_1m = peak as f64 * scale * FULL_SCALE_PA;
    Signal { start, samples, report }
}

/// Ear positions of the listener.
fn ears(scene: &Scene) -> Vec<[f64; 3]> {
    let l = &scene.listener;
    match l.channels {
        Channels::Mono => vec![l.position_m],
        Channels::Stereo => {
            let r = l.right;
            let n = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
            let h = 0.5 * l.ear_spacing_m / n;
            let p = l.position_m;
            vec![
                [p[0] - h * r[0], p[1] - h * r[1], p[2] - h * r[2]],
                [p[0] + h * r[0], p[1] + h * r[1], p[2] + h * r[2]],
            ]
        }
    }
}

fn mix(scene: &Scene, signals: &[Signal], paths: &[Trajectory], total: usize) -> Vec<Vec<f32>> {
    let fs = scene.sample_rate_hz as f64;
    ears(scene)
        .into_iter()
        .map(|ear| {
            let mut out = vec![0.0f32; total];
            for (s, path) in signals.iter().zip(paths) {
                add_heard(&s.samples, s.start, path, ear, fs, scene.listener.gain, &mut out);
            }
            out
        })
        .collect()
}

fn fade_out(channels: &mut [Vec<f32>], len: usize) {
    for c in channels {
        let n = c.len();
        let len = len.min(n);
        for j in 0..len {
            let x = (j as f64 + 0.5) / len as f64;
            let g = 0.5 * (1.0 + (std::f64::consts::PI * x).cos());
            c[n - len + j] *= g as f32;
        }
    }
}
