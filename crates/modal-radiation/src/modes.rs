//! Radiation of a bank's modes: each mode vibrating harmonically at its
//! undamped frequency with unit modal velocity amplitude.
//!
//! Mass-normalized shapes `φ_i` [1/√kg] and modal velocity amplitude 1
//! give the surface velocity `φ_i(x)` [m/s]; a panel's normal velocity is
//! the exact mean over the panel of its surface triangle's (quadratic or
//! linear) interpolant of `φ · n` ([`crate::velocity`]; a quadratic surface
//! triangle is four panels), `n` the smooth-surface normal at each node,
//! fitted to the local surface ([`crate::normals`]). Modes whose
//! frequencies lie within a relative `group_tolerance` of each other
//! (degenerate pairs and multiplets) are solved at their geometric-mean
//! frequency with one factorization: the transfer varies smoothly with `k`
//! (no resonances in the exterior problem), by about `(l+1)·δf/f` in power
//! for a degree-`l` multipole, i.e. < 0.04 dB at the default 10⁻³.

use std::sync::Arc;
use std::time::Instant;

use faer::c64;
use modal_bank::ModeBank;

use crate::bem::{solve_on, Air, Discretization, Formulation, SolverPath, SurfaceField};
use crate::cluster::{Adjacency, Clusters};
use crate::error::RadiationError;
use crate::geometry::{dot, BoundaryMesh};
use crate::multipole::{fit, Multipole, DEFAULT_TOLERANCE};
use crate::near::NearField;
use crate::normals::{fit_normals, SurfaceNormals};
use crate::velocity::{panel_sources, triangle_source, velocity_of, PanelSource};

/// Options of a bank radiation run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadiationOptions {
    /// The air.
    pub air: Air,
    /// Modes closer than this relative frequency share one solve.
    pub group_tolerance: f64,
    /// Relative RMS error of the multipole truncation at twice the body radius.
    pub multipole_tolerance: f64,
    /// Boundary integral equation: the default chooses per frequency
    /// ([`Formulation::Automatic`]); the others are for studies.
    pub formulation: Formulation,
    /// Frequency-adaptive resolution: clustered pressure unknowns
    /// ([`crate::cluster`]) and, for a quadratic bank, its corner triangles
    /// when the wavelength allows ([`COARSE_MAX_KH`]). Off: one unknown per
    /// panel of the four-panel split.
    pub adaptive_resolution: bool,
    /// `κ`: cluster diameter `κ / max(k, k_s)` (smaller is finer and dearer).
    pub cluster_kh: f64,
    /// Most bytes one solve's matrix and near field may hold
    /// ([`crate::bem::Discretization::memory_limit_bytes`]); `None`: no
    /// limit. The default solves stay below 1 GB (at most
    /// [`MAX_DENSE_PANELS`] unknowns); a full-resolution one of 64 000
    /// panels may need many GB at high frequency.
    pub memory_limit_bytes: Option<u64>,
    /// With `adaptive_resolution` off: rounds of splitting the panels with
    /// a corner on a crease (a thin wall's rim, a bar's edges) in four
    /// ([`crate::refine`]). 0: none. On a free steel disc 20 cm × 2 mm the
    /// 1 629 Hz mode moved by 0.43 dB median, 1.06 dB max after two rounds,
    /// and by 0.09 / 0.26 dB from one round to two (BENCHMARKS.md, "The
    /// thin disc again").
    pub crease_refinement: usize,
}

impl Default for RadiationOptions {
    fn default() -> Self {
        RadiationOptions {
            air: Air::default(),
            group_tolerance: 1e-3,
            multipole_tolerance: DEFAULT_TOLERANCE,
            formulation: Formulation::Automatic,
            adaptive_resolution: true,
            cluster_kh: DEFAULT_CLUSTER_KH,
            memory_limit_bytes: None,
            crease_refinement: 0,
        }
    }
}

/// The radiation of one mode.
#[derive(Clone, Debug)]
pub struct ModeRadiation {
    /// Mode index in the bank.
    pub mode: usize,
    /// The mode's undamped frequency [Hz].
    pub frequency_hz: f64,
    /// Surface pressure and normal velocity (solved at the group frequency).
    pub surface: SurfaceField,
    /// Radiated power at unit modal velocity amplitude [W], from the far
    /// field (the multipole coefficients), which stays accurate at low `ka`
    /// where the surface integral `½Re∫p v*` is a small difference of
    /// large reactive terms.
    pub power_w: f64,
    /// Radiation efficiency `P / (½ρ₀c∫|v_n|²dS)`.
    pub efficiency: f64,
    /// Far-field representation about the centre of mass.
    pub multipole: Multipole,
    /// The panels `surface` lives on (the bank's fine or coarse panels).
    pub mesh: Arc<BoundaryMesh>,
}

