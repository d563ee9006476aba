//! Discretization levels: the per-mode error estimate of every bank made from a
//! surface mesh, and `--accuracy PCT` (issue 14, item 4).
//!
//! 1. Level 0 is the requested discretization (the mesher's default sizing, or the
//!    user's `--cell`). A coarser level (the tetrahedralizer's cell × [`COARSE_FACTOR`];
//!    its whole sizing field scales with the cell) is solved beside it and
//!    [`crate::accuracy::estimate`] gives each mode's error. Richardson compares two
//!    discretizations of the *same* solid: a coarse level whose mesh falls into a
//!    different number of free parts (measured: two boxes sharing an edge, kept apart
//!    at the fine cell, joined through faces at 1.5×, estimate 137× the true error) is
//!    another object, so it is replaced by one at [`MILD_COARSE_FACTOR`] (the part
//!    count is the number of rigid-body modes removed).
//! 2. While the largest estimate over the lowest [`AccuracyTarget::modes`] modes is
//!    above the target (or unknown), the element sizes shrink by the factor the
//!    estimate predicts, `s' = s · 0.9 (target / worst)^{1/p}` (clamped to
//!    [[`MIN_STEP`], [`MAX_STEP`]]), and the previous level becomes the coarse one. A
//!    level whose predicted solver memory, `memory · (s / s')⁴` (DOF ∝ s⁻³, fill of a
//!    nested-dissection factor ∝ DOF^{4/3}), exceeds the memory guard (75 % of the
//!    available memory, the eigensolver's own default limit) is not attempted: the
//!    bank says what it reached and what the next level would need. So does a level
//!    refused by the mesher's or the solver's own guards, and a level whose predicted
//!    wall time, `t · (s / s')⁶` (`t`: the last level's; a nested-dissection
//!    factorization costs ∝ DOF², measured ∝ s⁻⁵·¹ … s⁻⁶·⁰ on the corpus holed sphere),
//!    would take the run past [`TIME_BUDGET_S`].
//! 3. An explicit `--cell` is a prescribed discretization: it gets its estimate and a
//!    warning when the target is missed, with the cell that would reach it, but it is
//!    not refined. A tet mesh file (or an in-memory mesh) cannot be re-meshed here: it
//!    is solved as it is and gets no estimate ([`PRESCRIBED_NOTE`]).
//!
//! Every level is solved over a band widened by [`BAND_MARGIN`] (and a few more modes),
//! so the modes near the band edges have partners on the other level; the bank is then
//! cut back to the requested band and mode count.

use modal_bank::ModeBank;

use crate::accuracy::{estimate, LevelEstimate, ASSUMED_ORDER};
use crate::load::LevelSize;
use crate::pipeline::{assemble_and_analyze, solve_bank};
use crate::{is_surface_file, MeshSource, PrecomputeError, Request, Stage};

/// Part of the cache key of banks made to an accuracy target; bump when the levels
/// or the estimate change.
pub const LEVELS_VERSION: &str = "levels-4";

/// Element sizes of the coarse level relative to the fine one.
pub const COARSE_FACTOR: f64 = 1.5;

/// Coarse factor used instead of [`COARSE_FACTOR`] when the coarser level's mesh has a
/// different number of free parts than the fine one (√1.5: half the step).
pub const MILD_COARSE_FACTOR: f64 = 1.224_744_871_391_589;

/// A refinement is not started when the run (all levels so far plus the predicted next
/// one) would exceed this many seconds of wall time; the bank says what was reached.
pub const TIME_BUDGET_S: f64 = 60.0;

/// Exponent of the predicted time of a level in its size step (see the module docs).
const TIME_EXPONENT: i32 = 6;

/// Smallest and largest size step of one refinement.
pub const MIN_STEP: f64 = 0.4;
/// See [`MIN_STEP`].
pub const MAX_STEP: f64 = 0.8;

/// At most this many refinements after level 0.
pub const MAX_REFINEMENTS: usize = 3;

/// Levels are solved over `[min / BAND_MARGIN, max · BAND_MARGIN]`.
pub const BAND_MARGIN: f64 = 1.3;

