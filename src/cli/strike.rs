//! `modal strike`: strike a bank at surface points and write the sound: the
//! pressure at a listener (default 0.5 m off the first struck point, farther
//! for bodies larger than ≈ 0.25 m in radius, see
//! [`super::listener`]) or, with `--mic`, a contact microphone.

use anyhow::{bail, ensure, Context, Result};
use modal_bank::ModeBank;
use modal_scene::FULL_SCALE_PA;
use modal_synth::{
    contact, default_contact_time_s, render_strikes, OutputGain, RenderLength, Strike, SynthModel,
    SynthOptions, WavFormat, WavGain, MIN_FREQUENCY_HZ,
};
use serde::Serialize;

use super::args::StrikeArgs;
use super::bank_cmds::load_bank_with_radiation;
use super::interrupt;
use super::listener::{default_listener, listener_gains, TransferSource};
use super::output::{print_json, warn};

/// Default impulse [N·s]: a light tap (a 10 g striker at 1 m/s).
pub const DEFAULT_IMPULSE_NS: f64 = 0.01;

/// Longest automatic ring after the last strike [s]; a fade-out ends sounds
/// that ring longer.
pub const AUTO_DURATION_CAP_S: f64 = 30.0;
/// Level of `--normalize`: peak at −1 dBFS.
const NORMALIZED_PEAK: f64 = 0.891;
/// Heaviest and largest `--hertz` striker accepted [kg, m] (a wrecking ball).
const MAX_STRIKER_KG: f64 = 1e4;
const MAX_STRIKER_M: f64 = 10.0;
/// Approach speed [m/s] assumed by `--hertz` (t_c ∝ v^{−1/5}, so it matters little).
const HERTZ_SPEED_M_S: f64 = 1.0;

/// What the samples are: `listener` pressure / 20 Pa, or `contact_mic` velocity / (1 m/s).
#[derive(Serialize)]
struct OutputJson {
    kind: &'static str,
    listener_m: Option<[f64; 3]>,
    transfer: Option<TransferSource>,
}

#[derive(Serialize)]
struct StrikeJson {
    out: String,
    output: OutputJson,
    sample_rate: u32,
    duration_s: f64,
    capped: bool,
    contact_time_s: f64,
    strikes: Vec<StrikePointJson>,
    top_modes: Vec<TopModeJson>,
    peak: f64,
    clipped_samples: usize,
    modes_total: usize,
    modes_skipped: usize,
    modes_culled: u64,
    mode_samples: u64,
    samples_computed: u64,
}

#[derive(Serialize)]
struct StrikePointJson {
    requested: [f64; 3],
    surface_point: [f64; 3],
    distance_m: f64,
    impulse_ns: [f64; 3],
    time_s: f64,
}

#[derive(Serialize)]
struct TopModeJson {
    mode: usize,
    /// Undamped, as `info` and `radiation` give it.
    frequency_hz: f64,
    /// The frequency it rings at.
    damped_frequency_hz: f64,
    /// Peak amplitude as a fraction of full scale (20 Pa, or 1 m/s at `--mic`).
    amplitude: f64,
    t60_s: Option<f64>,
}

/// The k-th value of a per-strike list: one value applies to all strikes.
fn nth<T: Copy>(values: &[T], k: usize, default: T, name: &str, strikes: usize) -> Result<T> {
    match values.len() {
        0 => Ok(default),
        1 => Ok(values[0]),
        n if n == strikes => Ok(values[k]),
        n => bail!("--{name} given {n} times for {strikes} strikes: give it once or once per --at"),
    }
}