impl ModeRadiation {
    /// Pressure at `x` in the air (representation formula on the mode's
    /// panels) [Pa]; errors inside the body.
    pub fn pressure_at(&self, x: [f64; 3]) -> Result<c64, RadiationError> {
        self.surface.pressure_at(&self.mesh, x)
    }

    /// [`ModeRadiation::pressure_at`] at each of `points`, in parallel
    /// ([`SurfaceField::pressures_at`]).
    pub fn pressures_at(&self, points: &[[f64; 3]]) -> Result<Vec<c64>, RadiationError> {
        self.surface.pressures_at(&self.mesh, points)
    }
}

/// Progress of a run, for the caller to show.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// Groups solved so far.
    pub groups_done: usize,
    /// Groups in all.
    pub groups: usize,
    /// Modes in the group just solved.
    pub modes: Vec<usize>,
    /// Its frequency [Hz].
    pub frequency_hz: f64,
    /// Panels of the solve (geometry and velocity; the corner triangles of
    /// a quadratic bank at low frequency, see [`COARSE_MAX_KH`]).
    pub panels: usize,
    /// Pressure unknowns (clusters of panels, see [`crate::cluster`]).
    pub unknowns: usize,
    /// Effective wavenumber `max(k, k_s)` that sized the clusters [1/m].
    pub k_eff: f64,
    /// The pressure unknowns are too coarse for this frequency: `k·d` above
    /// [`UNDER_RESOLVED_KH`] for the cluster diameter `d` and the panels, or
    /// the clusters had to grow to fit [`MAX_DENSE_PANELS`]. Expect larger
    /// errors; mesh finer for such modes.
    pub under_resolved: bool,
    /// The cluster size `κ` (`k_eff` × diameter) the clusters had to grow
    /// to, past the one asked for, to fit [`MAX_DENSE_PANELS`] unknowns
    /// (`None`: they did not). κ = 0.5 was 0.19 / 0.71 dB (median / max) and
    /// κ = 1 0.63 / 1.0 dB from one unknown per panel on the demo bar
    /// (BENCHMARKS.md, "Error against cost").
    pub grown_kh: Option<f64>,
    /// Seconds spent in the solve (near field when first needed, assembly,
    /// GMRES or LU).
    pub solve_s: f64,
    /// Of `solve_s`, seconds spent integrating the static near field of the
    /// panel level ([`crate::near`]): once per level, 0 when reused.
    pub near_s: f64,
    /// Memory held by that near field [bytes].
    pub near_bytes: usize,
    /// Seconds spent in the multipole fit.
    pub fit_s: f64,
    /// How the system was solved (a dense LU after GMRES failed is slow).
    pub solver: SolverPath,
    /// The equation solved ([`Formulation::resolved`]).
    pub formulation: Formulation,
}

impl std::fmt::Display for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "radiation {}/{}: mode(s) {:?} at {:.1} Hz, {} unknowns on {} panels{}, solve {:.2} s{} [{}; {}], fit {:.2} s",
            self.groups_done,
            self.groups,
            self.modes,
            self.frequency_hz,
            self.unknowns,
            self.panels,
            match (self.grown_kh, self.under_resolved) {
                (Some(kh), _) => format!(
                    " (under-resolved: clusters grown to κ = {kh:.2} to fit {MAX_DENSE_PANELS} unknowns, expect larger errors)"
                ),
                (None, true) => " (under-resolved: expect larger errors)".to_string(),
                (None, false) => String::new(),
            },
            self.solve_s,
            if self.near_s > 0.0 {
                format!(" (near field {:.2} s, {:.0} MB)", self.near_s, self.near_bytes as f64 / 1e6)
            } else {
                String::new()
            },
            self.solver,
            self.formulation,
            self.fit_s
        )
    }
}

/// The bank's surface as flat panels (quadratic triangles split in four).
pub fn boundary_mesh(bank: &ModeBank) -> Result<BoundaryMesh, RadiationError> {
    let s = &bank.surface;
    match &s.triangle_edge_nodes {
        Some(edges) => BoundaryMesh::quadratic(s.positions.clone(), &s.triangles, edges),
        None => BoundaryMesh::new(s.positions.clone(), &s.triangles),
    }
}

/// The corner triangles of a quadratic bank surface (the coarse panel
/// level of low-frequency solves, on the same vertices as
/// [`boundary_mesh`]); `None` for a linear surface, which has one level.
pub fn corner_mesh(bank: &ModeBank) -> Result<Option<BoundaryMesh>, RadiationError> {
    let s = &bank.surface;
    s.triangle_edge_nodes.as_ref().map(|_| BoundaryMesh::new(s.positions.clone(), &s.triangles)).transpose()
}