/// Warning for a prescribed tet mesh under an accuracy target.
pub const PRESCRIBED_NOTE: &str =
    "no error estimate: a tet mesh file is solved as given (the estimate needs a \
     second, coarser mesh of the same object; give the surface mesh (OBJ/STL/PLY/OFF/glTF) to get one)";

/// What `--accuracy` asks for.
#[derive(Clone, Debug, PartialEq)]
pub struct AccuracyTarget {
    /// Largest acceptable estimated error of a frequency [%].
    pub target_pct: f64,
    /// The target applies to the lowest this many modes of the bank (every mode
    /// still gets its estimate).
    pub modes: usize,
}

/// How many of the lowest modes the default accuracy target applies to.
pub const DEFAULT_ACCURACY_MODES: usize = 10;

impl Default for AccuracyTarget {
    /// 1 % on the lowest [`DEFAULT_ACCURACY_MODES`] modes (the CLI default).
    fn default() -> Self {
        AccuracyTarget { target_pct: 1.0, modes: DEFAULT_ACCURACY_MODES }
    }
}

/// At most this many coarser first levels are tried when the default one does not fit
/// the memory guard ([`within_memory`]). A layered shell's memory barely moves with its
/// sizes (a 0.3 mm tin can: 1.32, 1.28, 1.19× the guard at × 1, 1.13, 1.81): with 5
/// retries it was refused at × 1.69 and fits from × 4.3, 13 steps of at least × 1.1.
/// Those refusals are estimates made before meshing, each well under a second.
pub const MEMORY_RETRIES: usize = 16;

/// Margin on the memory overrun when the first level is coarsened to fit.
const MEMORY_MARGIN: f64 = 1.25;

/// Runs `attempt` on the request's own discretization (`None`) and, when that is the
/// tool's default (a surface mesh without `--cell`) and the solve is refused for the
/// memory guard, on element sizes × `f` (`Some(LevelSize::Factor(f))`), up to
/// [`MEMORY_RETRIES`] times: the defaults must give an answer, not a refusal after a
/// minute of meshing (a glass of 1.5 mm wall on a stem: 1.9 M DOF, a 32 GB factor). The
/// factor comes from the overrun by the module doc's model, memory ∝ s⁻⁴, with
/// [`MEMORY_MARGIN`]. Returns the result and the level it was solved at; the warning
/// says what was coarsened and why.
pub(crate) fn within_memory<T>(
    request: &Request,
    warnings: &mut Vec<String>,
    mut attempt: impl FnMut(Option<LevelSize>) -> Result<T, PrecomputeError>,
) -> Result<(T, Option<LevelSize>), PrecomputeError> {
    let adjustable = request.surface.cell.is_none() && remeshable(&request.source);
    let (mut level, mut factor, mut first_overrun) = (None, 1.0, None);
    for retry in 0.. {
        match attempt(level) {
            Ok(result) => {
                if let Some((needed, limit)) = first_overrun {
                    warnings.push(format!(
                        "the mesh at the default element sizes needs ≈ {:.1} GB, above the memory limit of {:.1} GB: \
                         meshed with every element size × {factor:.2} instead, so expect larger errors than at the \
                         defaults (the error estimate says how large), and the bank is not cached; more memory \
                         (MODAL_MEMORY_LIMIT_GB) or --cell decide otherwise",
                        needed as f64 / 1e9,
                        limit as f64 / 1e9
                    ));
                }
                return Ok((result, level));
            }
            Err(err) => match err.memory_overrun() {
                Some((needed, limit)) if adjustable && retry < MEMORY_RETRIES && limit > 0 => {
                    first_overrun.get_or_insert((needed, limit));
                    let overrun = needed as f64 / limit as f64;
                    factor *= (MEMORY_MARGIN * overrun).powf(0.25).max(1.1);
                    level = Some(LevelSize::Factor(factor));
                }
                _ => return Err(err),
            },
        }
    }
    unreachable!("the loop returns")
}

