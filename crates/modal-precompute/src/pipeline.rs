//! Stages 3–5: assemble, solve, build the bank; with the cache around them.

use std::time::Instant;

use faer::sparse::SparseColMat;
use faer::Mat;
use modal_bank::{BankCache, ModeBank, SolveInfo};
use modal_eigen::{EigenOptions, EigenSolution};
use modal_fem::Material;
use modal_mesh::TetMesh;

use crate::levels::AccuracyTarget;
use crate::load::{load_mesh_sized, LevelSize, Scale, SurfaceMeshing, TetBudget};
use crate::{cache_key, MeshSource, PrecomputeError};

/// What to compute. `Default` gives the CLI's defaults for everything but
/// the source and material.
#[derive(Clone, Debug)]
pub struct Request {
    /// The geometry.
    pub source: MeshSource,
    /// Factor applied to all coordinates (e.g. 0.001 for millimetres).
    pub scale: f64,
    /// The caller stated `scale` (`--scale`, a manifest's or a scene's key). Unstated,
    /// a mesh file whose object is more than 20 m across is refused before any work as
    /// a file in millimetres ([`crate::Scale`]). Not part of the cache key: it decides
    /// whether a solve is attempted, not its result.
    pub scale_stated: bool,
    /// Options for surface meshes (OBJ/STL/PLY/OFF/glTF).
    pub surface: SurfaceMeshing,
    /// Material, incl. Rayleigh damping.
    pub material: Material,
    /// Element order: 2 (quadratic, default) or 1 (linear).
    pub order: u8,
    /// Lowest frequency kept [Hz].
    pub min_freq_hz: f64,
    /// Highest frequency kept [Hz].
    pub max_freq_hz: f64,
    /// Keep at most this many modes (the lowest in the band).
    pub max_modes: usize,
    /// Clamp every node inside `[x0, y0, z0, x1, y1, z1]` [m].
    pub fix_box: Option<[f64; 6]>,
    /// Threads of the sparse factorization and solves (`None`: one, measured
    /// fastest on 2 cores; the completeness check still overlaps on a second).
    pub threads: Option<usize>,
    /// Per-mode error estimate and the accuracy to reach (surface meshes only, see
    /// `crate::levels`); `None`: one solve at the given discretization, no estimate.
    pub accuracy: Option<AccuracyTarget>,
    /// Memory the eigensolver may plan for [bytes], also the guard of the accuracy
    /// levels; `None`: 75 % of the available memory (the eigensolver's default).
    /// Not part of the cache key: it decides whether a solve is attempted, not its result.
    pub memory_limit_bytes: Option<u64>,
}

/// Top of the default band [Hz] (`precompute --max-freq`).
pub const DEFAULT_MAX_FREQ_HZ: f64 = 20_000.0;

impl Request {
    /// A request with the CLI defaults: order 2, 20 Hz – 20 kHz, 64 modes; no
    /// accuracy target (the CLI's `precompute` sets `--accuracy 1`).
    pub fn new(source: MeshSource, material: Material) -> Self {
        Request {
            source,
            scale: 1.0,
            scale_stated: false,
            surface: SurfaceMeshing::default(),
            material,
            order: 2,
            min_freq_hz: 20.0,
            max_freq_hz: DEFAULT_MAX_FREQ_HZ,
            max_modes: 64,
            fix_box: None,
            threads: None,
            accuracy: None,
            memory_limit_bytes: None,
        }
    }

    /// The surface options with flat walls sized for the modes this request keeps
    /// (unless they say otherwise): a plate asked for 200 modes is meshed finer than
    /// one asked for the default 64 (`modal_tetra::TetOptions::resolved_modes`).
    pub fn surface_meshing(&self) -> SurfaceMeshing {
        SurfaceMeshing {
            resolved_modes: self.surface.resolved_modes.or(Some(self.max_modes)),
            ..self.surface.clone()
        }
    }