/// Panels whose normal is within this angle of a node's smooth-surface
/// normal use that normal at that corner; across creases (a bar's edges)
/// the panel's own normal is used. Also the angle at which
/// [`crate::normals`] splits the triangles around a node into smooth sectors.
pub const CREASE_ANGLE_DEG: f64 = 25.0;

/// Smooth-surface normals of the bank's surface, fitted to the local
/// surface and never across a crease ([`crate::normals`]).
pub fn surface_normals(bank: &ModeBank) -> SurfaceNormals {
    let s = &bank.surface;
    fit_normals(&s.positions, &s.triangles, s.triangle_edge_nodes.as_deref(), CREASE_ANGLE_DEG)
}

/// Local node indices (corners 0–2, mid-edge nodes 3–5) of the corners of
/// the four panels a quadratic triangle is split into
/// ([`BoundaryMesh::quadratic`]).
const SPLIT_CORNERS: [[usize; 3]; 4] = [[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]];

/// Normal of each panel corner: the node's smooth-surface normal
/// ([`surface_normals`], from the node's sector that holds the panel's
/// triangle) where it is within [`CREASE_ANGLE_DEG`] of the panel's normal,
/// the panel's own normal otherwise. `mesh` is the bank's
/// [`boundary_mesh`]; on any other panel mesh over the bank's nodes each
/// node's first-sector normal is used.
pub fn corner_normals(bank: &ModeBank, mesh: &BoundaryMesh) -> Vec<[[f64; 3]; 3]> {
    corner_normals_of(bank, mesh, &surface_normals(bank))
}

/// [`corner_normals`] from the bank's [`surface_normals`] `normals`.
pub(crate) fn corner_normals_of(
    bank: &ModeBank,
    mesh: &BoundaryMesh,
    normals: &SurfaceNormals,
) -> Vec<[[f64; 3]; 3]> {
    let split = split_of(bank, mesh);
    mesh.panels
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let smooth: [[f64; 3]; 3] = match split {
                Some(split) => split[i % split.len()].map(|k| normals.per_triangle[i / split.len()][k]),
                None => p.corners.map(|c| normals.per_node.get(c).copied().unwrap_or([0.0; 3])),
            };
            smooth.map(|n| smooth_or_panel(n, p.normal))
        })
        .collect()
}

/// How `mesh`'s panels lie on the bank's triangles: `Some(split)` when
/// `mesh` is the bank's [`boundary_mesh`], whose panel `i` has the local
/// nodes `split[i % split.len()]` of triangle `i / split.len()` (see
/// [`triangle_node`]); `None` for any other panel mesh.
pub(crate) fn split_of(bank: &ModeBank, mesh: &BoundaryMesh) -> Option<&'static [[usize; 3]]> {
    let s = &bank.surface;
    let split: &'static [[usize; 3]] = match &s.triangle_edge_nodes {
        Some(_) => &SPLIT_CORNERS,
        None => &[[0, 1, 2]],
    };
    let matches = mesh.panels.len() == split.len() * s.triangles.len()
        && mesh.panels.iter().enumerate().all(|(i, p)| {
            let local = split[i % split.len()];
            (0..3).all(|j| p.corners[j] == triangle_node(bank, i / split.len(), local[j]))
        });
    matches.then_some(split)
}

/// Surface node `k` of bank triangle `t`: corners 0–2, then (quadratic
/// banks) the mid-edge nodes of edges 01, 12, 20.
pub(crate) fn triangle_node(bank: &ModeBank, t: usize, k: usize) -> usize {
    match &bank.surface.triangle_edge_nodes {
        Some(e) if k >= 3 => e[t][k - 3],
        _ => bank.surface.triangles[t][k],
    }
}

/// The node's normal where it is within [`CREASE_ANGLE_DEG`] of the panel
/// normal, else the panel normal.
pub(crate) fn smooth_or_panel(node: [f64; 3], panel: [f64; 3]) -> [f64; 3] {
    let cos_crease = CREASE_ANGLE_DEG.to_radians().cos();
    if node != [0.0; 3] && dot(node, panel) >= cos_crease {
        node
    } else {
        panel
    }
}