/// Refuses a first level coarsened to fit the memory guard (`level` a size
/// factor, [`within_memory`]) whose mesh has fallen apart: more separate
/// parts than the surface has bodies, or less than [`FIT_VOLUME_KEPT`] of
/// the volume the surface encloses. Its walls are thinner than the coarser
/// cells; solved, the object would ring as loose pieces (a wine glass of
/// 1.5 mm wall at × 1.40: six parts, 36 rigid modes removed, its first mode
/// 244 Hz against 285 Hz at × 1.37) or as a fragment (a scanned bust of
/// 1.2 mm wall at × 2.42: 10 % of its mass in 23 parts, the non-manifold scan
/// counted as as many bodies). Said before the solve.
pub(crate) fn refuse_broken_fit(
    assembled: &crate::pipeline::Assembled,
    level: Option<LevelSize>,
) -> Result<(), PrecomputeError> {
    match broken_fit(level, assembled.parts, assembled.surface_bodies, assembled.volume_kept) {
        Some(why) => Err(PrecomputeError::Invalid(why)),
        None => Ok(()),
    }
}

/// Why [`refuse_broken_fit`] refuses a level of `parts` parts keeping
/// `volume_kept` of a surface of `surface_bodies` bodies; `None`: it does not.
fn broken_fit(
    level: Option<LevelSize>,
    parts: usize,
    surface_bodies: Option<usize>,
    volume_kept: Option<f64>,
) -> Option<String> {
    let Some(LevelSize::Factor(factor)) = level else {
        return None;
    };
    let coarsened =
        format!("to fit the memory limit the mesh was coarsened (every element size × {factor:.2})");
    let advice = "More memory (MODAL_MEMORY_LIMIT_GB) decides otherwise";
    let plural = |n: usize| if n == 1 { "" } else { "s" };
    if let Some(kept) = volume_kept.filter(|k| *k < FIT_VOLUME_KEPT) {
        return Some(format!(
            "{coarsened}, and at those sizes it holds {:.0} % of the volume the surface encloses, in {parts} \
             part{}: walls thinner than the cells; refused rather than solved as a fragment. {advice}",
            100.0 * kept,
            plural(parts)
        ));
    }
    let bodies = surface_bodies.filter(|b| parts > *b)?;
    Some(format!(
        "{coarsened}, and at those sizes it falls apart into {parts} parts (the surface is {bodies} bod{}): walls \
         thinner than the cells; refused rather than solved as loose pieces. {advice}",
        if bodies == 1 { "y" } else { "ies" }
    ))
}

/// The least fraction of the surface's volume a mesh coarsened to fit the
/// memory guard must keep ([`refuse_broken_fit`]); the default levels of
/// ordinary assets keep 97–100 % (a scanned dragon 97.4 %, a bunny 99.8 %).
pub const FIT_VOLUME_KEPT: f64 = 0.8;

/// True when the source can be meshed at other sizes (a surface mesh file).
pub fn remeshable(source: &MeshSource) -> bool {
    matches!(source, MeshSource::File(path) if is_surface_file(path))
}

/// One solved level.
struct Level {
    bank: ModeBank,
    dofs: usize,
    memory: u64,
    size_factor: f64,
    /// Wall time of this level (mesh, assembly, solve) [s].
    seconds: f64,
    /// The tetrahedralizer's cell of this level [m].
    cell_m: f64,
    /// Meshed in layers across a thin wall.
    layered: bool,
    warnings: Vec<String>,
}

/// Solves level `index`: the request's own discretization for `base = None`,
/// else the finest level's size `base` scaled by `size_factor` (a stuffed
/// solid's cell, whose whole sizing field scales with it, or a layered
/// shell's default sizes).
fn solve_level(
    wide: &Request,
    index: usize,
    base: Option<LevelSize>,
    size_factor: f64,
    key: &str,
    progress: &mut dyn FnMut(Stage),
) -> Result<Level, PrecomputeError> {
    let level = base.map(|b| b.scaled(size_factor));
    // A factor level says its sizes against the defaults (a first level coarsened for
    // memory included); a cell level against the first level's cell.
    let shown = match level {
        Some(LevelSize::Factor(f)) => f,
        _ => size_factor,
    };
    progress(Stage::Level { index, size_factor: shown });
    let start = std::time::Instant::now();
    // The coarse level (1) only measures the error: its mesh's warnings are not the bank's.
    let mut said = |stage: Stage| {
        if index != 1 || !matches!(stage, Stage::Warning(_)) {
            progress(stage)
        }
    };
    let (assembled, analysis) = assemble_and_analyze(wide, true, level, &mut said)?;
    if index == 0 {
        refuse_broken_fit(&assembled, level)?;
    }
    let (bank, memory) = solve_bank(wide, &assembled, analysis, key.to_string(), &mut said)?;
    let level_cell = match level {
        Some(LevelSize::Cell(c)) => Some(c),
        _ => None,
    };
    let cell_m = assembled.cell_m.or(level_cell).unwrap_or(f64::NAN);
    let seconds = start.elapsed().as_secs_f64();
    Ok(Level {
        dofs: bank.info.dofs,
        bank,
        memory,
        size_factor,
        seconds,
        cell_m,
        layered: assembled.layered,
        warnings: assembled.warnings,
    })
}