    fn validate(&self) -> Result<(), PrecomputeError> {
        let invalid = |msg: String| Err(PrecomputeError::Invalid(msg));
        if !matches!(self.order, 1 | 2) {
            return invalid(format!("--order must be 1 or 2, got {}", self.order));
        }
        if !(self.min_freq_hz.is_finite() && self.min_freq_hz >= 0.0) {
            return invalid(format!("--min-freq must be a non-negative number, got {}", self.min_freq_hz));
        }
        if !(self.max_freq_hz.is_finite() && self.max_freq_hz > self.min_freq_hz) {
            return invalid(format!(
                "--max-freq ({}) must be a finite number above --min-freq ({})",
                self.max_freq_hz, self.min_freq_hz
            ));
        }
        if !(1..=MAX_MODES).contains(&self.max_modes) {
            return invalid(format!("--modes must be between 1 and {MAX_MODES}, got {}", self.max_modes));
        }
        check_threads(self.threads)?;
        if let Some(a) = &self.accuracy {
            if !(a.target_pct.is_finite() && a.target_pct > 0.0) {
                return invalid(format!(
                    "the accuracy target must be a positive percentage, got {}",
                    a.target_pct
                ));
            }
            if a.modes == 0 {
                return invalid("the accuracy target must apply to at least one mode".into());
            }
        }
        if self.fix_box.is_some_and(|b| b.iter().any(|x| !x.is_finite())) {
            return invalid("--fix-box must hold finite numbers".into());
        }
        self.material.validate().map_err(|e| PrecomputeError::Invalid(e.to_string()))
    }
}

/// The most modes a request may ask for: a 2 m square steel sheet 1 mm
/// thick has ≈ 26 000 modes below 20 kHz; beyond this no bank is playable
/// and the solver's vectors alone fill any memory.
pub const MAX_MODES: usize = 100_000;

/// The most solver threads a request may ask for. More than the cores buys
/// nothing (the solve is memory-bound beyond a few), and a pool of 10⁵
/// threads stalled for over a minute before any work; the largest common
/// machines have a few hundred cores.
pub const MAX_THREADS: usize = 1024;

/// Refuses a thread count outside `1..=`[`MAX_THREADS`] (`None`: the default),
/// for callers that must check it before a solve is known to be needed.
pub fn check_threads(threads: Option<usize>) -> Result<(), PrecomputeError> {
    match threads.filter(|n| !(1..=MAX_THREADS).contains(n)) {
        Some(n) => {
            Err(PrecomputeError::Invalid(format!("--threads must be between 1 and {MAX_THREADS}, got {n}")))
        }
        None => Ok(()),
    }
}

/// Progress of the pipeline, for the CLI's progress display.
#[derive(Clone, Debug, PartialEq)]
pub enum Stage {
    /// Reading (and maybe tetrahedralizing) the mesh.
    Load,
    /// Assembling K and M for this many DOFs.
    Assemble {
        /// Degrees of freedom.
        dofs: usize,
    },
    /// The eigen solver reports progress.
    Solve(String),
    /// Writing the bank to the cache.
    Store,
    /// A warning about the input (a mesh repair, a size that suggests another unit),
    /// said as soon as the mesh is read so the user can stop a long solve; it is in
    /// [`Outcome::warnings`] too. A finer discretization level says its own; the coarse
    /// level of the error estimate says none (its mesh is not the bank's).
    Warning(String),
    /// Starting discretization level `index` (0: the first) for the error estimate,
    /// its element sizes × `size_factor` relative to the default.
    Level {
        /// 0, 1, ...
        index: usize,
        /// Element sizes relative to the first request.
        size_factor: f64,
    },
}

/// The result of [`precompute`].
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The modes.
    pub bank: ModeBank,
    /// True when served from the cache without solving.
    pub cached: bool,
    /// Warnings for the user (mesh fixes, unit hints, zero damping, ...).
    pub warnings: Vec<String>,
}