fn contact_time(args: &StrikeArgs, bank: &ModeBank, impulse_ns: f64) -> Result<f64> {
    if let Some(tau) = args.contact_time {
        return Ok(tau);
    }
    let Some([mass_kg, radius_m]) = args.hertz else {
        let lowest =
            bank.frequencies_hz.iter().copied().filter(|&f| f >= MIN_FREQUENCY_HZ).fold(f64::NAN, f64::min);
        return Ok(default_contact_time_s(lowest));
    };
    ensure!(
        (f64::MIN_POSITIVE..=MAX_STRIKER_KG).contains(&mass_kg) && (f64::MIN_POSITIVE..=MAX_STRIKER_M).contains(&radius_m),
        "--hertz needs a striker of positive mass up to {MAX_STRIKER_KG} kg and radius up to {MAX_STRIKER_M} m"
    );
    // A striker of the bank's own material hitting the (locally flat) surface.
    let m = &bank.material;
    let e_star = contact::effective_modulus(m.youngs_pa, m.poisson, m.youngs_pa, m.poisson);
    let m_eff = contact::harmonic(mass_kg, bank.mass.mass_kg);
    let speed = if impulse_ns > 0.0 { impulse_ns / mass_kg } else { HERTZ_SPEED_M_S };
    let tau =
        contact::hertz_contact_time(m_eff, radius_m, e_star, speed).context("invalid --hertz parameters")?;
    let max = contact::MAX_CONTACT_TIME_S;
    ensure!(
        tau.is_finite() && tau <= max,
        "--hertz {},{} gives a contact time of {} s, beyond the {max} s a strike may last (a striker this heavy \
         and slow pushes rather than strikes)",
        modal_mesh::readable(mass_kg),
        modal_mesh::readable(radius_m),
        modal_mesh::readable(tau)
    );
    Ok(tau)
}