/// The request every level solves: the band widened by [`BAND_MARGIN`], a few more modes
/// (the mesh still sized for the request's own modes).
fn widened(request: &Request) -> Request {
    let mut wide = request.clone();
    wide.surface = request.surface_meshing();
    wide.min_freq_hz = request.min_freq_hz / BAND_MARGIN;
    wide.max_freq_hz = request.max_freq_hz * BAND_MARGIN;
    wide.max_modes = request.max_modes.saturating_add((request.max_modes / 4).max(6));
    wide
}

/// Solves `request` (a surface mesh) on as many levels as `target` needs (see the
/// module docs) and returns the finest bank with its per-mode estimate, warnings, and
/// whether the first level was coarsened to fit the memory guard ([`within_memory`]).
pub(crate) fn solve_to_accuracy(
    request: &Request,
    target: &AccuracyTarget,
    key: &str,
    progress: &mut dyn FnMut(Stage),
) -> Result<(ModeBank, Vec<String>, bool), PrecomputeError> {
    let wide = widened(request);
    let mut warnings = Vec::new();
    let (mut fine, first) =
        within_memory(request, &mut warnings, |level| solve_level(&wide, 0, level, 1.0, key, progress))?;
    let coarsened = first.is_some();
    warnings.append(&mut fine.warnings);
    let in_band = trim(&fine.bank, request, None).0;
    if in_band.mode_count() == 0 {
        // A silent bank (a bead rings above the band) has no error to estimate: finer
        // levels cannot add a mode to the band, only time (6 mm bead: 25.7 s and 3.6 GB
        // through level 2, against 5.8 s and 1.5 GB for level 0). The caller says so.
        return Ok((in_band, warnings, coarsened));
    }
    let base = if fine.layered {
        Some(first.unwrap_or(LevelSize::Factor(1.0)))
    } else {
        Some(fine.cell_m).filter(|c| c.is_finite() && *c > 0.0).map(LevelSize::Cell)
    };
    let mut coarse = match solve_level(&wide, 1, base, COARSE_FACTOR, key, progress) {
        Ok(level) => level,
        Err(err) => {
            warnings.push(format!(
                "no error estimate: the coarser level (element sizes × {COARSE_FACTOR}) failed: {err}"
            ));
            return Ok((trim(&fine.bank, request, None).0, warnings, coarsened));
        }
    };
    // Wall time of the levels solved so far (the time budget's clock).
    let mut spent = fine.seconds + coarse.seconds;
    let parts = |level: &Level| level.bank.info.rigid_modes_removed;
    if parts(&coarse) != parts(&fine) {
        // Another object (see the module docs): a milder coarsening, if it keeps the parts.
        match solve_level(&wide, 1, base, MILD_COARSE_FACTOR, key, progress) {
            Ok(mild) => {
                spent += mild.seconds;
                match mild_outcome(parts(&fine), Ok(parts(&mild))) {
                    None => coarse = mild,
                    Some(warning) => warnings.push(warning),
                }
            }
            Err(err) => warnings.extend(mild_outcome(parts(&fine), Err(err.to_string()))),
        }
    }
    let prescribed = request.surface.cell.is_some();
    for refinement in 0.. {
        let est = estimate(&fine.bank, &coarse.bank, fine.dofs, coarse.dofs);
        let (mut bank, kept) = trim(&fine.bank, request, Some(&est));
        bank.info.error_estimate_method = est.method(fine.dofs, coarse.dofs);
        let worst = kept.worst_of_first(target.modes);
        if worst.is_some_and(|w| w <= target.target_pct) {
            return Ok((bank, warnings, coarsened));
        }
        let reached = describe_worst(target, &kept, &bank.frequencies_hz);
        // The size that would reach the target by the estimate's own model.
        let wanted = worst.map_or(MAX_STEP, |w| 0.9 * (target.target_pct / w).powf(1.0 / ASSUMED_ORDER));
        let step = wanted.clamp(MIN_STEP, MAX_STEP);
        // The cell factor to advise: none for a mode without an estimate, about which the
        // model says nothing.
        let advised = worst.map(|_| wanted.min(MAX_STEP));
        let guard = request.memory_limit_bytes.or_else(modal_eigen::default_memory_limit);
        let advice =
            |f: f64| cell_advice(fine.cell_m * f, fine.memory as f64 * f.powi(-4), guard, target.target_pct);
        if prescribed {
            let cell = request.surface.cell.unwrap_or_default();
            let advice = advised.map_or(String::new(), |f| format!("; {}", advice(f)));
            warnings.push(format!("{reached} at the given --cell {cell:.4e} m{advice}"));
            return Ok((bank, warnings, coarsened));
        }
        let next = NextLevel { memory: fine.memory, seconds: fine.seconds, spent, step };
        if let Some(stop) = next.refused(refinement, guard) {
            let cell = fine.cell_m * step;
            let why = match stop {
                Stop::Memory { predicted, guard, late_s } => format!(
                    "the next finer level (cell {cell:.2e} m) would need ≈ {:.1} GB, above the memory guard of {:.1} GB{}",
                    predicted / 1e9,
                    guard as f64 / 1e9,
                    late_s.map_or(String::new(), |s| format!(
                        ", and ≈ {s:.0} s more, past the time budget of {TIME_BUDGET_S:.0} s ({spent:.0} s spent)"
                    ))
                ),
                Stop::Time { predicted_s } => format!(
                    "the next finer level (cell {cell:.2e} m) would take ≈ {predicted_s:.0} s more, beyond the \
                     time budget of {TIME_BUDGET_S:.0} s{}",
                    advised.map_or(String::new(), |f| format!(" ({})", advice(f)))
                ),
                Stop::Refinements => format!("stopped after {MAX_REFINEMENTS} refinements"),
            };
            warnings.push(format!("{reached} ({} DOF): {why}", fine.dofs));
            return Ok((bank, warnings, coarsened));
        }
        match solve_level(&wide, refinement + 2, base, fine.size_factor * step, key, progress) {
            Ok(mut finer) => {
                spent += finer.seconds;
                warnings.append(&mut finer.warnings);
                coarse = std::mem::replace(&mut fine, finer);
            }
            Err(
                err @ (PrecomputeError::Eigen(_)
                | PrecomputeError::Tetra(_)
                | PrecomputeError::Memory { .. }
                | PrecomputeError::Fem(modal_fem::FemError::TooLarge { .. })),
            ) => {
                warnings.push(format!(
                    "{reached} ({} DOF): the next finer level (cell {:.2e} m) was refused: {err}",
                    fine.dofs,
                    fine.cell_m * step
                ));
                return Ok((bank, warnings, coarsened));
            }
            Err(err) => return Err(err),
        }
    }
    unreachable!("the loop returns")
}