/// K and M of a checked mesh at the requested order.
pub struct Assembled {
    /// The mesh at the element order used (mid-edge nodes added for order 2).
    pub mesh: TetMesh,
    /// Connected parts, and the part of each node.
    pub parts: usize,
    /// Part id of each node of `mesh`.
    pub part_of_node: Vec<usize>,
    /// Stiffness matrix [N/m], full symmetric storage.
    pub k: SparseColMat<usize, f64>,
    /// Consistent mass matrix [kg], full symmetric storage.
    pub m: SparseColMat<usize, f64>,
    /// Seconds spent assembling.
    pub assemble_s: f64,
    /// Warnings collected while loading.
    pub warnings: Vec<String>,
    /// The tetrahedralizer's cell size [m] for a surface mesh (`None`: tet mesh).
    pub cell_m: Option<f64>,
    /// The surface was meshed in layers across a thin wall.
    pub layered: bool,
    /// Separate bodies of the input surface (`None` for a tet mesh).
    pub surface_bodies: Option<usize>,
    /// The mesh's volume over the surface's (`LoadedMesh::volume_kept`).
    pub volume_kept: Option<f64>,
}

/// Loads the mesh and assembles K and M (what `export-matrices` writes).
pub fn assemble_matrices(
    request: &Request,
    progress: &mut dyn FnMut(Stage),
) -> Result<Assembled, PrecomputeError> {
    Ok(assemble_and_analyze(request, false, None, progress)?.0)
}

/// [`assemble_matrices`], and with `analyze` (and no clamps, which change the matrices
/// solved) the eigensolver's ordering and symbolic factorization beside the numeric
/// assembly: they depend on the pattern only, and the second core is partly idle while the
/// element matrices are scattered (30k DOF: ≈ 0.14 s of ordering and analysis hidden).
/// `assemble_s` is the wall time of both. `level` sizes a surface mesh's tets (see
/// [`load_mesh_sized`]).
pub(crate) fn assemble_and_analyze(
    request: &Request,
    analyze: bool,
    level: Option<LevelSize>,
    progress: &mut dyn FnMut(Stage),
) -> Result<(Assembled, Option<modal_eigen::Analysis>), PrecomputeError> {
    request.validate()?;
    progress(Stage::Load);
    let limit = request.memory_limit_bytes.or_else(modal_eigen::default_memory_limit);
    let vector_bytes_per_dof = modal_eigen::vector_bytes_per_dof(&eigen_options(request));
    let budget = limit
        .filter(|_| request.order == 2)
        .map(|limit_bytes| TetBudget { limit_bytes, vector_bytes_per_dof });
    let scale = Scale { factor: request.scale, stated: request.scale_stated };
    let loaded = load_mesh_sized(&request.source, scale, &request.surface_meshing(), level, budget)?;
    loaded.warnings.iter().for_each(|w| progress(Stage::Warning(w.clone())));
    let mesh = modal_fem::prepare_mesh(&loaded.mesh, request.order)?;
    // Mid-edge nodes belong to the part of their edge's corners.
    let part_of_node = extend_parts(&mesh, &loaded.part_of_node);
    progress(Stage::Assemble { dofs: 3 * mesh.nodes.len() });
    let start = Instant::now();
    // Refuse before assembly what the solver's memory guard would refuse after it.
    let pattern = modal_fem::SparsityPattern::new_within(&mesh, limit)?;
    let matrices_bytes = modal_fem::matrices_bytes(pattern.nnz() as u64, pattern.dof_count() as u64);
    // A failed analysis is not an error here: the solve redoes it and reports.
    let analyze_pattern =
        || modal_eigen::analyze(pattern.symbolic().as_ref(), modal_eigen::Ordering::Auto).ok();
    let (assembly, analysis) =
        if analyze && request.fix_box.is_none() && limit.is_some_and(|l| matrices_bytes > l / 8) {
            // A large mesh: the factor's size first, from the pattern alone, so a mesh whose
            // factor cannot fit is refused before its matrices take most of the memory
            // (4.5 M DOF: 15 GB of K and M assembled, then a 110 GB factor refused).
            let analysis = analyze_pattern();
            if let (Some(a), Some(limit)) = (&analysis, limit) {
                let vectors = vector_bytes_per_dof * pattern.dof_count() as u64;
                refuse_beyond_memory(
                    pattern.dof_count(),
                    matrices_bytes,
                    a.factor_value_bytes(),
                    vectors,
                    limit,
                )?;
            }
            (pattern.assemble(&mesh, &request.material)?, analysis)
        } else if analyze && request.fix_box.is_none() {
            let (assembly, analysis) =
                rayon::join(|| pattern.assemble(&mesh, &request.material), analyze_pattern);
            (assembly?, analysis)
        } else {
            (pattern.assemble(&mesh, &request.material)?, None)
        };
    let assembled = Assembled {
        mesh,
        parts: loaded.parts,
        part_of_node,
        k: assembly.k,
        m: assembly.m,
        assemble_s: start.elapsed().as_secs_f64(),
        warnings: loaded.warnings,
        cell_m: loaded.cell_m,
        layered: loaded.layered,
        surface_bodies: loaded.surface_bodies,
        volume_kept: loaded.volume_kept,
    };
    Ok((assembled, analysis))
}

