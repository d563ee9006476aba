//! What `strike` hears at a listener: per-mode complex pressure transfer.
//!
//! Mode `i` vibrating with modal velocity `Re(V_i e^{−iωt})` radiates
//! `Re(T_i(x) V_i e^{−iωt})` at the listener, `T_i(x)` the complex pressure
//! [Pa] for unit modal velocity amplitude (`modal radiation`). In the
//! synthesizer's convention (`e^{+iωt}`, [`modal_synth::SynthOptions::phases`]) that
//! is the real gain `g_i = |T_i| / FULL_SCALE_PA` (level, decay and culling
//! use it) times the unit factor `conj(T_i e^{−ik_i r₀}) / |T_i|`. The phase
//! matters: symmetric bodies (a bowl, a bell, a sphere) have pairs of modes
//! at one frequency whose transfers add or cancel at the listener depending
//! on how the pair's shapes happen to be turned; with `|T_i|` alone the
//! level of a rim strike on a glass bowl changed by 47 dB with the strike's
//! angle. `e^{−ik_i r₀}` (`r₀` one distance for every mode, the listener's
//! from the expansion centre) removes the common propagation delay `r₀/c`,
//! so the file starts at the strike rather than `r₀/c` later, as `render`
//! does before its own delay. Samples are pressure divided by
//! [`FULL_SCALE_PA`], the full scale of `render` at gain 1.
//!
//! The transfer comes from, in order of preference:
//! 1. the bank's stored radiation table (`modal radiation --store`); its
//!    multipole expansion is only valid beyond the fit radius `r_f` (and
//!    diverges inside it), so a listener at `r < r_f` from the centre of
//!    mass hears, as in `render`, the field at `r_f` in its direction
//!    spread back by `r_f / max(r, r_min)` (`r_min` = `MIN_DISTANCE_M`; at
//!    the centre itself, where no direction is defined, the
//!    direction-averaged level, with no phase);
//! 2. a boundary-element solve now (`--solve-radiation`),
//! 3. the level estimate `render` uses without radiation (a pulsating
//!    sphere with the object's area and the mode's RMS normal velocity,
//!    `ρ₀c (a/r) (ka/√(1+(ka)²)) v_i`), with a warning. It has no phase;
//!    modes of one frequency get [`modal_synth::degenerate_phases`], so a
//!    pair is heard at its energy sum, not at a level set by how the
//!    eigensolver turned it.

use std::path::Path;

use anyhow::{Context, Result};
use modal_bank::{ModeBank, RadiationTable};
use modal_radiation::{c64, Air, RadiationOptions};
use modal_scene::{AIR_IMPEDANCE_PA_S_M, FULL_SCALE_PA, MIN_DISTANCE_M, SPEED_OF_SOUND_M_S};
use modal_synth::{SynthModel, C64};

use super::output::warn;

/// Default listener distance from the first struck point, along its outward normal [m].
pub const DEFAULT_LISTENER_DISTANCE_M: f64 = 0.5;

/// `strike`'s default listener: [`DEFAULT_LISTENER_DISTANCE_M`] off the
/// first struck point `surface_point` along its outward `normal`, or, for a
/// body too large for that (bounding radius above ≈ 0.25 m), farther along
/// the same line until it reaches the sphere beyond which a stored far
/// field is accurate ([`modal_radiation::multipole::FIT_RADIUS_PER_BODY_RADIUS`]
/// bounding radii from the centre of mass). So the default hears the whole
/// body as a listener in the room would, never an expansion inside its fit
/// radius.
pub fn default_listener(bank: &ModeBank, surface_point: [f64; 3], normal: [f64; 3]) -> Result<[f64; 3]> {
    let mesh = modal_radiation::modes::boundary_mesh(bank).context("the bank's surface cannot be used")?;
    let centre = bank.mass.center_of_mass_m;
    let fit_radius = modal_radiation::multipole::FIT_RADIUS_PER_BODY_RADIUS * mesh.radius_about(centre);
    // A hair outside, so rounding never puts it inside (and warns).
    let radius = fit_radius * (1.0 + 1e-9);
    Ok(beyond_sphere(surface_point, normal, centre, radius, DEFAULT_LISTENER_DISTANCE_M))
}