/// Whether the milder coarse level replaces a coarse level that changed the part count:
/// `None` when it was solved (`mild_parts` Ok) with the fine level's `fine_parts`, else
/// the warning that the estimate compares different objects (the milder level also
/// changed the parts, or failed: the reason is said either way, never dropped).
fn mild_outcome(fine_parts: usize, mild_parts: Result<usize, String>) -> Option<String> {
    let why = match mild_parts {
        Ok(parts) if parts == fine_parts => return None,
        Ok(_) => format!("element sizes × {COARSE_FACTOR} and × {MILD_COARSE_FACTOR:.2} both split or join parts of the mesh"),
        Err(err) => format!(
            "element sizes × {COARSE_FACTOR} split or join parts of the mesh, and the milder × \
             {MILD_COARSE_FACTOR:.2} failed: {err}"
        ),
    };
    Some(format!(
        "the coarser levels of the error estimate do not keep the object ({why}): the estimate compares \
         different objects and is only a rough bound"
    ))
}

/// Why a refinement is not started.
#[derive(Clone, Debug, PartialEq)]
enum Stop {
    /// [`MAX_REFINEMENTS`] reached.
    Refinements,
    /// Predicted solver memory [bytes] above the guard; with the predicted
    /// wall time [s] when that is past [`TIME_BUDGET_S`] too (more memory alone
    /// would not let the level run).
    Memory { predicted: f64, guard: u64, late_s: Option<f64> },
    /// Predicted wall time [s] of the next level would pass [`TIME_BUDGET_S`].
    Time { predicted_s: f64 },
}

