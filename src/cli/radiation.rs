//! `modal radiation`: the pressure each mode radiates to points around the
//! object, and its radiated power (acoustic transfer, `modal-radiation`).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{ensure, Context, Result};
use clap::Args;
use modal_bank::{ModeBank, RadiationTable};
use modal_radiation::{Air, BoundaryMesh, RadiationOptions};
use serde::Serialize;

use super::bank_cmds::load_bank_with_radiation;
use super::output::{print_json, warn};

#[derive(Debug, Args)]
pub struct RadiationArgs {
    /// Mode bank.
    pub bank: PathBuf,
    /// Field point X,Y,Z [m] in the bank's frame (outside the body); repeat for several.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_point, allow_hyphen_values = true)]
    pub point: Vec<[f64; 3]>,
    /// Air density ρ₀ [kg/m³].
    #[arg(long, value_name = "KG_M3", default_value_t = 1.21, allow_negative_numbers = true)]
    pub air_density: f64,
    /// Speed of sound c [m/s].
    #[arg(long, value_name = "M_S", default_value_t = 343.0, allow_negative_numbers = true)]
    pub sound_speed: f64,
    /// Highest mode frequency solved [Hz]; modes above it cannot be heard.
    #[arg(long, value_name = "HZ", default_value_t = 20_000.0)]
    pub max_freq: f64,
    /// Only these modes (indices into the bank; repeatable); default: every audible mode.
    #[arg(long, value_name = "I")]
    pub mode: Vec<usize>,
    /// Solve every mode on the full panel mesh (no coarser panels or pressure clusters; up to 64 000
    /// panels, slower): the accurate setting for thin flat walls (plates, discs) whose default
    /// clusters are wider than the wall (docs/radiation.md).
    #[arg(long)]
    pub full_resolution: bool,
    /// With --full-resolution: split the panels at creases (a thin wall's rim, a bar's edges) in
    /// four, N rounds (0–3), grading the panels towards the rim: a reference-quality solve of a
    /// thin wall (docs/radiation.md, "Thin walls").
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub refine_creases: usize,
    /// Pressure cluster size κ: clusters of diameter κ / max(k, k_s), k the
    /// acoustic and k_s the mode's surface wavenumber (smaller: finer, dearer).
    #[arg(long, value_name = "KAPPA", default_value_t = modal_radiation::modes::DEFAULT_CLUSTER_KH)]
    pub cluster_kh: f64,
    /// Also write a copy of the bank with every solved mode's far-field
    /// representation stored in it (format version 2), for `info`, `strike`.
    #[arg(long, value_name = "OUT.bank")]
    pub store: Option<PathBuf>,
    /// Print one JSON object on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

fn parse_point(text: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = text.split(',').collect();
    if parts.len() != 3 {
        return Err(format!("expected X,Y,Z (three numbers), got \"{text}\""));
    }
    let mut p = [0.0; 3];
    for (slot, s) in p.iter_mut().zip(parts) {
        *slot = s.trim().parse::<f64>().map_err(|_| format!("\"{s}\" is not a number"))?;
        if !slot.is_finite() {
            return Err(format!("\"{s}\" is not finite"));
        }
    }
    Ok(p)
}

/// Refuses field points on the bank's surface or inside the body before
/// any solve, by the library's classification
/// ([`BoundaryMesh::check_field_point`]) on every panel level a solve may
/// evaluate the pressure on: the panels `mesh` and, for a quadratic
/// surface, its corner triangles (the low-frequency level of
/// `radiate_modes`, whose larger panels keep points farther away).
pub fn check_field_points(bank: &ModeBank, mesh: &BoundaryMesh, points: &[[f64; 3]]) -> Result<()> {
    let corners = if points.is_empty() { None } else { modal_radiation::modes::corner_mesh(bank)? };
    for &x in points {
        let place = mesh.classify(x);
        corners.as_ref().map_or(place, |c| place.and(c.classify(x))).check(x)?;
    }
    Ok(())
}

#[derive(Serialize)]
struct RadiationJson {
    air_density_kg_m3: f64,
    sound_speed_m_s: f64,
    points: Vec<[f64; 3]>,
    modes: Vec<ModeJson>,
    /// Modes not solved because they cannot be heard (outside [20 Hz, --max-freq]).
    modes_skipped: Vec<usize>,
    panels: usize,
    seconds: f64,
}

#[derive(Serialize)]
struct ModeJson {
    index: usize,
    frequency_hz: f64,
    radiated_power_w: f64,
    radiation_efficiency: f64,
    multipole_order: usize,
    pressure_pa: Vec<[f64; 2]>,
}

/// Share of the surface on walls thinner than its panels from which `radiation` warns
/// that the defaults can be several dB off ([`modal_radiation::walls`]).
const THIN_WALL_WARNING_SHARE: f64 = 0.3;

/// The warning for a bank whose surface is mostly a wall thinner than the panels the
/// defaults solve low modes on (its corner triangles), or `None` (also when those
/// panels cannot be made: the warning is advice, the solve reports its own errors).
fn thin_wall_warning(bank: &modal_bank::ModeBank) -> Option<String> {
    let corners = modal_radiation::modes::corner_mesh(bank).ok().flatten();
    let mesh = corners.or_else(|| modal_radiation::modes::boundary_mesh(bank).ok())?;
    let thin = modal_radiation::walls::thin_walls(&mesh);
    (thin.area_fraction >= THIN_WALL_WARNING_SHARE).then(|| {
        format!(
            "{:.0} % of the surface is a wall {:.2} mm thick on panels {:.1} mm wide: at the default \
             resolution a thin wall's levels can be several dB off in quiet directions; --full-resolution \
             solves it on panels half as wide, slower (docs/radiation.md, \"Thin walls\")",
            100.0 * thin.area_fraction,
            1e3 * thin.median_wall_m,
            1e3 * thin.median_panel_m
        )
    })
}

/// Most `--refine-creases` rounds: on the 20 cm × 2 mm disc two rounds took its
/// 31 360 panels to 47 488, and one round to two moved its loudest mode by ≤ 0.26 dB
/// (BENCHMARKS.md, "The thin disc again").
const MAX_CREASE_ROUNDS: usize = 3;

/// Largest `--cluster-kh` accepted (see `run`).
const MAX_CLUSTER_KH: f64 = 1.0;

pub fn run(args: RadiationArgs) -> Result<()> {
    let started = Instant::now();
    let (bank, stored) = load_bank_with_radiation(&args.bank)?;
    let air = Air { density_kg_m3: args.air_density, sound_speed_m_s: args.sound_speed };
    air.validate()?;
    ensure!(args.max_freq > 0.0, "--max-freq must be positive");
    // Coarser clusters cost accuracy fast: on the test sphere a mode's power moves by
    // 0.23 dB at κ = 0.6 and 0.65 dB at κ = 1 against the default 0.3, and by 0.8 dB
    // beyond, with no warning; so κ stops at 1 (clusters of a sixth of a wavelength).
    ensure!(
        args.cluster_kh.is_finite() && args.cluster_kh > 0.0 && args.cluster_kh <= MAX_CLUSTER_KH,
        "--cluster-kh must be above 0 and at most {MAX_CLUSTER_KH} (got {:e}): larger clusters lose accuracy",
        args.cluster_kh
    );
    ensure!(
        args.refine_creases <= MAX_CREASE_ROUNDS,
        "--refine-creases must be at most {MAX_CREASE_ROUNDS} (got {}): each round can quadruple the panels at the creases",
        args.refine_creases
    );
    ensure!(
        args.refine_creases == 0 || args.full_resolution,
        "--refine-creases needs --full-resolution (the default clusters would merge the split panels again)"
    );
    let mesh = modal_radiation::modes::boundary_mesh(&bank).context("the bank's surface cannot be used")?;
    check_field_points(&bank, &mesh, &args.point).context("--point")?;
    let audible = |i: usize| modal_radiation::modes::is_audible(&bank, i, args.max_freq);
    for &m in &args.mode {
        ensure!(m < bank.mode_count(), "mode {m} does not exist (the bank has {} modes)", bank.mode_count());
    }
    if let Some(path) = &args.store {
        super::prepare_output(path).with_context(|| format!("--store {}", path.display()))?;
    }
    let mut candidates: Vec<usize> =
        if args.mode.is_empty() { (0..bank.mode_count()).collect() } else { args.mode.clone() };
    candidates.sort_unstable();
    candidates.dedup();
    let (modes, skipped): (Vec<usize>, Vec<usize>) = candidates.into_iter().partition(|&i| audible(i));
    eprintln!(
        "radiation: {} mode(s) on {} panels ({} skipped as inaudible)",
        modes.len(),
        mesh.len(),
        skipped.len()
    );
    if modes.is_empty() {
        warn(&format!(
            "no audible mode to solve (none at {} Hz or more and at most --max-freq {} Hz)",
            modal_radiation::modes::AUDIBLE_MIN_HZ,
            args.max_freq
        ));
    }
    if !args.full_resolution && !modes.is_empty() {
        if let Some(message) = thin_wall_warning(&bank) {
            warn(&message);
        }
    }
    let opts = RadiationOptions {
        air,
        adaptive_resolution: !args.full_resolution,
        cluster_kh: args.cluster_kh,
        crease_refinement: args.refine_creases,
        memory_limit_bytes: super::precompute::memory_guard_bytes()?,
        ..RadiationOptions::default()
    };
    let results =
        modal_radiation::modes::radiate_modes_on(&bank, &mesh, &modes, &opts, &mut |p| eprintln!("{p}"))?;
    let mut out = Vec::with_capacity(results.len());
    for r in &results {
        let pressure = r.pressures_at(&args.point)?.iter().map(|z| [z.re, z.im]).collect();
        out.push(ModeJson {
            index: r.mode,
            frequency_hz: r.frequency_hz,
            radiated_power_w: r.power_w,
            radiation_efficiency: r.efficiency,
            multipole_order: r.multipole.order,
            pressure_pa: pressure,
        });
    }
    out.sort_by_key(|m| m.index);
    if let Some(path) = &args.store {
        match modal_radiation::modes::to_table(&results, &opts) {
            Some(table) => {
                let table = keep_other_modes(table, stored.clone(), &bank);
                super::interrupt::guarded(|| bank.save_with_radiation(path, &table))
                    .with_context(|| format!("cannot write bank {}", path.display()))?;
                eprintln!("radiation: stored {} mode(s) in {}", table.modes.len(), path.display());
            }
            None => anyhow::bail!("no audible mode to store in {}", path.display()),
        }
    }
    let seconds = started.elapsed().as_secs_f64();
    eprintln!("radiation: done in {seconds:.2} s");
    let report = RadiationJson {
        air_density_kg_m3: air.density_kg_m3,
        sound_speed_m_s: air.sound_speed_m_s,
        points: args.point.clone(),
        modes: out,
        modes_skipped: skipped,
        panels: mesh.len(),
        seconds,
    };
    if args.json {
        return print_json(&report);
    }
    // The level column only when there are points (--point) to show.
    let level_header = if args.point.is_empty() { "" } else { "  level at each point [dB SPL]" };
    println!(
        "{:>5} {:>11} {:>12} {:>10} {:>5}{level_header}",
        "mode", "freq [Hz]", "power [W]", "efficiency", "order"
    );
    for m in &report.modes {
        let levels: Vec<String> = m
            .pressure_pa
            .iter()
            .map(|[re, im]| {
                let rms = (re * re + im * im).sqrt() / 2f64.sqrt();
                format!("{:.1}", 20.0 * (rms / 20e-6).log10())
            })
            .collect();
        let levels = if levels.is_empty() { String::new() } else { format!("  {}", levels.join(" ")) };
        println!(
            "{:>5} {:>11.2} {:>12.4e} {:>10.3e} {:>5}{levels}",
            m.index, m.frequency_hz, m.radiated_power_w, m.radiation_efficiency, m.multipole_order,
        );
    }
    Ok(())
}

/// The table to store: `solved` (this run's modes) plus the entries the
/// input bank already held for other modes, so `--mode I` or a lower
/// `--max-freq` adds to a stored transfer instead of dropping the rest. An
/// old entry is kept only where it describes the same problem: the same
/// expansion centre, fit radius, air and tolerance, and a wavenumber within
/// the solver's grouping tolerance of the mode's frequency now; otherwise
/// the old entries are dropped, and a warning says how many.
fn keep_other_modes(solved: RadiationTable, old: Option<RadiationTable>, bank: &ModeBank) -> RadiationTable {
    let Some(old) = old else { return solved };
    let others: Vec<_> = old.modes.into_iter().filter(|m| solved.mode(m.mode).is_none()).collect();
    if others.is_empty() {
        return solved;
    }
    let same_problem = old.centre_m == solved.centre_m
        && old.fit_radius_m == solved.fit_radius_m
        && old.air_density_kg_m3 == solved.air_density_kg_m3
        && old.sound_speed_m_s == solved.sound_speed_m_s
        && old.tolerance == solved.tolerance;
    let tolerance = RadiationOptions::default().group_tolerance;
    let (kept, stale): (Vec<_>, Vec<_>) = others.into_iter().partition(|m| {
        let f = m.wavenumber * solved.sound_speed_m_s / (2.0 * std::f64::consts::PI);
        let now = bank.frequencies_hz.get(m.mode).copied().unwrap_or(f64::NAN);
        same_problem && (f - now).abs() <= tolerance * now
    });
    if !stale.is_empty() {
        warn(&format!(
            "{} transfer(s) stored for other modes were solved for other air, another surface or other \
             frequencies: not kept (solve them again with `modal radiation`)",
            stale.len()
        ));
    }
    let mut table = solved;
    table.modes.extend(kept);
    table.modes.sort_by_key(|m| m.mode);
    table
}