/// The point `start + t·n̂` with the smallest `t ≥ min_distance` at which
/// `|x − centre| ≥ radius`: `t = −d·n̂ + √((d·n̂)² − |d|² + radius²)`,
/// `d = start − centre`, when that exceeds `min_distance` (`start` lies
/// inside the sphere, so the root is real and positive).
fn beyond_sphere(start: [f64; 3], n: [f64; 3], centre: [f64; 3], radius: f64, min_distance: f64) -> [f64; 3] {
    let length = distance(n, [0.0; 3]);
    let n = if length > 0.0 { n.map(|c| c / length) } else { [0.0, 0.0, 1.0] };
    let d = [0, 1, 2].map(|q| start[q] - centre[q]);
    let dn = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
    let discriminant = dn * dn - (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + radius * radius;
    let exit = if discriminant > 0.0 { -dn + discriminant.sqrt() } else { 0.0 };
    let t = exit.max(min_distance);
    [0, 1, 2].map(|q| start[q] + t * n[q])
}

/// Where the per-mode transfer came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TransferSource {
    /// The bank's stored multipole expansions.
    Stored,
    /// A boundary-element solve in this run.
    Solved,
    /// The pulsating-sphere level estimate (no radiation data).
    Estimate,
}

impl TransferSource {
    /// The name `--json` gives it.
    pub fn name(self) -> &'static str {
        match self {
            TransferSource::Stored => "stored",
            TransferSource::Solved => "solved",
            TransferSource::Estimate => "estimate",
        }
    }
}

/// Per-mode output gains (sample units per unit modal velocity) at a listener.
pub struct ListenerGains {
    /// One gain per bank mode: `|T_i| / FULL_SCALE_PA`.
    pub gains: Vec<f64>,
    /// One unit factor per bank mode, the transfer's phase (module doc);
    /// for estimated modes, [`modal_synth::degenerate_phases`].
    pub phases: Vec<C64>,
    /// Where the transfer came from.
    pub source: TransferSource,
}

/// Gains for a listener at `x` (bank frame) of the bank stored at `path`
/// with its stored transfer `table`, for the modes a render at `sample_rate_hz` plays (the others are never
/// heard, so never solved).
pub fn listener_gains(
    path: &Path,
    bank: &ModeBank,
    table: Option<&RadiationTable>,
    x: [f64; 3],
    solve_up_to_hz: Option<f64>,
    sample_rate_hz: f64,
) -> Result<ListenerGains> {
    let mesh = modal_radiation::modes::boundary_mesh(bank).context("the bank's surface cannot be used")?;
    super::radiation::check_field_points(bank, &mesh, &[x]).context("--listener")?;
    let mut audible = modal_radiation::modes::audible_modes(bank, f64::INFINITY);
    audible.retain(|&i| {
        let (f, d, xi) = (bank.frequencies_hz[i], bank.decay_rates[i], bank.damping_ratios[i]);
        modal_synth::classify_mode(f, d, xi, sample_rate_hz).is_ok()
    });
    if let Some(table) = table.filter(|_| solve_up_to_hz.is_none()) {
        let estimated = estimate(bank, x)?;
        let mut heard = Heard::new(bank.mode_count());
        let mut missing = 0;
        let r = distance(x, table.centre_m);
        // The field is taken at the fit sphere inside it (`held_pressure`),
        // and has no phase at the centre itself.
        let r_ref = if r > 0.0 { r.max(table.fit_radius_m) } else { 0.0 };
        if r < table.fit_radius_m {
            warn(&format!(
                "the listener is {r:.3} m from the centre of mass, inside the {:.3} m radius the stored far field \
                 is accurate beyond: it hears the field at that radius spread back to it, as `render` does \
                 (--solve-radiation for the near field)",
                table.fit_radius_m
            ));
        }
        for &i in &audible {
            match table.mode(i) {
                Some(entry) => {
                    let mp = modal_radiation::modes::stored_multipole(table, entry);
                    heard.set(i, held_pressure(&mp, x), mp.wavenumber * r_ref);
                }
                None => {
                    heard.estimated(i, &estimated);
                    missing += 1;
                }
            }
        }
        if missing > 0 {
            warn(&format!("{missing} audible mode(s) have no stored radiation: their level is estimated"));
        }
        return Ok(heard.from(TransferSource::Stored));
    }
    if let Some(max_hz) = solve_up_to_hz {
        let (solved, above): (Vec<usize>, Vec<usize>) =
            audible.iter().partition(|&&i| bank.frequencies_hz[i] <= max_hz);
        if !above.is_empty() {
            warn(&format!(
                "{} audible mode(s) above --transfer-max-freq {max_hz} Hz keep the level estimate",
                above.len()
            ));
        }
        let opts = RadiationOptions {
            air: Air::default(),
            memory_limit_bytes: super::precompute::memory_guard_bytes()?,
            ..RadiationOptions::default()
        };
        let started = std::time::Instant::now();
        let results = if solved.is_empty() {
            Vec::new()
        } else {
            modal_radiation::modes::radiate_modes_on(bank, &mesh, &solved, &opts, &mut |p| eprintln!("{p}"))?
        };
        eprintln!("radiation: {} mode(s) solved in {:.2} s", results.len(), started.elapsed().as_secs_f64());
        let mut heard = Heard::new(bank.mode_count());
        if !above.is_empty() {
            let estimated = estimate(bank, x)?;
            for i in above {
                heard.estimated(i, &estimated);
            }
        }
        for r in &results {
            let r_ref = distance(x, r.multipole.centre);
            heard.set(r.mode, r.pressure_at(x)?, r.multipole.wavenumber * r_ref);
        }
        return Ok(heard.from(TransferSource::Solved));
    }
    warn(&format!(
        "{} has no radiation data: the listener level is a pulsating-sphere estimate \
         (run `modal radiation BANK --store OUT.bank`, or strike with --solve-radiation)",
        path.display()
    ));
    estimate(bank, x)
}