/// What is known before the next, finer level: the last level's solver memory [bytes]
/// and wall time [s], the time spent on all levels so far [s], and the size step.
struct NextLevel {
    memory: u64,
    seconds: f64,
    spent: f64,
    step: f64,
}

impl NextLevel {
    /// Why refinement number `refinement` (0-based) is not started, if it is not: memory
    /// `m · (1/step)⁴` above `guard`, or `spent + t · (1/step)⁶` beyond [`TIME_BUDGET_S`]
    /// (see the module docs); memory first, it is the harder limit.
    fn refused(&self, refinement: usize, guard: Option<u64>) -> Option<Stop> {
        let predicted = self.memory as f64 * (1.0 / self.step).powi(4);
        let predicted_s = self.seconds * (1.0 / self.step).powi(TIME_EXPONENT);
        match guard {
            Some(guard) if predicted > guard as f64 => {
                let late_s = (self.spent + predicted_s > TIME_BUDGET_S).then_some(predicted_s);
                Some(Stop::Memory { predicted, guard, late_s })
            }
            _ if self.spent + predicted_s > TIME_BUDGET_S => Some(Stop::Time { predicted_s }),
            _ if refinement == MAX_REFINEMENTS => Some(Stop::Refinements),
            _ => None,
        }
    }
}

/// The `--cell` the estimate's model says would reach `target_pct`, and
/// whether this machine could solve it: its solver memory predicted as the
/// levels' own, `memory · (s/s')⁴` (`predicted_bytes`), against `guard`. A
/// scanned bunny's 142 % on its ears advised `--cell 4.04e-4 m`, ≈ 10⁸ DOF,
/// as if it were a step away.
fn cell_advice(cell_m: f64, predicted_bytes: f64, guard: Option<u64>, target_pct: f64) -> String {
    match guard {
        Some(guard) if predicted_bytes > guard as f64 => format!(
            "reaching {target_pct} % would take about --cell {cell_m:.2e} m and ≈ {:.0} GB (this level's memory \
             × (cell ratio)⁴), beyond the memory guard of {:.1} GB",
            predicted_bytes / 1e9,
            guard as f64 / 1e9
        ),
        _ => format!("about --cell {cell_m:.2e} m would reach {target_pct} %"),
    }
}

/// What the estimate reached, for the warning: the worst estimate of the lowest modes, or
/// which of them (number and frequency `hz`) have no estimate.
fn describe_worst(target: &AccuracyTarget, kept: &LevelEstimate, hz: &[f64]) -> String {
    if let Some(w) = kept.worst_of_first(target.modes) {
        return format!(
            "estimated error of the lowest {} modes up to {w:.2} % (target {} %)",
            target.modes, target.target_pct
        );
    }
    let unmatched: Vec<String> = kept
        .error_pct
        .iter()
        .zip(hz)
        .take(target.modes)
        .enumerate()
        .filter(|(_, (e, _))| e.is_none())
        // Numbered as `modal info` and `--mode` number them, from 0.
        .map(|(i, (_, f))| format!("{i} ({f:.0} Hz)"))
        .collect();
    if unmatched.is_empty() {
        return format!(
            "the lowest {} modes have no error estimate (target {} %)",
            target.modes, target.target_pct
        );
    }
    // A mode the coarser level does not have lives in a feature that level cannot hold:
    // the corpus bell's crown hangs on a 0.08 mm neck, and its two crown modes come out
    // 13–17 % stiff at the defaults (BENCHMARKS.md, "The corpus bell's crown").
    format!(
        "mode(s) {} of the lowest {} have no mode like them on the coarser level, so their error is unknown \
         (target {} %): a feature finer than the cells (a neck, a thin flap) may carry them, and a finer cell \
         is no promise",
        unmatched.join(", "),
        target.modes,
        target.target_pct
    )
}