/// Normal velocity of mode `mode` on each panel at unit modal velocity
/// [m/s], as the solver takes it: on the bank's [`boundary_mesh`], the
/// exact mean over the panel of its triangle's interpolant of `φ · n`
/// ([`crate::velocity`]), on any other panel mesh over the bank's nodes
/// the mean over its corners, with the normals of [`corner_normals`] (so
/// a purely tangential motion of a curved surface, like a sphere's
/// torsional modes, gives ≈ 0 rather than the facets' tilt).
pub fn normal_velocity(
    bank: &ModeBank,
    mesh: &BoundaryMesh,
    mode: usize,
) -> Result<Vec<c64>, RadiationError> {
    if mesh.vertices.len() != bank.surface_node_count() {
        return Err(RadiationError::Bank("the panel mesh is not the bank's surface".into()));
    }
    let sources = panel_sources(bank, mesh, &surface_normals(bank));
    let weights: Vec<[f64; 6]> = sources.iter().map(PanelSource::weights).collect();
    velocity_of(bank, &sources, &weights, mode)
}

/// Lowest damped frequency treated as audible [Hz].
pub const AUDIBLE_MIN_HZ: f64 = 20.0;

/// Whether mode `mode` of `bank` can be heard below `max_hz`: its damped
/// frequency at least [`AUDIBLE_MIN_HZ`] and its frequency at most
/// `max_hz` (the modes `modal radiation` and a batch's stored transfer
/// solve).
pub fn is_audible(bank: &ModeBank, mode: usize, max_hz: f64) -> bool {
    bank.damped_frequency_hz(mode) >= AUDIBLE_MIN_HZ && bank.frequencies_hz[mode] <= max_hz
}

/// Groups of mode indices (ascending frequency) within `tol` of the group's first.
pub fn frequency_groups(bank: &ModeBank, modes: &[usize], tol: f64) -> Vec<Vec<usize>> {
    let mut sorted = modes.to_vec();
    sorted.sort_by(|&a, &b| bank.frequencies_hz[a].total_cmp(&bank.frequencies_hz[b]).then(a.cmp(&b)));
    sorted.dedup();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for m in sorted {
        let f = bank.frequencies_hz[m];
        match groups.last_mut() {
            Some(g) if f <= bank.frequencies_hz[g[0]] * (1.0 + tol) => g.push(m),
            _ => groups.push(vec![m]),
        }
    }
    groups
}

/// Solves the radiation of `modes` of `bank` (any order; results in
/// ascending frequency), reporting each solved group to `progress`.
pub fn radiate_modes(
    bank: &ModeBank,
    modes: &[usize],
    opts: &RadiationOptions,
    progress: &mut dyn FnMut(&Progress),
) -> Result<Vec<ModeRadiation>, RadiationError> {
    opts.air.validate()?;
    let mesh = boundary_mesh(bank)?;
    radiate_modes_on(bank, &mesh, modes, opts, progress)
}

/// Largest `k·h` (wavenumber times the longest corner-triangle edge) at which a quadratic bank's velocity and geometry are taken on its
/// corner triangles (velocity: the exact mean of the quadratic field) instead
/// of the four flat panels per triangle: ≥ 12 panels per wavelength.
/// Measured on the FEM sphere bank (tests/radiation_cli.rs) within the
/// 0.5 dB acceptance.
pub const COARSE_MAX_KH: f64 = 0.5;

/// `k·h` above which the pressure unknowns are flagged under-resolved
/// (fewer than ~6 per wavelength).
pub const UNDER_RESOLVED_KH: f64 = 1.0;

/// Default `κ`: pressure clusters of diameter `κ / max(k, k_s)`
/// ([`crate::cluster`]), ≈ 20 unknowns per wavelength.
///
/// Set by the cross-check's 3 dB at points down to 40 dB below a mode's
/// loudest (docs/radiation.md): there the far field is what is left of the
/// whole surface's contributions cancelling, so its error must stay near
/// −45 dB of the loudest point. Which directions are quiet is not known
/// before the solve, so the size is one for the whole surface, not finer
/// only where the far field is a residual: the failing modes were not the
/// subsonic ones (a thin bowl's supersonic modes, `k > k_s`, radiation
/// efficiency 0.3–1.5, failed at κ = 0.5; the bar's subsonic ones, 0.001,
/// passed). Measured on the bowls with the dense-size cap lifted: max
/// 4.0 / 4.2 dB at κ = 0.5 / 0.4, 1.7–1.9 dB at 0.35 / 0.3 / 0.25; 0.3 is
/// the middle of the passing range (the error at a quiet point also
/// depends on where the cluster boundaries fall).
pub const DEFAULT_CLUSTER_KH: f64 = 0.3;

/// Largest cluster diameter as a fraction of the body's radius about the
/// centre of mass (the pressure must still follow the body's shape at low
/// frequency).
pub const MAX_CLUSTER_RADIUS_FRACTION: f64 = 0.5;

