//! The render pipeline: banks → physics + excitation → synthesis → listener mix.
//!
//! Stages (each timed in the [`RenderReport`]):
//! 1. **banks**: one provider call per distinct asset ([`crate::BankProvider`]);
//! 2. **physics + excitation**: fixed-rate rapier steps; after each step the
//!    contacts become strikes ([`crate::excite`]); trajectories are kept for
//!    the listener; once every body sleeps the remaining steps are skipped;
//! 3. **synthesis**: the checked model and radiation gains of each distinct
//!    bank are built on the second core while the physics runs; then one
//!    [`modal_synth::ModalVoice`] per object that was
//!    struck (objects never hit cost nothing), in parallel over objects, each
//!    rendered from its first strike until, with no strike pending, a block
//!    of it as heard from the object's nearest point to an ear is
//!    [`SILENCE_DB`] below the output's estimated peak (the largest object
//!    peak heard from its farthest point); that last block fades out so the
//!    cut is click-free. The estimate needs every voice's peak, so voices are
//!    rendered in two parallel phases: up to their last strike, then the tail;
//! 4. **mix**: per object and ear, 1/r gain and r/c delay ([`crate::listener`]),
//!    the ears in parallel.
//!
//! Between 2 and 3, **radiation**: with `[listener] radiation = "transfer"`
//! the provider is asked once per distinct asset for its acoustic transfer
//! table ([`crate::BankProvider::radiation`]); an object whose bank has one
//! is synthesized once per listening point (ear, ground image), each voice
//! weighted by the transfer in the body's rotating frame (module
//! `transfer`, which states exactly what it replaces). The rest use:
//!
//! **Level estimate.** Mode `i` radiates like a pulsating sphere of radius
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
use modal_synth::{DrivenVoice, ForceSegment, ModalVoice, OutputGain, SynthModel, SynthOptions};
use rayon::prelude::*;

use crate::excite::{Exciter, ImpactEvent, StepInput, StepStrikes, Strike};
use crate::ground::with_slab;
use crate::listener::{listening_points, mix, Trajectory};
use crate::physics::{check_ground_clearance, ContactSide, PairContacts, World};
use crate::provider::resolve_banks;
pub use crate::report::{ObjectReport, RenderReport};
use crate::spec::{Radiation, Scene};
use crate::sustain::{ContactEvent, SustainInput, SustainedEvent, Sustainer};
use crate::transfer::{object_transfers, BankTransfer, EarTransfer};
use crate::{BankProvider, SceneError};

/// Characteristic impedance of air ρ₀c [Pa·s/m] (20 °C).
pub const AIR_IMPEDANCE_PA_S_M: f64 = 413.0;
/// Sound pressure that maps to a sample value of 1.0 [Pa] (120 dB SPL).
pub const FULL_SCALE_PA: f64 = 20.0;
/// Length of the raised-cosine fade at the end of the output [s].
pub const FADE_OUT_S: f64 = 0.005;
/// A voice stops once a block of it, heard from its nearest point, is this
/// far below the output's estimated peak [dB] (16-bit PCM resolves −96 dB).
pub const SILENCE_DB: f64 = -100.0;
/// Samples rendered per voice call.
const RENDER_CHUNK: usize = 4096;

/// Options of [`render`].
#[derive(Clone, Debug, Default)]
pub struct RenderOptions {
    /// Keep one [`ImpactEvent`] per impact and one [`SustainedEvent`] per
    /// sustained-contact segment (for `--events`).
    pub collect_events: bool,
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
    /// Sustained-contact segments (in order of their end), if
    /// [`RenderOptions::collect_events`].
    pub sustained: Vec<SustainedEvent>,
}

impl Rendered {
    /// Impacts and sustained-contact segments in order of their start time
    /// (what `--events` writes).
    pub fn contact_events(&self) -> Vec<ContactEvent> {
        let mut events: Vec<ContactEvent> = self.events.iter().cloned().map(ContactEvent::Impact).collect();
        events.extend(self.sustained.iter().cloned().map(ContactEvent::Sustained));
        events.sort_by(|a, b| a.time_s().total_cmp(&b.time_s()));
        events
    }
}