pub fn run(args: StrikeArgs) -> Result<()> {
    // Everything a radiation solve could be wasted on is checked first.
    modal_synth::check_sample_rate(args.rate as f64)?;
    super::args::check_transfer_max_freq(args.transfer_max_freq)?;
    if let Some(d) = args.duration {
        ensure!(
            d.is_finite() && d > 0.0 && d <= modal_synth::MAX_DURATION_S,
            "--duration must be above 0 s and at most {} s (got {d})",
            modal_synth::MAX_DURATION_S
        );
        // (A shorter one wrote an empty WAV blamed on the strike.)
        ensure!(
            (d * args.rate as f64).round() >= 1.0,
            "--duration {d} s is shorter than one sample at --rate {} Hz",
            args.rate
        );
    }
    super::prepare_output(&args.out).with_context(|| format!("cannot write {}", args.out.display()))?;
    super::check_not_input(&args.out, &args.bank, "-o")?;
    for &t in &args.time {
        ensure!(
            t.is_finite() && (0.0..modal_synth::MAX_DURATION_S).contains(&t),
            "--time must be from 0 s to below {} s, the longest file (got {t})",
            modal_synth::MAX_DURATION_S
        );
    }
    let (bank, stored) = load_bank_with_radiation(&args.bank)?;
    let model = SynthModel::new(&bank).context("cannot synthesize this bank")?;
    let at_points = if args.at.is_empty() {
        vec![model.ringing_point().context("the bank has no surface to strike")?]
    } else {
        args.at.clone()
    };
    let n = at_points.len();
    let mut strikes = Vec::with_capacity(n);
    let mut points_json = Vec::with_capacity(n);
    for (k, &at) in at_points.iter().enumerate() {
        let point = model.locate(at).with_context(|| format!("--at {},{},{}", at[0], at[1], at[2]))?;
        let magnitude = nth(&args.impulse, k, DEFAULT_IMPULSE_NS, "impulse", n)?;
        ensure!(magnitude.is_finite() && magnitude >= 0.0, "--impulse must be a finite number >= 0 N·s");
        // Default direction: into the surface.
        let dir = nth(&args.dir, k, point.normal.map(|c| -c), "dir", n)?;
        let norm = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        ensure!(norm > 0.0, "--dir must not be the zero vector");
        let impulse_ns = dir.map(|c| c / norm * magnitude);
        let time_s = nth(&args.time, k, 0.0, "time", n)?;
        let contact_time_s = contact_time(&args, &bank, magnitude)?;
        strikes.push(Strike { time_s, at, impulse_ns, contact_time_s });
        points_json.push(StrikePointJson {
            requested: at,
            surface_point: point.position,
            distance_m: point.distance,
            impulse_ns,
            time_s,
        });
    }
    if let Some(mic) = args.mic {
        model.locate(mic).with_context(|| format!("--mic {},{},{}", mic[0], mic[1], mic[2]))?;
    }
    if let ([at], true) = (at_points.as_slice(), args.at.is_empty()) {
        // Said once the strike is known to be valid, before the slow part.
        eprintln!(
            "strike: no --at, so struck at ({:.4}, {:.4}, {:.4}) m, along the normal, where the lowest modes move most",
            at[0], at[1], at[2]
        );
    }
    // Output: the pressure at a listener (default), or a contact microphone.
    let (gain, phases, output) = match args.mic {
        Some(at) => (
            OutputGain::ContactMic { at: Some(at) },
            None,
            OutputJson { kind: "contact_mic", listener_m: None, transfer: None },
        ),
        None => {
            let listener = match args.listener {
                Some(x) => x,
                None => {
                    let p = &points_json[0];
                    let n = model.locate(p.surface_point).map(|h| h.normal).unwrap_or([0.0, 0.0, 1.0]);
                    default_listener(&bank, p.surface_point, n)?
                }
            };
            let heard = listener_gains(
                &args.bank,
                &bank,
                stored.as_ref(),
                listener,
                args.solve_radiation.then_some(args.transfer_max_freq.unwrap_or(f64::INFINITY)),
                args.rate as f64,
            )?;
            (
                OutputGain::PerMode(heard.gains),
                Some(heard.phases),
                OutputJson { kind: "listener", listener_m: Some(listener), transfer: Some(heard.source) },
            )
        }
    };
    let options = SynthOptions { sample_rate: args.rate as f64, gain, phases, ..SynthOptions::default() };
    if let Some(d) = args.duration {
        let late = strikes.iter().filter(|s| s.time_s >= d).count();
        ensure!(
            late < n,
            "every strike is at or after the end of the --duration {d} s: the file would be silent"
        );
        if late > 0 {
            warn(&format!("{late} strike(s) at or after the end of the --duration {d} s are not heard"));
        }
    }
    // The automatic length rings on for at most the cap after the last strike
    // (a lone strike at --time 31 wrote 30 s of silence).
    let last_s = strikes.iter().map(|s| s.time_s).fold(0.0, f64::max);
    let length = match args.duration {
        Some(d) => RenderLength::Fixed(d),
        None => RenderLength::Auto { cap_s: (last_s + AUTO_DURATION_CAP_S).min(modal_synth::MAX_DURATION_S) },
    };
    let mut rendered = render_strikes(&bank, &strikes, &options, length)?;
    if args.duration.is_some() {
        // A cut through a ringing body clicks; end it as `render` does.
        modal_synth::fade_out(&mut rendered.samples, (modal_scene::FADE_OUT_S * args.rate as f64) as usize);
    }
    let top_modes = top_modes(&bank, &strikes[0], &options)?;
    let format = if args.float { WavFormat::Float32 } else { WavFormat::Pcm16 };
    let gain = if args.normalize { WavGain::Normalize { peak: NORMALIZED_PEAK } } else { WavGain::default() };
    let report = interrupt::guarded(|| {
        modal_synth::write_wav(&args.out, &[&rendered.samples], args.rate, format, gain)
    })
    .with_context(|| format!("cannot write {}", args.out.display()))?;
    if report.clipped > 0 {
        warn(&format!(
            "{} samples clipped at full scale (use --float, --normalize or a smaller --impulse)",
            report.clipped
        ));
    }
    if rendered.capped {
        warn(&format!(
            "the sound rings longer than {AUTO_DURATION_CAP_S} s after the last strike: faded out at {:.1} s \
             (--duration sets the length)",
            rendered.duration_s
        ));
    }
    let stats = &rendered.stats;
    if stats.modes_total == 0 {
        warn(&format!("the bank holds no mode: {} is silent", args.out.display()));
    } else if report.peak == 0.0 && stats.modes_skipped < stats.modes_total {
        // Nothing to scale up: --normalize and --float cannot help.
        warn(&format!(
            "{} is silent: the strikes excite none of the modes it plays (a zero --impulse, or a direction \
             along which no mode moves at the struck point)",
            args.out.display()
        ));
    } else if !args.float
        && !args.normalize
        && report.peak < modal_synth::PCM16_SMALLEST_NONZERO
        && stats.modes_skipped < stats.modes_total
    {
        // A heavy body (a 35 kg beam, or a file read in the wrong unit) barely moves under
        // the default tap: say so rather than write zeros that look like a bug.
        warn(&format!(
            "the peak is {:.1e} of full scale, below half a step of 16-bit PCM: {} is silent; the body weighs {:.3e} kg, \
             so strike harder (--impulse) or use --normalize or --float",
            report.peak,
            args.out.display(),
            bank.mass.mass_kg
        ));
    }
    if stats.modes_total > 0 && stats.modes_skipped == stats.modes_total {
        super::output::warn(&format!(
            "all {} modes were skipped (below 20 Hz, above 0.45 × --rate {} Hz, or overdamped): {} is silent",
            stats.modes_total,
            args.rate,
            args.out.display()
        ));
    }
    let json = StrikeJson {
        out: args.out.display().to_string(),
        output,
        sample_rate: args.rate,
        duration_s: rendered.duration_s,
        capped: rendered.capped,
        contact_time_s: strikes[0].contact_time_s,
        strikes: points_json,
        top_modes,
        peak: report.peak,
        clipped_samples: report.clipped,
        modes_total: rendered.stats.modes_total,
        modes_skipped: rendered.stats.modes_skipped,
        modes_culled: rendered.stats.modes_culled,
        mode_samples: rendered.stats.mode_samples,
        samples_computed: rendered.stats.samples_rendered,
    };
    if args.json {
        return print_json(&json);
    }
    print_human(&json);
    Ok(())
}