/// Most pressure unknowns of one solve: the solver's dense limit
/// ([`crate::bem::MAX_DENSE_UNKNOWNS`], its fallback when GMRES on the
/// compressed matrix does not converge), so every solve keeps that fallback.
/// Above it the clusters are grown until they fit (flagged in
/// [`Progress::under_resolved`]).
pub const MAX_DENSE_PANELS: usize = crate::bem::MAX_DENSE_UNKNOWNS;

/// Most panels of a solve with one unknown per panel (`adaptive_resolution`
/// off, the CLI's `--full-resolution`): asked for, it is solved compressed
/// above [`MAX_DENSE_PANELS`], without the dense fallback (a GMRES that does
/// not converge there is an error, [`RadiationError::NotConverged`]). A thin
/// wall needs unknowns about a wall thickness wide: a free disc 20 cm × 2 mm
/// on its 31 360-panel split took 13–46 s a mode and 1.5 GB below 2 kHz; with
/// two rounds of [`RadiationOptions::crease_refinement`], 47 488 panels,
/// 65–96 s a mode and 2.3 GB at 1.6 kHz (BENCHMARKS.md, "The thin disc
/// again").
/// Larger solves are stopped by the memory guard as their assembly crosses it.
pub const MAX_FULL_RESOLUTION_PANELS: usize = 64_000;

/// One panel level of a bank: panels, their adjacency, their near field
/// (integrated when the level is first solved on), and how to get a mode's
/// normal velocity on them.
struct Level {
    mesh: Arc<BoundaryMesh>,
    adjacency: Adjacency,
    near: std::sync::OnceLock<NearField>,
    /// Longest panel edge [m].
    h: f64,
    /// [`crate::bem::interior_wavenumber_bound`] of the mesh [1/m]: where
    /// [`Formulation::Automatic`] changes equation.
    resonance_bound: f64,
    /// Per panel, where its velocity comes from ([`crate::velocity`]).
    sources: Vec<PanelSource>,
    /// Per panel, [`PanelSource::weights`].
    weights: Vec<[f64; 6]>,
}

impl Level {
    fn new(mesh: BoundaryMesh, sources: Vec<PanelSource>) -> Level {
        debug_assert_eq!(mesh.len(), sources.len());
        Level {
            h: mesh.panels.iter().map(|p| p.diameter).fold(0.0, f64::max),
            resonance_bound: crate::bem::interior_wavenumber_bound(&mesh),
            adjacency: Adjacency::new(&mesh),
            near: std::sync::OnceLock::new(),
            mesh: Arc::new(mesh),
            weights: sources.iter().map(PanelSource::weights).collect(),
            sources,
        }
    }

    /// Mode `mode`'s normal velocity on each panel: the exact mean over the
    /// panel of its triangle's interpolant of `φ·n` ([`crate::velocity`]).
    fn velocity(&self, bank: &ModeBank, mode: usize) -> Result<Vec<c64>, RadiationError> {
        velocity_of(bank, &self.sources, &self.weights, mode)
    }
}

/// The panel levels of a bank: fine (every surface node a panel corner)
/// and, for quadratic banks, coarse (the corner triangles, velocity from
/// the three mid-edge nodes: the exact mean of a quadratic field over the
/// triangle, since the corner shape functions integrate to zero).
struct Panels {
    fine: Level,
    coarse: Option<Level>,
    /// Each fine panel split in four at its edge midpoints (velocity: the
    /// exact mean of the triangle's interpolant over each quarter), when that still has at most
    /// [`MAX_DENSE_PANELS`] panels: small objects whose fine panels are
    /// too coarse for their top modes (`k·h > 1`) get one unknown per
    /// panel at half the size (see [`plan`]). `None` when the split does
    /// not fit or resolution is not adaptive; otherwise split by
    /// [`Panels::finer`] when a frequency group first needs it, so a run
    /// of low modes never splits.
    finer: Option<std::sync::OnceLock<Level>>,
    /// The fine level refined towards its creases
    /// ([`RadiationOptions::crease_refinement`] rounds), made on first use.
    refined: std::sync::OnceLock<Level>,
}

impl Panels {
    fn new(bank: &ModeBank, mesh: &BoundaryMesh, adaptive: bool) -> Result<Panels, RadiationError> {
        if mesh.vertices.len() != bank.surface_node_count() {
            return Err(RadiationError::Bank("the panel mesh is not the bank's surface".into()));
        }
        let smooth = surface_normals(bank);
        let sources = panel_sources(bank, mesh, &smooth);
        let corners = if adaptive { corner_mesh(bank)? } else { None };
        // The corner triangles: each a whole quadratic triangle, whose mean
        // is the mean of its mid-edge values.
        let coarse = corners.map(|m| {
            let sources = m
                .panels
                .iter()
                .zip(&smooth.per_triangle)
                .enumerate()
                .map(|(t, (p, n))| triangle_source(bank, t, n, p.normal, true))
                .collect();
            Level::new(m, sources)
        });
        Ok(Panels {
            fine: Level::new(mesh.clone(), sources),
            coarse,
            finer: (adaptive && 4 * mesh.len() <= MAX_DENSE_PANELS).then(std::sync::OnceLock::new),
            refined: std::sync::OnceLock::new(),
        })
    }