/// Simulates `scene` and renders what its listener hears.
pub fn render(
    scene: &Scene,
    provider: &mut dyn BankProvider,
    opts: &RenderOptions,
) -> Result<Rendered, SceneError> {
    let original = scene;
    let scene = &*with_slab(original);
    let mut report = RenderReport {
        duration_s: scene.duration_s,
        sample_rate: scene.sample_rate_hz,
        ..Default::default()
    };
    let t = Instant::now();
    let resolved = resolve_banks(scene, provider)?;
    report.banks_requested = resolved.requested();
    let (requests, asset_of) = resolved.requests();
    report.banks_s = t.elapsed().as_secs_f64();
    let light = resolved.light();
    check_ground_clearance(original, &light[..original.objects.len()])?;

    let names: Vec<String> = (0..scene.objects.len()).map(|i| scene.object_name(i)).collect();
    // The physics needs only each bank's surface, mass and material. Banks
    // whose shapes are still pending are completed (read, checksummed,
    // validated), and the synthesis models built, on the second core while
    // the (single-threaded) physics runs.
    let (sim, completed) = rayon::join(
        || simulate(scene, &light, &names, opts, &mut report),
        || {
            let banks = resolved.complete()?;
            let models = distinct_models(&banks);
            Ok::<_, SceneError>((banks, models))
        },
    );
    let (banks, models) = completed?;
    let mut sim = sim?;
    let paths: Vec<Arc<Trajectory>> =
        std::mem::take(&mut sim.trajectories).into_iter().map(Arc::new).collect();

    let per_object = shared_models(&banks, &names, &sim, models)?;
    let t = Instant::now();
    let transfers = if scene.listener.radiation == Radiation::Transfer {
        object_transfers(provider, &requests, &asset_of, &banks, &per_object)?
    } else {
        vec![None; banks.len()]
    };
    report.radiation_s = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let fs = scene.sample_rate_hz as f64;
    let total = (scene.duration_s * fs).round() as usize;
    let signals = synthesize(scene, &banks, &per_object, &transfers, &sim, &paths, total)?;
    report.synthesis_s = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let heard: Vec<(usize, &[Vec<f32>])> = signals.iter().map(|s| (s.start, &s.samples[..])).collect();
    let mut channels = mix(scene, &heard, &paths, total);
    fade_out(&mut channels, (FADE_OUT_S * fs) as usize);
    report.mix_s = t.elapsed().as_secs_f64();

    for (i, s) in signals.iter().enumerate() {
        report.objects.push(ObjectReport {
            name: names[i].clone(),
            impacts: sim.impacts[i],
            strikes: sim.strikes[i].len(),
            force_segments: sim.segments[i].len(),
            final_position_m: paths[i].positions.last().map_or([0.0; 3], |p| p.map(f64::from)),
            ground_depth_m: sim.ground_depth_m[i],
            ..s.report.clone()
        });
    }
    report.impacts = sim.events_total;
    report.peak = channels.iter().flatten().fold(0.0f64, |m, x| m.max((*x as f64).abs()));
    report.clipped_samples = channels.iter().flatten().filter(|x| x.abs() > 1.0).count();
    Ok(Rendered {
        channels,
        sample_rate: scene.sample_rate_hz,
        report,
        events: sim.events,
        sustained: sim.sustained,
    })
}

/// Raises each object's deepest contact with the ground (its side has no
/// object) to this step's.
fn record_ground_depth(pairs: &[PairContacts], sides: &[ContactSide], deepest_m: &mut [f64]) {
    for pair in pairs {
        let objects = pair.sides.map(|s| sides[s].object);
        let object = match objects {
            [Some(i), None] | [None, Some(i)] => i,
            _ => continue,
        };
        let depth = pair.points.iter().map(|p| -p.separation_m).fold(0.0, f64::max);
        deepest_m[object] = deepest_m[object].max(depth);
    }
}

struct Simulation {
    strikes: Vec<Vec<Strike>>,
    /// Per object: sustained-contact force segments.
    segments: Vec<Vec<ForceSegment>>,
    sustained: Vec<SustainedEvent>,
    impacts: Vec<usize>,
    trajectories: Vec<Trajectory>,
    events: Vec<ImpactEvent>,
    events_total: usize,
    /// Per object: deepest into the ground plane [m] (`ObjectReport::ground_depth_m`).
    ground_depth_m: Vec<f64>,
}