/// The eigensolver's options for `request`.
fn eigen_options(request: &Request) -> EigenOptions {
    EigenOptions {
        min_freq_hz: request.min_freq_hz,
        max_freq_hz: request.max_freq_hz,
        max_modes: request.max_modes,
        threads: request.threads.unwrap_or(0),
        memory_limit_bytes: request.memory_limit_bytes,
        ..EigenOptions::default()
    }
}

/// Refuses a solve whose K and M (`matrices_bytes`), factor values (`factor_bytes`) and
/// the eigensolver's dense vectors (`vector_bytes`), all held during the solve, exceed
/// `limit` [bytes].
fn refuse_beyond_memory(
    dofs: usize,
    matrices_bytes: u64,
    factor_bytes: u64,
    vector_bytes: u64,
    limit: u64,
) -> Result<(), PrecomputeError> {
    let needed_bytes = matrices_bytes + factor_bytes + vector_bytes;
    if needed_bytes <= limit {
        return Ok(());
    }
    Err(PrecomputeError::Memory {
        message: format!(
            "the mesh has {dofs} DOF: its stiffness and mass matrices need ≈ {:.1} GB and their factor ≈ {:.1} GB, \
             the eigensolver's vectors ≈ {:.1} GB, above the memory limit of {:.1} GB; {}",
            matrices_bytes as f64 / 1e9,
            factor_bytes as f64 / 1e9,
            vector_bytes as f64 / 1e9,
            limit as f64 / 1e9,
            memory_remedy(vector_bytes, needed_bytes, limit, "a larger element size or --cell")
        ),
        needed_bytes,
        limit_bytes: limit,
    })
}

/// Part ids for a mesh whose first nodes are those of the checked mesh and
/// whose added nodes (mid-edge) take the part of a tet corner.
fn extend_parts(mesh: &TetMesh, part_of_corner: &[usize]) -> Vec<usize> {
    let mut parts = vec![usize::MAX; mesh.nodes.len()];
    parts[..part_of_corner.len().min(mesh.nodes.len())]
        .copy_from_slice(&part_of_corner[..part_of_corner.len().min(mesh.nodes.len())]);
    for t in 0..mesh.cells.len() {
        let part = parts[mesh.cells.corners(t)[0]];
        for &n in mesh.cells.nodes_of(t) {
            if parts[n] == usize::MAX {
                parts[n] = part;
            }
        }
    }
    debug_assert!(parts.iter().all(|&p| p != usize::MAX), "every node belongs to a tet");
    parts
}

/// Computes (or fetches from `cache`) the mode bank for `request`.
pub fn precompute(
    request: &Request,
    cache: Option<&BankCache>,
    force: bool,
    progress: &mut dyn FnMut(Stage),
) -> Result<Outcome, PrecomputeError> {
    request.validate()?;
    let key = cache_key(request)?;
    let mut warnings = Vec::new();
    if let (Some(cache), false) = (cache, force) {
        match cache.get(&key) {
            Ok(Some(bank)) => {
                warnings.extend(bank_warnings(request, &bank));
                return Ok(Outcome { bank, cached: true, warnings });
            }
            Ok(None) => {}
            Err(err) => warnings.push(format!("ignoring a damaged cache entry ({err}); recomputing")),
        }
    }
    let (bank, coarsened) = match (&request.accuracy, crate::levels::remeshable(&request.source)) {
        (Some(target), true) => {
            let (bank, level_warnings, coarsened) =
                crate::levels::solve_to_accuracy(request, target, &key, progress)?;
            warnings.extend(level_warnings);
            (bank, coarsened)
        }
        (accuracy, remeshable) => {
            let mut level_warnings = Vec::new();
            let ((bank, assembled_warnings), level) =
                crate::levels::within_memory(request, &mut level_warnings, |level| {
                    let (assembled, analysis) = assemble_and_analyze(request, true, level, progress)?;
                    crate::levels::refuse_broken_fit(&assembled, level)?;
                    let bank = solve_bank(request, &assembled, analysis, key.clone(), progress)?.0;
                    Ok((bank, assembled.warnings))
                })?;
            warnings.extend(assembled_warnings);
            warnings.extend(level_warnings);
            if accuracy.is_some() && !remeshable {
                warnings.push(crate::levels::PRESCRIBED_NOTE.into());
            }
            (bank, level.is_some())
        }
    };
    warnings.extend(bank_warnings(request, &bank));
    // A mesh coarsened for this machine's memory is not the request's answer: another run,
    // with more memory, must not be served it from the cache.
    if let (Some(cache), false) = (cache, coarsened) {
        progress(Stage::Store);
        if let Err(err) = cache.put(&key, &bank) {
            warnings.push(format!("could not store the result in the cache: {err}"));
        }
    }
    Ok(Outcome { bank, cached: false, warnings })
}