/// The modes of `bank` inside the request's band, at most `max_modes`, with their
/// estimates stored in the bank's `info`; and the estimate cut to the same modes.
fn trim(bank: &ModeBank, request: &Request, est: Option<&LevelEstimate>) -> (ModeBank, LevelEstimate) {
    let keep: Vec<usize> = (0..bank.mode_count())
        .filter(|&i| (request.min_freq_hz..=request.max_freq_hz).contains(&bank.frequencies_hz[i]))
        .take(request.max_modes)
        .collect();
    let s3 = 3 * bank.surface_node_count();
    let pick = |v: &[f64]| keep.iter().map(|&i| v[i]).collect::<Vec<f64>>();
    let mut out = bank.clone();
    out.frequencies_hz = pick(&bank.frequencies_hz);
    out.damping_ratios = pick(&bank.damping_ratios);
    out.decay_rates = pick(&bank.decay_rates);
    out.residuals = pick(&bank.residuals);
    out.shapes = keep.iter().flat_map(|&i| bank.shapes[i * s3..(i + 1) * s3].iter().copied()).collect();
    let kept = match est {
        Some(e) => LevelEstimate {
            error_pct: keep.iter().map(|&i| e.error_pct[i]).collect(),
            matched: keep.iter().map(|&i| e.matched[i]).collect(),
            mac: keep.iter().map(|&i| e.mac[i]).collect(),
            ratio: e.ratio,
        },
        None => LevelEstimate { error_pct: Vec::new(), matched: Vec::new(), mac: Vec::new(), ratio: 0.0 },
    };
    if est.is_some() {
        out.info.error_estimate_pct = kept.error_pct.clone();
    }
    (out, kept)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fit_for_memory_is_refused_when_it_falls_apart_or_loses_the_volume() {
        let fit = Some(LevelSize::Factor(2.42));
        // Whole, or at the requested sizes: solved.
        assert_eq!(broken_fit(fit, 1, Some(1), Some(0.98)), None);
        assert_eq!(broken_fit(None, 20, Some(1), Some(0.09)), None);
        assert_eq!(broken_fit(Some(LevelSize::Cell(0.01)), 20, Some(1), Some(0.09)), None);
        // A tet mesh (no surface to compare with) that keeps its parts.
        assert_eq!(broken_fit(fit, 2, None, None), None);
        let apart = broken_fit(fit, 2, Some(1), Some(0.98)).expect("two loose pieces");
        assert!(apart.contains("falls apart into 2 parts (the surface is 1 body)"), "{apart}");
        // The scanned bust: its non-manifold surface counts 20+ bodies, but 9 % of it is left.
        let fragment = broken_fit(fit, 20, Some(25), Some(0.09)).expect("a fragment");
        assert!(
            fragment.contains("holds 9 % of the volume") && fragment.contains("in 20 parts"),
            "{fragment}"
        );
        assert!(fragment.contains("× 2.42"), "{fragment}");
        assert_eq!(broken_fit(fit, 1, Some(1), Some(FIT_VOLUME_KEPT)), None);
    }

    #[test]
    fn a_milder_coarse_level_replaces_only_when_it_keeps_the_parts_and_a_failure_is_said() {
        assert_eq!(mild_outcome(2, Ok(2)), None);
        let joined = mild_outcome(2, Ok(1)).expect("parts changed again: a warning");
        assert!(joined.contains("both split or join") && joined.contains("rough bound"), "{joined}");
        let failed = mild_outcome(2, Err("the mesher refused".into())).expect("a failure: a warning");
        assert!(failed.contains("failed: the mesher refused") && failed.contains("rough bound"), "{failed}");
    }

    #[test]
    fn a_cell_beyond_the_memory_guard_is_advised_as_such() {
        let gb = 1e9 as u64;
        assert_eq!(cell_advice(2e-3, 3e9, Some(18 * gb), 1.0), "about --cell 2.00e-3 m would reach 1 %");
        assert_eq!(cell_advice(2e-3, 3e12, None, 1.0), "about --cell 2.00e-3 m would reach 1 %");
        let far = cell_advice(4.04e-4, 6.9e12, Some(18 * gb), 1.0);
        assert!(far.starts_with("reaching 1 % would take about --cell 4.04e-4 m and ≈ 6900 GB"), "{far}");
        assert!(far.contains("beyond the memory guard of 18.0 GB"), "{far}");
    }

    #[test]
    fn a_mode_without_an_estimate_is_named_and_given_no_cell_promise() {
        let target = AccuracyTarget { target_pct: 1.0, modes: 3 };
        let kept = LevelEstimate {
            error_pct: vec![Some(0.2), None, Some(0.3), None],
            matched: vec![Some(0), None, Some(1), None],
            mac: vec![1.0, 0.0, 1.0, 0.0],
            ratio: 1.5,
        };
        let hz = [637.1, 1484.4, 1685.3, 3075.8];
        let said = describe_worst(&target, &kept, &hz);
        assert!(said.starts_with("mode(s) 1 (1484 Hz) of the lowest 3"), "{said}");
        assert!(!said.contains("3076"), "mode 4 is beyond the target's modes: {said}");
        let all = LevelEstimate { error_pct: vec![Some(0.2), Some(0.3), Some(0.1), None], ..kept };
        let worst = describe_worst(&target, &all, &hz);
        assert!(worst.contains("up to 0.30 %"), "{worst}");
    }

    #[test]
    fn refinement_stops_for_memory_then_time_then_count() {
        // 1 GB and 2 s at step 0.5: the next level needs 16 GB and 128 s.
        let next = NextLevel { memory: 1_000_000_000, seconds: 2.0, spent: 3.0, step: 0.5 };
        assert_eq!(
            next.refused(0, Some(8_000_000_000)),
            Some(Stop::Memory { predicted: 16e9, guard: 8_000_000_000, late_s: Some(128.0) })
        );
        // Memory alone: said alone (a scanned dragon's level after 90 s was told only of
        // its 34 GB, though the time budget was spent too).
        let quick = NextLevel { seconds: 0.1, ..next };
        assert_eq!(
            quick.refused(0, Some(8_000_000_000)),
            Some(Stop::Memory { predicted: 16e9, guard: 8_000_000_000, late_s: None })
        );
        assert_eq!(next.refused(0, Some(32_000_000_000)), Some(Stop::Time { predicted_s: 128.0 }));
        // Step 0.8: 2.44 GB and 7.6 s, 10.6 s with the 3 s spent: inside both limits.
        let cheap = NextLevel { step: 0.8, ..next };
        assert_eq!(cheap.refused(0, Some(8_000_000_000)), None);
        assert_eq!(cheap.refused(0, None), None);
        assert_eq!(cheap.refused(MAX_REFINEMENTS, None), Some(Stop::Refinements));
        // The time spent counts: 55 s already spent leaves no room for 7.6 s more.
        let late = NextLevel { spent: 55.0, ..cheap };
        assert!(matches!(late.refused(0, None), Some(Stop::Time { .. })));
    }

    #[test]
    fn every_level_meshes_a_plate_for_the_requested_modes_not_the_widened_count() {
        let mut request =
            Request::new(MeshSource::File("plate.obj".into()), modal_fem::Material::preset("steel").unwrap());
        request.max_modes = 200;
        let wide = widened(&request);
        assert!(wide.max_modes > 200);
        assert_eq!(wide.surface_meshing().tet_options().resolved_modes, 200);
        assert_eq!(request.surface_meshing().tet_options().resolved_modes, 200);
        // The default 64 modes: the mesher's default options, so the default mesh and key.
        let default =
            Request::new(MeshSource::File("plate.obj".into()), modal_fem::Material::preset("steel").unwrap());
        assert_eq!(widened(&default).surface_meshing().tet_options(), modal_tetra::TetOptions::default());
    }
}