fn simulate(
    scene: &Scene,
    banks: &[Arc<ModeBank>],
    names: &[String],
    opts: &RenderOptions,
    report: &mut RenderReport,
) -> Result<Simulation, SceneError> {
    let n = banks.len();
    let t = Instant::now();
    let mut world = World::new(scene, banks)?;
    report.listener_inside = world.object_containing(scene.listener.position_m).map(|i| names[i].clone());
    report.colliders_s = t.elapsed().as_secs_f64();
    let dt = 1.0 / scene.physics_rate_hz;
    let steps = (scene.duration_s * scene.physics_rate_hz).ceil() as usize;
    let mut sim = Simulation {
        strikes: vec![Vec::new(); n],
        segments: vec![Vec::new(); n],
        sustained: Vec::new(),
        impacts: vec![0; n],
        trajectories: vec![Trajectory { dt, positions: Vec::new(), rotations: Vec::new() }; n],
        events: Vec::new(),
        events_total: 0,
        ground_depth_m: vec![0.0; n],
    };
    let record = |world: &World, sim: &mut Simulation| {
        for (i, path) in sim.trajectories.iter_mut().enumerate() {
            path.positions.push(world.center_of_mass(i).map(|x| x as f32));
            // Rows: the world axes seen in the body frame, transposed = body-from-world.
            let cols = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|e| world.to_body(i, e));
            path.rotations.push([0, 1, 2].map(|r| [0, 1, 2].map(|c| cols[c][r] as f32)));
        }
    };
    record(&world, &mut sim);
    let mut exciter = Exciter::with_placed(&world.placed_pairs);
    let gravity = scene.gravity_m_s2.iter().map(|g| g * g).sum::<f64>().sqrt();
    let mut sustainer = scene.sustained.then(|| Sustainer::new(scene.sample_rate_hz as f64, dt, gravity));
    let mut pairs: Vec<PairContacts> = Vec::new();
    let mut impacts_before = 0;
    let mut simulated = 0;
    for k in 0..steps {
        if k > 0 && world.all_asleep() {
            break;
        }
        let t = Instant::now();
        world.step();
        world.contacts(&mut pairs);
        world.resist_rolling(&pairs);
        record_ground_depth(&pairs, &world.sides, &mut sim.ground_depth_m);
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
        let t = Instant::now();
        if let Some(sustainer) = sustainer.as_mut() {
            let kinematics = |side: usize| world.kinematics(side);
            let input = SustainInput {
                t0: k as f64 * dt,
                pairs: &pairs,
                sides: &world.sides,
                names,
                kinematics: &kinematics,
                to_body: &to_body,
            };
            let events = if opts.collect_events { Some(&mut sim.sustained) } else { None };
            sustainer.step(&input, &mut sim.segments, events);
        }
        report.sustained_s += t.elapsed().as_secs_f64();
        simulated = k + 1;
    }
    if let Some(sustainer) = sustainer.as_mut() {
        let t = Instant::now();
        let kinematics = |side: usize| world.kinematics(side);
        let to_body = |i: usize, v: [f64; 3]| world.to_body(i, v);
        let input = SustainInput {
            t0: simulated as f64 * dt,
            pairs: &[],
            sides: &world.sides,
            names,
            kinematics: &kinematics,
            to_body: &to_body,
        };
        let events = if opts.collect_events { Some(&mut sim.sustained) } else { None };
        sustainer.finish(&input, &mut sim.segments, events);
        report.sustained_s += t.elapsed().as_secs_f64();
    }
    sim.events_total = impacts_before;
    Ok(sim)
}

/// One object's radiated signal at 1 m and its statistics.
struct Signal {
    /// Output sample index of `samples[k][0]`.
    start: usize,
    /// Pressure at 1 m divided by [`FULL_SCALE_PA`]: one signal heard at
    /// every listening point (level estimate), or one per listening point
    /// ([`listening_points`], with the transfer).
    samples: Vec<Vec<f32>>,
    report: ObjectReport,
}

/// A checked synthesis model and its radiation gains, shared by instances.
pub(crate) type SharedModel = (Arc<SynthModel>, Arc<Vec<f64>>);