    /// The finer level, split on first use; `None` when it does not fit.
    fn finer(&self) -> Result<Option<&Level>, RadiationError> {
        let Some(cell) = &self.finer else { return Ok(None) };
        if let Some(level) = cell.get() {
            return Ok(Some(level));
        }
        let level = split_level(&self.fine.mesh, &self.fine.sources)?;
        Ok(Some(cell.get_or_init(|| level)))
    }

    /// The fine level with the panels at its creases split `rounds` times
    /// ([`crate::refine::refine_near_creases`]); `None` for 0 rounds.
    fn refined(&self, rounds: usize) -> Result<Option<&Level>, RadiationError> {
        if rounds == 0 {
            return Ok(None);
        }
        if let Some(level) = self.refined.get() {
            return Ok(Some(level));
        }
        let (mesh, sources) = crate::refine::refine_near_creases(
            &self.fine.mesh,
            &self.fine.sources,
            rounds,
            CREASE_ANGLE_DEG,
            PanelSource::quarters,
        )?;
        let level = Level::new(mesh, sources);
        Ok(Some(self.refined.get_or_init(|| level)))
    }
}

/// The [`Panels::finer`] level of `mesh` whose panels take their velocity
/// from `sources`: each panel `[a, b, c]` split at its edge midpoints
/// (shared between neighbours, so the surface stays closed) into
/// `[a, ab, ca]`, `[ab, b, bc]`, `[ca, bc, c]`, `[ab, bc, ca]`, each
/// quarter the exact mean of its triangle's interpolant over it
/// ([`PanelSource::quarters`]).
fn split_level(mesh: &BoundaryMesh, sources: &[PanelSource]) -> Result<Level, RadiationError> {
    let (mesh, sources) = crate::refine::split_panels(mesh, sources, |_| true, PanelSource::quarters)?;
    Ok(Level::new(mesh, sources))
}

/// How one frequency group was solved.
struct Plan<'a> {
    level: &'a Level,
    clusters: Clusters,
    under_resolved: bool,
    /// `κ` the clusters grew to past the one asked for, to fit
    /// [`MAX_DENSE_PANELS`] unknowns.
    grown_kh: Option<f64>,
    /// Effective wavenumber max(k, k_s) [1/m].
    k_eff: f64,
}

fn plan<'a>(
    panels: &'a Panels,
    k: f64,
    ks: f64,
    radius: f64,
    opts: &RadiationOptions,
) -> Result<Plan<'a>, RadiationError> {
    let k_eff = k.max(ks);
    let level = match &panels.coarse {
        Some(c) if k * c.h <= COARSE_MAX_KH => c,
        _ if k * panels.fine.h > UNDER_RESOLVED_KH => panels.finer()?.unwrap_or(&panels.fine),
        _ => &panels.fine,
    };
    if !opts.adaptive_resolution {
        let (max, rounds) = (MAX_FULL_RESOLUTION_PANELS, opts.crease_refinement);
        if level.mesh.len() > max {
            return Err(RadiationError::TooManyPanels { panels: level.mesh.len(), max });
        }
        let level = panels.refined(rounds)?.unwrap_or(level);
        if level.mesh.len() > max {
            return Err(RadiationError::TooManyRefinedPanels { panels: level.mesh.len(), max, rounds });
        }
        let clusters = Clusters::identity(level.mesh.len());
        let under_resolved = k * level.h > UNDER_RESOLVED_KH;
        return Ok(Plan { level, clusters, under_resolved, grown_kh: None, k_eff });
    }
    let wanted = (opts.cluster_kh / k_eff).min(MAX_CLUSTER_RADIUS_FRACTION * radius);
    let (clusters, diameter) =
        Clusters::fit(&level.mesh, &level.adjacency, wanted, 4.0 * radius, MAX_DENSE_PANELS).ok_or_else(
            || {
                let frequency_hz = k * opts.air.sound_speed_m_s / std::f64::consts::TAU;
                RadiationError::TooRuggedToCluster { frequency_hz, max: MAX_DENSE_PANELS }
            },
        )?;
    let grown_kh = (diameter > wanted).then_some(k_eff * diameter);
    let under_resolved = grown_kh.is_some()
        || k * diameter.max(level.h) > UNDER_RESOLVED_KH && k * level.h > UNDER_RESOLVED_KH;
    Ok(Plan { level, clusters, under_resolved, grown_kh, k_eff })
}