/// What the user must hear about a finished bank, cached or solved: a
/// residual floor, and a band with no mode in it (every caller, the batch
/// catalogue included, says it; a silent prop must not pass as "ok").
fn bank_warnings(request: &Request, bank: &ModeBank) -> Vec<String> {
    let silent = (bank.mode_count() == 0).then(|| {
        format!(
            "no mode between {} Hz and {} Hz: the bank is silent (a small or stiff object rings higher: raise \
             the highest frequency)",
            request.min_freq_hz, request.max_freq_hz
        )
    });
    residual_floor_warning(bank).into_iter().chain(silent).collect()
}

/// What to change when a solve needs `needed` bytes of `limit`, `vectors`
/// of them the eigensolver's vectors (which grow with the modes asked for,
/// the rest with the mesh): fewer modes when they dominate and the rest
/// would fit, else a coarser mesh (`coarser` says how).
pub(crate) fn memory_remedy(vectors: u64, needed: u64, limit: u64, coarser: &str) -> String {
    if vectors > needed / 2 && needed - vectors.min(needed) <= limit {
        "ask for fewer modes (--modes)".to_string()
    } else {
        format!("use a coarser mesh ({coarser}) or --order 1")
    }
}

/// The residual every mode should reach (`‖Kw − λMw‖ / (λ‖Mw‖)`).
pub const TARGET_RESIDUAL: f64 = 1e-8;

/// Says so when double precision could not certify [`TARGET_RESIDUAL`] for
/// some modes (the solver's documented floor, reached only by the lowest
/// modes of very fine or very thin meshes), so the user is never left with a
/// silently weaker result. The frequencies stay accurate: for a symmetric
/// problem the eigenvalue error is second order in the residual.
pub fn residual_floor_warning(bank: &ModeBank) -> Option<String> {
    let above: Vec<usize> =
        (0..bank.residuals.len()).filter(|&i| bank.residuals[i] > TARGET_RESIDUAL).collect();
    let worst = above.iter().map(|&i| bank.residuals[i]).fold(0.0, f64::max);
    let first = *above.first()?;
    Some(format!(
        "{} of {} modes (first: mode {} at {:.1} Hz) have residuals up to {worst:.1e} > {TARGET_RESIDUAL:.0e}: \
         the limit of double precision for this mesh (very fine or very thin elements); the frequencies \
         stay accurate (eigenvalue error is second order in the residual)",
        above.len(),
        bank.residuals.len(),
        first + 1,
        bank.frequencies_hz[first],
    ))
}