fn synthesize(
    scene: &Scene,
    banks: &[Arc<ModeBank>],
    per_object: &[Option<SharedModel>],
    transfers: &[Option<Arc<BankTransfer>>],
    sim: &Simulation,
    paths: &[Arc<Trajectory>],
    total: usize,
) -> Result<Vec<Signal>, SceneError> {
    let names = |i: usize| scene.object_name(i);
    let fs = scene.sample_rate_hz as f64;
    let ears = listening_points(scene);
    // Phase 1: every struck voice up to its last strike (its peak is known then).
    let mut runs: Vec<Option<VoiceRun>> = (0..banks.len())
        .into_par_iter()
        .map(|i| -> Result<Option<VoiceRun>, SceneError> {
            let Some((model, gains)) = &per_object[i] else { return Ok(None) };
            let transfer = transfers[i].as_ref();
            let opts = SynthOptions {
                sample_rate: fs,
                gain: OutputGain::PerMode(transfer.map_or_else(|| gains.to_vec(), |t| t.gains.clone())),
                parallel: false,
                ..SynthOptions::default()
            };
            // An impact heard through a direction-free level hears modes of one
            // frequency at their energy sum, the mean over directions, not at a level
            // set by how the eigensolver turned them (a bowl's pair cancelled at some
            // strike angles). The sustained-contact voice keeps the coherent sum: a
            // contact running round a rim then swells and fades as a listener at one
            // place would hear it (Euler's disk, tests/sustained_cli.rs), which a
            // mean over directions cannot.
            let direction_free = modal_synth::degenerate_phases(&banks[i].frequencies_hz);
            let failed = |e: modal_synth::SynthError| SceneError::Synthesis {
                object: names(i),
                message: e.to_string(),
            };
            let driven = if sim.segments[i].is_empty() {
                None
            } else {
                Some(DrivenVoice::from_model(Arc::clone(model), opts.clone()).map_err(failed)?)
            };
            let voices = match transfer {
                // One voice per listening point, each with its own direction; the
                // transfer's phase comes with it, so only estimated modes keep theirs.
                Some(t) => ears
                    .iter()
                    .map(|&ear| {
                        let opts =
                            SynthOptions { phases: Some(t.voice_phases(&direction_free)), ..opts.clone() };
                        let mut v = ModalVoice::from_model(Arc::clone(model), opts)?;
                        v.set_modulation(Arc::new(EarTransfer::new(
                            Arc::clone(t),
                            Arc::clone(&paths[i]),
                            ear,
                        )));
                        Ok(v)
                    })
                    .collect::<Result<Vec<_>, _>>()
                    .map_err(failed)?,
                None => {
                    let opts = SynthOptions { phases: Some(direction_free), ..opts };
                    vec![ModalVoice::from_model(Arc::clone(model), opts).map_err(failed)?]
                }
            };
            // The transfer's gains are in Pa·m already; the estimate's are RMS velocities.
            let scale = match transfer {
                Some(_) => 1.0 / FULL_SCALE_PA,
                None => AIR_IMPEDANCE_PA_S_M * equivalent_radius(&banks[i]) / FULL_SCALE_PA,
            };
            let (near_m, far_m) = distance_range(&paths[i], &ears);
            let place = Placement { total, fs, scale, near_m, far_m };
            let excitation = Excitation { strikes: &sim.strikes[i], segments: &sim.segments[i] };
            Ok(VoiceRun::start(voices, driven, excitation, &place).map(|mut run| {
                run.render_strikes(total);
                run
            }))
        })
        .collect::<Result<_, _>>()?;
    // Phase 2: each voice until it is SILENCE_DB below the output's peak.
    let gain = scene.listener.gain;
    let reference =
        runs.iter().flatten().map(|r| r.peak as f64 * r.scale * gain / r.far_m).fold(0.0, f64::max);
    let stop_level = reference * 10f64.powf(SILENCE_DB / 20.0);
    runs.par_iter_mut()
        .flatten()
        .for_each(|run| run.render_tail(total, stop_level / (run.scale * gain / run.near_m)));
    Ok(runs
        .into_iter()
        .enumerate()
        .map(|(i, run)| {
            let report = ObjectReport {
                modes_total: banks[i].mode_count(),
                modes_with_transfer: transfers[i].as_ref().map_or(0, |t| t.with_transfer),
                mode_levels: transfers[i].as_ref().map_or_else(Vec::new, |t| t.levels.clone()),
                ..Default::default()
            };
            match run {
                Some(run) => run.finish(report),
                None => Signal { start: 0, samples: vec![Vec::new()], report },
            }
        })
        .collect())
}

/// A model (or why the bank cannot be synthesized) per distinct bank, keyed
/// by the first object using it.
type DistinctModels = Vec<(usize, Result<SharedModel, String>)>;

/// The checked synthesis model and radiation gains of every distinct bank
/// (distinct `Arc`s), in object order.
fn distinct_models(banks: &[Arc<ModeBank>]) -> DistinctModels {
    let mut models = DistinctModels::new();
    for (i, bank) in banks.iter().enumerate() {
        if banks[..i].iter().any(|b| Arc::ptr_eq(b, bank)) {
            continue;
        }
        let model = SynthModel::shared(Arc::clone(bank)).map_err(|e| e.to_string()).map(|model| {
            let gains = radiation_gains(&model, bank);
            (Arc::new(model), Arc::new(gains))
        });
        models.push((i, model));
    }
    models
}