/// [`radiate_modes`] on a given panel mesh of the bank's surface.
pub fn radiate_modes_on(
    bank: &ModeBank,
    mesh: &BoundaryMesh,
    modes: &[usize],
    opts: &RadiationOptions,
    progress: &mut dyn FnMut(&Progress),
) -> Result<Vec<ModeRadiation>, RadiationError> {
    let centre = bank.mass.center_of_mass_m;
    let panels = Panels::new(bank, mesh, opts.adaptive_resolution)?;
    let radius = mesh.radius_about(centre);
    let mut surface_k = vec![0.0; bank.mode_count()];
    for &m in modes {
        let v = panels.fine.velocity(bank, m)?;
        if v.iter().all(|z| z.norm() == 0.0) {
            return Err(RadiationError::NoSurfaceVelocity { mode: m });
        }
        surface_k[m] = panels.fine.adjacency.surface_wavenumber(&panels.fine.mesh, &v);
    }
    let groups = frequency_groups(bank, modes, opts.group_tolerance);
    let mut out = Vec::with_capacity(modes.len());
    for (gi, group) in groups.iter().enumerate() {
        let (lo, hi) =
            (bank.frequencies_hz[group[0]], bank.frequencies_hz[*group.last().unwrap_or(&group[0])]);
        let f = (lo * hi).sqrt();
        let k = 2.0 * std::f64::consts::PI * f / opts.air.sound_speed_m_s;
        let ks = group.iter().map(|&m| surface_k[m]).fold(0.0, f64::max);
        let plan = plan(&panels, k, ks, radius, opts)?;
        let mesh = &plan.level.mesh;
        let fields = group.iter().map(|&m| plan.level.velocity(bank, m)).collect::<Result<Vec<_>, _>>()?;
        let t0 = Instant::now();
        let fresh = plan.level.near.get().is_none();
        let near = plan.level.near.get_or_init(|| NearField::new(mesh));
        let near_s = if fresh { t0.elapsed().as_secs_f64() } else { 0.0 };
        let disc = Discretization {
            mesh,
            near,
            clusters: &plan.clusters,
            aggregate: opts.adaptive_resolution,
            memory_limit_bytes: opts.memory_limit_bytes,
        };
        let formulation = opts.formulation.resolved_below(k, plan.level.resonance_bound);
        let (surfaces, solver) = solve_on(&disc, opts.air, f, &fields, formulation)?;
        let solve_s = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let multipoles = fit(mesh, &surfaces, centre, opts.multipole_tolerance);
        let fit_s = t1.elapsed().as_secs_f64();
        for ((&mode, surface), multipole) in group.iter().zip(surfaces).zip(multipoles) {
            let power_w = multipole.radiated_power(opts.air);
            out.push(ModeRadiation {
                mode,
                frequency_hz: bank.frequencies_hz[mode],
                power_w,
                efficiency: power_w / surface.velocity_power_scale(mesh),
                surface,
                multipole,
                mesh: Arc::clone(mesh),
            });
        }
        progress(&Progress {
            groups_done: gi + 1,
            groups: groups.len(),
            modes: group.clone(),
            frequency_hz: f,
            panels: mesh.len(),
            unknowns: plan.clusters.len(),
            k_eff: plan.k_eff,
            under_resolved: plan.under_resolved,
            grown_kh: plan.grown_kh,
            solve_s,
            near_s,
            near_bytes: near.bytes(),
            fit_s,
            solver,
            formulation,
        });
    }
    Ok(out)
}

/// The bank-storable table of `results` (see `modal_bank::RadiationTable`),
/// entries in ascending mode order.
pub fn to_table(results: &[ModeRadiation], opts: &RadiationOptions) -> Option<modal_bank::RadiationTable> {
    let first = results.first()?;
    let mut modes: Vec<modal_bank::ModeTransfer> = results
        .iter()
        .map(|r| modal_bank::ModeTransfer {
            mode: r.mode,
            wavenumber: r.multipole.wavenumber,
            order: r.multipole.order,
            coefficients: r.multipole.coefficients.iter().map(|c| [c.re, c.im]).collect(),
            power_w: r.power_w,
            efficiency: r.efficiency,
        })
        .collect();
    modes.sort_by_key(|m| m.mode);
    Some(modal_bank::RadiationTable {
        centre_m: first.multipole.centre,
        fit_radius_m: first.multipole.fit_radius,
        air_density_kg_m3: opts.air.density_kg_m3,
        sound_speed_m_s: opts.air.sound_speed_m_s,
        tolerance: opts.multipole_tolerance,
        modes,
    })
}