/// Clamps, deflates rigid modes, solves and builds the bank; also returns the
/// solver's memory estimate [bytes].
pub(crate) fn solve_bank(
    request: &Request,
    assembled: &Assembled,
    analysis: Option<modal_eigen::Analysis>,
    input_hash: String,
    progress: &mut dyn FnMut(Stage),
) -> Result<(ModeBank, u64), PrecomputeError> {
    let nodes = &assembled.mesh.nodes;
    let clamped = match request.fix_box {
        Some(b) => modal_fem::fix_box(nodes, b),
        None => vec![false; 3 * nodes.len()],
    };
    if clamped.iter().all(|&c| c) {
        return Err(PrecomputeError::Invalid(
            "--fix-box clamps every node: nothing is left to vibrate".into(),
        ));
    }
    // A part with a clamped node has no rigid-body modes.
    let mut clamped_parts: Vec<usize> =
        (0..nodes.len()).filter(|&n| clamped[3 * n]).map(|n| assembled.part_of_node[n]).collect();
    clamped_parts.sort_unstable();
    clamped_parts.dedup();
    let rigid_full =
        modal_fem::rigid_body_fields(nodes, &assembled.part_of_node, assembled.parts, &clamped_parts);
    // Without clamps the assembled matrices are solved as they are (a copy of K and M
    // costs ≈ 1.5 % of a 30k-DOF precompute).
    let restricted = if clamped.iter().any(|&c| c) {
        Some(modal_fem::restrict(&assembled.k, &assembled.m, &clamped)?)
    } else {
        None
    };
    let (k, m, dof_map) = match &restricted {
        Some(r) => (&r.k, &r.m, r.dofs.clone()),
        None => (&assembled.k, &assembled.m, modal_fem::DofMap::from_clamped(&clamped)),
    };
    let rigid = restrict_rows(&rigid_full, &dof_map.free_to_full);
    let options = eigen_options(request);
    let rigid_ref = (rigid.ncols() > 0).then(|| rigid.as_ref());
    let solution = modal_eigen::solve_analyzed(k, m, rigid_ref, &options, analysis, &mut |p| {
        progress(Stage::Solve(format!("{p:?}")))
    })?;
    let memory = solution.stats.memory_estimate_bytes;
    Ok((build_bank(request, assembled, &dof_map, &solution, input_hash), memory))
}

fn restrict_rows(fields: &Mat<f64>, rows: &[usize]) -> Mat<f64> {
    Mat::from_fn(rows.len(), fields.ncols(), |i, j| fields[(rows[i], j)])
}

/// Puts the solution into a bank: shapes at surface nodes (clamped DOFs are
/// zero), damping from the material's Rayleigh coefficients.
fn build_bank(
    request: &Request,
    assembled: &Assembled,
    dof_map: &modal_fem::DofMap,
    solution: &EigenSolution,
    input_hash: String,
) -> ModeBank {
    let surface = modal_mesh::boundary_surface(&assembled.mesh);
    let n_modes = solution.eigenvalues.len();
    let mut shapes = Vec::with_capacity(n_modes * surface.node_ids.len() * 3);
    for mode in 0..n_modes {
        for &node in &surface.node_ids {
            for c in 0..3 {
                let value =
                    dof_map.full_to_free[3 * node + c].map_or(0.0, |free| solution.vectors[(free, mode)]);
                shapes.push(value as f32);
            }
        }
    }
    let material = &request.material;
    let omegas: Vec<f64> = solution.eigenvalues.iter().map(|&l| l.max(0.0).sqrt()).collect();
    let stats = &solution.stats;
    ModeBank {
        frequencies_hz: omegas.iter().map(|w| w / (2.0 * std::f64::consts::PI)).collect(),
        damping_ratios: omegas.iter().map(|&w| material.damping_ratio(w)).collect(),
        decay_rates: omegas.iter().map(|&w| material.decay_rate(w)).collect(),
        residuals: solution.residuals.clone(),
        shapes,
        surface,
        material: material.clone(),
        mass: modal_fem::mass_properties(&assembled.mesh, material.density_kg_m3),
        info: SolveInfo {
            order: request.order,
            dofs: dof_map.free_count(),
            rigid_modes_removed: stats.rigid_modes_removed,
            inertia_expected: stats.inertia_expected,
            inertia_found: stats.inertia_found,
            assemble_s: assembled.assemble_s,
            // Reported phases: "factor" includes the ordering and symbolic
            // analysis, "solve" the iteration and the completeness check.
            factor_s: stats.symbolic_s + stats.factor_s,
            solve_s: stats.solve_s + stats.check_s,
            input_hash,
            error_estimate_pct: Vec::new(),
            error_estimate_method: String::new(),
        },
    }
}