/// Each object's model from `models`, `None` for objects never struck; a
/// bank that cannot be synthesized is an error of its first struck object.
fn shared_models(
    banks: &[Arc<ModeBank>],
    names: &[String],
    sim: &Simulation,
    models: DistinctModels,
) -> Result<Vec<Option<SharedModel>>, SceneError> {
    let mut per_object = Vec::with_capacity(banks.len());
    for (i, bank) in banks.iter().enumerate() {
        if sim.strikes[i].is_empty() && sim.segments[i].is_empty() {
            per_object.push(None);
            continue;
        }
        let (_, model) = models
            .iter()
            .find(|(first, _)| Arc::ptr_eq(&banks[*first], bank))
            .expect("distinct_models covers every bank");
        match model {
            Ok((model, gains)) => per_object.push(Some((Arc::clone(model), Arc::clone(gains)))),
            Err(message) => {
                return Err(SceneError::Synthesis { object: names[i].clone(), message: message.clone() })
            }
        }
    }
    Ok(per_object)
}

/// Nearest and farthest distance [m] between an object's path and the ears
/// (clamped below at [`crate::MIN_DISTANCE_M`]).
fn distance_range(path: &Trajectory, ears: &[[f64; 3]]) -> (f64, f64) {
    let mut range = (f64::INFINITY, 0.0f64);
    for p in &path.positions {
        for e in ears {
            let r = (0..3).map(|c| (p[c] as f64 - e[c]).powi(2)).sum::<f64>().sqrt();
            range = (range.0.min(r), range.1.max(r));
        }
    }
    if path.positions.is_empty() || ears.is_empty() {
        range = (1.0, 1.0);
    }
    (range.0.max(crate::MIN_DISTANCE_M), range.1.max(crate::MIN_DISTANCE_M))
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
pub(crate) fn equivalent_radius(bank: &ModeBank) -> f64 {
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

/// Where and how loud a voice is heard, and the output length.
struct Placement {
    /// Output length [samples].
    total: usize,
    /// Sample rate [Hz].
    fs: f64,
    /// Synthesizer units → pressure at 1 m / [`FULL_SCALE_PA`].
    scale: f64,
    /// Nearest / farthest distance to an ear [m].
    near_m: f64,
    far_m: f64,
}

/// What drives one object: impacts and sustained-contact forces.
struct Excitation<'a> {
    strikes: &'a [Strike],
    segments: &'a [ForceSegment],
}

/// A voice (impulses, and sustained forces if any) being rendered in
/// chunks of [`RENDER_CHUNK`] samples: one impulse voice heard at every
/// listening point, or one per listening point (transfer); the sustained
/// forces' voice is shared by all (direction-averaged level).
struct VoiceRun {
    voices: Vec<ModalVoice>,
    driven: Option<DrivenVoice>,
    /// Output sample index of `samples[0]`.
    start: usize,
    /// Next output sample to render.
    pos: usize,
    /// The sample after which no strike or force is pending.
    last_sample: usize,
    /// Output of each voice so far (synthesizer units).
    samples: Vec<Vec<f32>>,
    /// The sustained-force voice's chunk, when several voices share it.
    scratch: Vec<f32>,
    /// Largest |sample| so far (synthesizer units).
    peak: f32,
    /// Synthesizer units → pressure at 1 m / [`FULL_SCALE_PA`].
    scale: f64,
    /// Nearest / farthest distance to an ear [m].
    near_m: f64,
    far_m: f64,
    strikes_dropped: usize,
    segments_dropped: usize,
}

impl VoiceRun {
    /// Applies the strikes and forces; `None` when none of them landed.
    fn start(
        mut voices: Vec<ModalVoice>,
        mut driven: Option<DrivenVoice>,
        excitation: Excitation<'_>,
        place: &Placement,
    ) -> Option<VoiceRun> {
        let (mut first, mut last, mut dropped) = (f64::INFINITY, 0.0f64, 0);
        for s in excitation.strikes {
            let mut landed = None;
            for voice in &mut voices {
                // Every voice has the same model: a strike lands on all or none.
                let at = landed.unwrap_or(modal_synth::ImpactPoint::Position(s.point_m));
                match voice.add_impulse(s.time_s, at, s.impulse_ns, s.contact_time_s) {
                    Ok(p) => landed = Some(p.into()),
                    Err(_) => break,
                }
            }
            match landed {
                Some(_) => {
                    first = first.min(s.time_s);
                    last = last.max(s.time_s + s.contact_time_s);
                }
                None => dropped += 1,
            }
        }
        let mut segments_dropped = 0;
        if let Some(d) = driven.as_mut() {
            for seg in excitation.segments {
                let (a, b) =
                    (seg.start as f64 / place.fs, (seg.start + seg.forces.len() as u64) as f64 / place.fs);
                match d.add_segment(seg.clone()) {
                    Ok(_) => {
                        first = first.min(a);
                        last = last.max(b);
                    }
                    Err(_) => segments_dropped += 1,
                }
            }
        }
        let total = place.total;
        let start = ((first * place.fs).floor() as usize).min(total);
        let last_sample = (last * place.fs).ceil() as usize + 1;
        let run = VoiceRun {
            samples: vec![Vec::new(); voices.len()],
            scratch: Vec::new(),
            voices,
            driven,
            start,
            pos: start,
            last_sample,
            peak: 0.0,
            scale: place.scale,
            near_m: place.near_m,
            far_m: place.far_m,
            strikes_dropped: dropped,
            segments_dropped,
        };
        first.is_finite().then_some(run)
    }

    fn is_silent(&self) -> bool {
        self.voices.iter().all(ModalVoice::is_silent)
            && self.driven.as_ref().is_none_or(DrivenVoice::is_silent)
    }

    /// Renders one chunk; returns its peak (over every voice).
    fn chunk(&mut self, total: usize) -> f32 {
        let len = RENDER_CHUNK.min(total - self.pos);
        let at = self.samples[0].len();
        for (voice, samples) in self.voices.iter_mut().zip(&mut self.samples) {
            samples.resize(at + len, 0.0);
            voice.render(&mut samples[at..], self.pos as u64);
        }
        if let Some(d) = self.driven.as_mut() {
            if let [only] = &mut self.samples[..] {
                d.render(&mut only[at..], self.pos as u64);
            } else {
                self.scratch.clear();
                self.scratch.resize(len, 0.0);
                d.render(&mut self.scratch, self.pos as u64);
                for samples in &mut self.samples {
                    samples[at..].iter_mut().zip(&self.scratch).for_each(|(y, x)| *y += x);
                }
            }
        }
        let block_peak = self.samples.iter().flat_map(|s| &s[at..]).fold(0.0f32, |m, x| m.max(x.abs()));
        self.peak = self.peak.max(block_peak);
        self.pos += len;
        block_peak
    }

    /// Renders until every strike has been applied.
    fn render_strikes(&mut self, total: usize) {
        while self.pos < total && self.pos <= self.last_sample {
            self.chunk(total);
        }
    }

    /// Renders until a chunk peaks below `floor` (synthesizer units) or the
    /// voice falls silent, then fades that last chunk out (no click).
    fn render_tail(&mut self, total: usize, floor: f64) {
        while self.pos < total {
            if self.is_silent() {
                return;
            }
            let at = self.samples[0].len();
            if (self.chunk(total) as f64) <= floor {
                for samples in &mut self.samples {
                    let tail = &mut samples[at..];
                    let n = tail.len();
                    for (j, x) in tail.iter_mut().enumerate() {
                        let g = 0.5 * (1.0 + (std::f64::consts::PI * (j as f64 + 0.5) / n as f64).cos());
                        *x = (*x as f64 * g) as f32;
                    }
                }
                return;
            }
        }
    }

    fn finish(mut self, mut report: ObjectReport) -> Signal {
        for x in self.samples.iter_mut().flatten() {
            *x = (*x as f64 * self.scale) as f32;
        }
        let stats = self.voices[0].stats();
        report.strikes_dropped = self.strikes_dropped;
        report.force_segments_dropped = self.segments_dropped;
        report.modes_synthesized = stats.modes_total - stats.modes_skipped;
        report.mode_samples = self.voices.iter().map(|v| v.stats().mode_samples).sum::<u64>()
            + self.driven.as_ref().map_or(0, |d| d.stats().mode_samples);
        report.samples_computed = self.samples[0].len() as u64;
        report.peak_pa_at_1m = self.peak as f64 * self.scale * FULL_SCALE_PA;
        Signal { start: self.start, samples: self.samples, report }
    }
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