/// The pulsating-sphere estimate at `x` for every mode, with the phases of
/// modes heard without a transfer ([`modal_synth::degenerate_phases`]).
fn estimate(bank: &ModeBank, x: [f64; 3]) -> Result<ListenerGains> {
    let gains = estimate_gains(bank, x)?;
    let phases = modal_synth::degenerate_phases(&bank.frequencies_hz);
    Ok(ListenerGains { gains, phases, source: TransferSource::Estimate })
}

/// Gains and phases being filled in, mode by mode.
struct Heard {
    gains: Vec<f64>,
    phases: Vec<C64>,
}

impl Heard {
    fn new(modes: usize) -> Heard {
        Heard { gains: vec![0.0; modes], phases: vec![C64::new(1.0, 0.0); modes] }
    }

    /// Mode `i` heard through the transfer `t` [Pa per unit modal velocity]
    /// whose common delay is the phase `kr₀` (module doc).
    fn set(&mut self, i: usize, t: c64, k_r0: f64) {
        let level = t.norm();
        self.gains[i] = level / FULL_SCALE_PA;
        if level > 0.0 && level.is_finite() {
            let (s, c) = k_r0.sin_cos();
            // conj(t e^{−ikr₀}) = conj(t) e^{ikr₀}.
            let reduced = c64::new(t.re, -t.im) * c64::new(c, s) / level;
            self.phases[i] = C64::new(reduced.re, reduced.im);
        }
    }

    /// Mode `i` heard through the level `estimate` (no transfer for it).
    fn estimated(&mut self, i: usize, estimate: &ListenerGains) {
        self.gains[i] = estimate.gains[i];
        self.phases[i] = estimate.phases[i];
    }

    fn from(self, source: TransferSource) -> ListenerGains {
        ListenerGains { gains: self.gains, phases: self.phases, source }
    }
}

/// The radiation table stored in the bank file at `path` (`None` for banks
/// without one; a glTF's is in its exact side data, `extras.modal`).
pub fn stored_radiation(path: &Path) -> Result<Option<modal_bank::RadiationTable>> {
    if modal_export::gltf::is_gltf_path(path) {
        let imported = modal_export::gltf::import_gltf_file(path)
            .with_context(|| format!("cannot load bank {}", path.display()))?;
        return Ok(imported.radiation);
    }
    let (_, table) = ModeBank::load_with_radiation(path)
        .with_context(|| format!("cannot load bank {}", path.display()))?;
    Ok(table)
}