/// The loudest modes the first strike excites.
fn top_modes(bank: &ModeBank, strike: &Strike, options: &SynthOptions) -> Result<Vec<TopModeJson>> {
    let voice = modal_synth::ModalVoice::new(bank, options.clone())?;
    let point = voice.locate(strike.at.into())?;
    Ok(voice
        .excitation(&point, strike.impulse_ns, strike.contact_time_s)
        .into_iter()
        .take(8)
        .map(|m| TopModeJson {
            mode: m.mode,
            frequency_hz: bank.frequencies_hz[m.mode],
            damped_frequency_hz: m.frequency_hz,
            amplitude: m.amplitude,
            t60_s: (m.decay_rate > 0.0).then(|| 1000f64.ln() / m.decay_rate),
        })
        .collect())
}

fn print_human(json: &StrikeJson) {
    for (k, s) in json.strikes.iter().enumerate() {
        let snapped = if s.distance_m == 0.0 {
            "on the surface".into()
        } else {
            format!("snapped {:.2e} m", s.distance_m)
        };
        // `+ 0.0` shows a negative zero as 0.
        let [ix, iy, iz] = s.impulse_ns.map(|c| c + 0.0);
        println!(
            "strike {}: t = {:.4} s at ({:.4}, {:.4}, {:.4}) m ({snapped}), impulse ({ix:.3e}, {iy:.3e}, {iz:.3e}) N·s",
            k + 1,
            s.time_s,
            s.surface_point[0],
            s.surface_point[1],
            s.surface_point[2],
        );
    }
    match (&json.output.listener_m, json.output.transfer) {
        (Some(l), Some(t)) => println!(
            "output: pressure at the listener ({:.4}, {:.4}, {:.4}) m, full scale 20 Pa (transfer: {})",
            l[0],
            l[1],
            l[2],
            t.name()
        ),
        _ => println!("output: contact microphone, normal surface velocity, full scale 1 m/s"),
    }
    println!("contact time {:.3e} s; loudest modes excited by the first strike:", json.contact_time_s);
    // Amplitudes are in output units: 20 Pa at the listener, 1 m/s at a contact microphone.
    let (unit, scale) = if json.output.listener_m.is_some() { ("Pa", FULL_SCALE_PA) } else { ("m/s", 1.0) };
    for m in &json.top_modes {
        let t60 = m.t60_s.map_or("inf".into(), |t| format!("{t:.3} s"));
        println!(
            "  mode {:>3}  {:>10.2} Hz  amplitude {:.3e} {unit} ({:.3} of full scale)  T60 {}",
            m.mode,
            m.frequency_hz,
            m.amplitude * scale,
            m.amplitude,
            t60
        );
    }
    println!(
        "wrote {} ({:.3} s at {} Hz, peak {:.3} of full scale, {} of {} modes skipped: below 20 Hz, above \
         0.45 × the rate ({:.0} Hz) or overdamped)",
        json.out,
        json.duration_s,
        json.sample_rate,
        json.peak,
        json.modes_skipped,
        json.modes_total,
        modal_synth::MAX_FREQUENCY_FRACTION * json.sample_rate as f64
    );
    println!(
        "work: {} mode-samples over {} computed samples; {} modes culled once below the threshold",
        json.mode_samples, json.samples_computed, json.modes_culled
    );
}