/// The modes a stored transfer up to `max_hz` covers: every
/// [`is_audible`] mode of `bank`, ascending.
pub fn audible_modes(bank: &ModeBank, max_hz: f64) -> Vec<usize> {
    (0..bank.mode_count()).filter(|&i| is_audible(bank, i, max_hz)).collect()
}

/// The transfer table of every audible mode of `bank` up to `max_hz`
/// ([`audible_modes`], [`radiate_modes`], [`to_table`]); `None` when no
/// mode is audible there.
pub fn transfer_table(
    bank: &ModeBank,
    max_hz: f64,
    opts: &RadiationOptions,
    progress: &mut dyn FnMut(&Progress),
) -> Result<Option<modal_bank::RadiationTable>, RadiationError> {
    let modes = audible_modes(bank, max_hz);
    if modes.is_empty() {
        return Ok(None);
    }
    Ok(to_table(&radiate_modes(bank, &modes, opts, progress)?, opts))
}

/// Whether `table` is what [`transfer_table`] of `bank` up to `max_hz`
/// with `opts` stores: the same modes, air and multipole tolerance (a
/// bank finished earlier need not be solved again).
pub fn is_transfer_table_of(
    table: &modal_bank::RadiationTable,
    bank: &ModeBank,
    max_hz: f64,
    opts: &RadiationOptions,
) -> bool {
    table.air_density_kg_m3 == opts.air.density_kg_m3
        && table.sound_speed_m_s == opts.air.sound_speed_m_s
        && table.tolerance == opts.multipole_tolerance
        && table.modes.iter().map(|m| m.mode).eq(audible_modes(bank, max_hz))
}

/// The multipole expansion of a stored entry.
pub fn stored_multipole(table: &modal_bank::RadiationTable, entry: &modal_bank::ModeTransfer) -> Multipole {
    Multipole {
        centre: table.centre_m,
        wavenumber: entry.wavenumber,
        fit_radius: table.fit_radius_m,
        order: entry.order,
        coefficients: entry.coefficients.iter().map(|c| c64::new(c[0], c[1])).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The finer level of a closed surface is closed (inside point still
    /// inside), has four times the panels, `V + E` vertices and the same
    /// area, and keeps every panel's integral of a velocity that is linear
    /// over each parent panel (`Σ` children's area × velocity = the
    /// parent's).
    #[test]
    fn the_finer_level_splits_each_panel_in_four_and_keeps_the_velocity_integral() {
        let mesh = crate::geometry::tests::icosphere(0.1, [0.01, -0.02, 0.03], 2);
        let n = mesh.len();
        let sources: Vec<PanelSource> =
            mesh.panels.iter().map(|p| PanelSource::linear(p.corners.map(|c| (c, p.normal)))).collect();
        let finer = split_level(&mesh, &sources).expect("a closed surface splits");
        assert_eq!(finer.mesh.len(), 4 * n);
        assert_eq!(finer.mesh.vertices.len(), mesh.vertices.len() + 3 * n / 2);
        assert!((finer.mesh.area() - mesh.area()).abs() <= 1e-12 * mesh.area());
        assert!(finer.mesh.contains([0.01, -0.02, 0.03]) && !finer.mesh.contains([0.2, 0.0, 0.0]));
        assert!(2.0 * finer.h <= mesh.panels.iter().map(|p| p.diameter).fold(0.0, f64::max) + 1e-15);

        // A nodal value f(node) = a smooth function; per panel, its
        // weighted nodal values (Level::velocity without the bank).
        let f = |node: usize| {
            let v = mesh.vertices[node];
            3.0 * v[0] - v[1] * v[2] + 0.5
        };
        let value = |s: &PanelSource, w: &[f64; 6]| (0..3).map(|k| w[k] * f(s.nodes[k].0)).sum::<f64>();
        for (parent, (p, s)) in mesh.panels.iter().zip(&sources).enumerate() {
            let children = 4 * parent..4 * parent + 4;
            let split: f64 = finer.sources[children.clone()]
                .iter()
                .zip(&finer.weights[children.clone()])
                .zip(&finer.mesh.panels[children])
                .map(|((c, w), q)| q.area * value(c, w))
                .sum();
            let whole = p.area * value(s, &s.weights());
            assert!(
                (split - whole).abs() <= 1e-12 * whole.abs().max(p.area),
                "panel {parent}: {split} vs {whole}"
            );
        }
    }
}