/// `p` [Pa] of the stored expansion `mp` heard at `x` (module doc): `P(x)`
/// beyond the fit radius, the fit sphere's field spread back by
/// `r_f / max(r, r_min)` inside it, the direction-averaged level (real) at
/// the centre.
fn held_pressure(mp: &modal_radiation::Multipole, x: [f64; 3]) -> c64 {
    let r = distance(x, mp.centre);
    if r >= mp.fit_radius {
        return mp.pressure_at(x);
    }
    let spread = mp.fit_radius / r.max(MIN_DISTANCE_M);
    if r == 0.0 {
        // The far-field level at the fit radius, RMS over directions.
        return c64::new(mp.far_field_rms() / mp.fit_radius * spread, 0.0);
    }
    let on_sphere = [0, 1, 2].map(|q| mp.centre[q] + (x[q] - mp.centre[q]) * mp.fit_radius / r);
    mp.pressure_at(on_sphere) * spread
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// `render`'s level estimate per mode at `x`, in sample units.
fn estimate_gains(bank: &ModeBank, x: [f64; 3]) -> Result<Vec<f64>> {
    let model = SynthModel::new(bank).context("cannot synthesize this bank")?;
    let area: f64 = modal_radiation::modes::boundary_mesh(bank)?.area();
    let a = (area / (4.0 * std::f64::consts::PI)).sqrt();
    let r = distance(x, bank.mass.center_of_mass_m).max(MIN_DISTANCE_M);
    Ok(model
        .rms_normal_shapes()
        .iter()
        .zip(&bank.frequencies_hz)
        .map(|(v, f)| {
            let ka = 2.0 * std::f64::consts::PI * f / SPEED_OF_SOUND_M_S * a;
            AIR_IMPEDANCE_PA_S_M * (a / r) * ka / (1.0 + ka * ka).sqrt() * v / FULL_SCALE_PA
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use modal_radiation::{c64, Multipole};

    /// A degree-2 expansion about `centre` fitted at 0.3 m.
    fn expansion(centre: [f64; 3]) -> Multipole {
        let coefficients = (0..9).map(|j| c64::new(0.3 * j as f64 - 1.0, 0.1 * (j % 4) as f64)).collect();
        Multipole { centre, wavenumber: 20.0, fit_radius: 0.3, order: 2, coefficients }
    }

    #[test]
    fn the_default_listener_is_half_a_metre_off_or_on_the_fit_sphere_if_farther() {
        let c = [0.2, -0.1, 0.3];
        let start = [0.25, -0.1, 0.3];
        let n = [0.0, 0.0, 2.0]; // not unit: the direction counts
                                 // A small body: 0.5 m along the normal.
        let near = beyond_sphere(start, n, c, 0.3, 0.5);
        assert_eq!(near, [0.25, -0.1, 0.8]);
        // A large one: on the fit sphere, along the same line, beyond 0.5 m.
        for radius in [1.0, 3.0, 40.0] {
            let x = beyond_sphere(start, n, c, radius, 0.5);
            assert!((distance(x, c) - radius).abs() <= 1e-12 * radius, "radius {radius}: {x:?}");
            assert_eq!([x[0], x[1]], [start[0], start[1]]);
            assert!(x[2] - start[2] > 0.5);
        }
        // A normal pointing back past the centre still leaves the sphere.
        let x = beyond_sphere(start, [-1.0, 0.0, 0.0], c, 2.0, 0.5);
        assert!((distance(x, c) - 2.0).abs() <= 1e-12 && x[0] < c[0]);
    }

    #[test]
    fn a_listener_inside_the_fit_radius_hears_the_fit_sphere_spread_back() {
        let c = [0.1, -0.2, 0.05];
        let mp = expansion(c);
        let at = |dir: [f64; 3], r: f64| held_pressure(&mp, [0, 1, 2].map(|q| c[q] + dir[q] * r)).norm();
        let dir = [0.6, 0.0, 0.8];
        // Beyond the fit radius: the expansion itself.
        let far = [0, 1, 2].map(|q| c[q] + dir[q] * 0.7);
        assert_eq!(held_pressure(&mp, far), mp.pressure_at(far));
        // Continuous at the fit radius, then 1/r inwards, held below r_min.
        let on = at(dir, 0.3);
        assert!((at(dir, 0.3 * (1.0 - 1e-12)) - on).abs() < 1e-9 * on);
        assert!((at(dir, 0.15) - 2.0 * on).abs() < 1e-12 * on);
        let held = on * 0.3 / MIN_DISTANCE_M;
        for r in [0.05, 1e-3, 1e-9] {
            // (At 1 nm the direction keeps ~8 digits of the offset from c.)
            assert!((at(dir, r) - held).abs() < 1e-6 * held, "r = {r}");
        }
        // The expansion itself diverges there; the held level does not.
        assert!(mp.pressure_at([0, 1, 2].map(|q| c[q] + dir[q] * 1e-3)).norm() > 1e3 * held);
        // At the centre: the direction-averaged level at the fit radius, spread back.
        let mean: f64 = (0..400)
            .map(|i| {
                // Fibonacci directions.
                let z = 1.0 - (2.0 * i as f64 + 1.0) / 400.0;
                let phi = i as f64 * std::f64::consts::PI * (3.0 - 5f64.sqrt());
                let s = (1.0 - z * z).sqrt();
                mp.far_field([s * phi.cos(), s * phi.sin(), z]).norm_sqr()
            })
            .sum::<f64>()
            / 400.0;
        let centre = held_pressure(&mp, c).norm();
        let want = mean.sqrt() / 0.3 * 0.3 / MIN_DISTANCE_M;
        assert!(centre.is_finite() && (centre - want).abs() < 0.01 * want, "{centre} vs {want}");
    }
}
