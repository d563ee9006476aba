//! One measured case of the study: shape × element order × mesh level.
//!
//! Phases, each timed with its own wall clock: `mesh` (structured generator of
//! `modal_mesh::generate`), `assemble` (sparsity pattern, K and M, clamp restriction,
//! rigid-body fields), `factor` (ordering + symbolic + numeric Cholesky of K − σM, from
//! the eigensolver's own [`modal_eigen::SolveStats`]) and `solve` (Krylov–Schur iteration
//! plus inertia and residual checks). Mesh levels refine geometrically:
//! `h_k = h_0 · 2^(−k/2)` (k = 0, 1, …), so each level has ≈2.8× the DOFs of the previous;
//! `h_0` per shape and order is chosen so that five levels end at 4·10⁴–10⁵ DOF for both
//! orders (TET4 starts one halving finer than TET10: 8× fewer nodes per volume).

use crate::compare::{compare_sorted, Comparison};
use crate::reference::{self, BAR_SIZE, SPHERE_RADIUS, STEEL_E_PA, STEEL_NU, STEEL_RHO};
use crate::StudyError;
use faer::Mat;
use modal_eigen::{EigenOptions, EigenSolution};
use modal_fem::Material;
use modal_mesh::generate::Shape;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// A shape of the study with its boundary condition and reference.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StudyShape {
    /// Free-free steel bar 0.3 × 0.02 × 0.01 m.
    Bar,
    /// Free steel sphere of radius 0.05 m.
    Sphere,
    /// The bar clamped on its face x = 0.
    Cantilever,
}

impl StudyShape {
    /// All shapes, in report order.
    pub const ALL: [StudyShape; 3] = [StudyShape::Bar, StudyShape::Sphere, StudyShape::Cantilever];

    /// Lower-case name used on the command line and in file names.
    pub fn name(self) -> &'static str {
        match self {
            StudyShape::Bar => "bar",
            StudyShape::Sphere => "sphere",
            StudyShape::Cantilever => "cantilever",
        }
    }

    /// Parses a name of [`StudyShape::name`].
    pub fn from_name(name: &str) -> Result<StudyShape, StudyError> {
        StudyShape::ALL
            .into_iter()
            .find(|s| s.name() == name)
            .ok_or_else(|| StudyError::UnknownShape(name.to_string()))
    }

    /// The generator's shape.
    pub fn geometry(self) -> Shape {
        match self {
            StudyShape::Bar | StudyShape::Cantilever => Shape::Box { size: BAR_SIZE },
            StudyShape::Sphere => Shape::Sphere { radius: SPHERE_RADIUS },
        }
    }

    /// Smallest dimension D of the shape (m): the bar's thickness, the sphere's diameter
    /// (the quantity the default mesh size rule `h = D / N` refers to).
    pub fn smallest_dimension_m(self) -> f64 {
        match self {
            StudyShape::Bar | StudyShape::Cantilever => BAR_SIZE[2],
            StudyShape::Sphere => 2.0 * SPHERE_RADIUS,
        }
    }

    /// Reference frequencies (Hz), ascending.
    pub fn reference_hz(self) -> Vec<f64> {
        match self {
            StudyShape::Bar => reference::BAR_FREE_HZ.to_vec(),
            StudyShape::Sphere => reference::sphere_lamb_hz(SPHERE_RADIUS),
            StudyShape::Cantilever => reference::CANTILEVER_HZ.to_vec(),
        }
    }

    /// Clamped box `[x0, y0, z0, x1, y1, z1]` (m), if any: the nodes of the face x = 0.
    pub fn clamp_box(self) -> Option<[f64; 6]> {
        let eps = 1e-9;
        match self {
            StudyShape::Cantilever => Some([-eps, -eps, -eps, eps, BAR_SIZE[1] + eps, BAR_SIZE[2] + eps]),
            _ => None,
        }
    }

    /// Coarsest element size `h_0` (m) of the ladder for element `order`.
    pub fn coarsest_h_m(self, order: u8) -> f64 {
        let d = self.smallest_dimension_m();
        let per_d = match self {
            StudyShape::Bar | StudyShape::Cantilever => 1.0,
            // The compact sphere holds far more elements per D than the slender bar, and its
            // O-grid mesh is denser than V/h³: start at D/2.5.
            StudyShape::Sphere => 2.5,
        };
        // Linear tets have 8× fewer nodes per element volume: start one halving finer.
        let order_factor = if order == 1 { 2.0 } else { 1.0 };
        d / (per_d * order_factor)
    }

    /// Element size (m) of mesh `level` for element `order`.
    pub fn level_h_m(self, order: u8, level: usize) -> f64 {
        self.coarsest_h_m(order) * 2f64.powf(-(level as f64) / 2.0)
    }
}

/// What to run: one shape, element order (1 or 2) and mesh level (or an explicit size).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseSpec {
    /// The shape.
    pub shape: StudyShape,
    /// Element order: 1 (TET4) or 2 (TET10).
    pub order: u8,
    /// Mesh level (0 = coarsest), see [`StudyShape::level_h_m`].
    pub level: usize,
    /// Element size (m) replacing the level's, to measure one specific rule (e.g. `D/5`).
    #[serde(default)]
    pub h_override_m: Option<f64>,
}

impl CaseSpec {
    /// A case on the level ladder.
    pub fn new(shape: StudyShape, order: u8, level: usize) -> CaseSpec {
        CaseSpec { shape, order, level, h_override_m: None }
    }

    /// Parses `shape:order:level` (e.g. `bar:2:3`) or `shape:order:h=<mm>` (e.g. `bar:2:h=2`).
    pub fn parse(text: &str) -> Result<CaseSpec, StudyError> {
        let bad = || StudyError::BadCase(text.to_string());
        let parts: Vec<&str> = text.split(':').collect();
        let [shape, order, size] = parts[..] else { return Err(bad()) };
        let shape = StudyShape::from_name(shape)?;
        let order: u8 = order.parse().map_err(|_| bad())?;
        if !(1..=2).contains(&order) {
            return Err(bad());
        }
        if let Some(mm) = size.strip_prefix("h=") {
            let mm: f64 = mm.parse().map_err(|_| bad())?;
            // Below 1/100 of the smallest dimension a case would not fit in memory.
            let min_mm = shape.smallest_dimension_m() * 10.0;
            if !(mm.is_finite() && mm >= min_mm && mm <= 1e3) {
                return Err(bad());
            }
            return Ok(CaseSpec { shape, order, level: 0, h_override_m: Some(mm * 1e-3) });
        }
        let level: usize = size.parse().map_err(|_| bad())?;
        if level > 20 {
            return Err(bad());
        }
        Ok(CaseSpec::new(shape, order, level))
    }

    /// The text [`CaseSpec::parse`] reads.
    pub fn label(&self) -> String {
        match self.h_override_m {
            Some(h) => format!("{}:{}:h={}", self.shape.name(), self.order, h * 1e3),
            None => format!("{}:{}:{}", self.shape.name(), self.order, self.level),
        }
    }

    /// Element size (m) of this case.
    pub fn h_m(&self) -> f64 {
        self.h_override_m.unwrap_or_else(|| self.shape.level_h_m(self.order, self.level))
    }
}

/// Measurements of one case.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CaseResult {
    /// What was run.
    pub spec: CaseSpec,
    /// Nominal element size passed to the generator (m).
    pub h_m: f64,
    /// Mean cell size `(6 V / tets)^(1/3)` (m): the edge of a cube holding six such tets.
    pub h_mean_m: f64,
    /// Mesh nodes.
    pub nodes: usize,
    /// Mesh tets.
    pub tets: usize,
    /// Free degrees of freedom (clamped ones removed).
    pub dofs: usize,
    /// Seconds generating the mesh.
    pub mesh_s: f64,
    /// Seconds assembling K and M (pattern, values, clamp, rigid fields).
    pub assemble_s: f64,
    /// Seconds in ordering, symbolic and numeric factorization.
    pub factor_s: f64,
    /// Seconds in the eigen iteration and its checks.
    pub solve_s: f64,
    /// Wall seconds of the whole case.
    pub total_s: f64,
    /// Peak resident memory of the process running the case (bytes), if known.
    pub peak_rss_bytes: Option<u64>,
    /// Computed elastic frequencies (Hz), ascending.
    pub frequencies_hz: Vec<f64>,
    /// Error against the reference.
    pub comparison: Comparison,
}

/// The study material (analytic.md's steel, no damping).
pub fn study_material() -> Material {
    Material {
        name: Some("steel (E 200 GPa, nu 0.3, rho 7850)".into()),
        youngs_pa: STEEL_E_PA,
        poisson: STEEL_NU,
        density_kg_m3: STEEL_RHO,
        alpha: 0.0,
        beta: 0.0,
    }
}

/// Runs one case in this process (see the module docs); `peak_rss_bytes` is left `None`
/// (the caller measures it, see [`crate::peak_rss_bytes`]).
pub fn run_case(spec: CaseSpec) -> Result<CaseResult, StudyError> {
    let start = Instant::now();
    let shape = spec.shape;
    let h = spec.h_m();
    let mesh = modal_mesh::generate::generate(&shape.geometry(), h, spec.order)?;
    let mesh_s = start.elapsed().as_secs_f64();

    let t = Instant::now();
    let system = assemble(&mesh, shape.clamp_box())?;
    let assemble_s = t.elapsed().as_secs_f64();

    let reference = shape.reference_hz();
    let solution = solve(&system, reference.len())?;
    let stats = &solution.stats;
    let frequencies_hz = solution.frequencies_hz();
    let comparison = compare_sorted(&frequencies_hz, &reference);
    let volume = modal_mesh::mesh_volume(&mesh);
    Ok(CaseResult {
        spec,
        h_m: h,
        h_mean_m: (6.0 * volume / mesh.cells.len() as f64).cbrt(),
        nodes: mesh.node_count(),
        tets: mesh.cells.len(),
        dofs: system.k.nrows(),
        mesh_s,
        assemble_s,
        factor_s: stats.symbolic_s + stats.factor_s,
        solve_s: stats.solve_s + stats.check_s,
        total_s: start.elapsed().as_secs_f64(),
        peak_rss_bytes: None,
        frequencies_hz,
        comparison,
    })
}

/// K, M on the free DOFs and the rigid-body fields to deflate (none when clamped).
struct System {
    k: faer::sparse::SparseColMat<usize, f64>,
    m: faer::sparse::SparseColMat<usize, f64>,
    rigid: Option<Mat<f64>>,
}

fn assemble(mesh: &modal_mesh::TetMesh, clamp: Option<[f64; 6]>) -> Result<System, StudyError> {
    let assembly = modal_fem::assemble(mesh, &study_material())?;
    match clamp {
        None => {
            let (parts, count) = modal_fem::node_parts(mesh);
            let rigid = modal_fem::rigid_body_fields(&mesh.nodes, &parts, count, &[]);
            Ok(System { k: assembly.k, m: assembly.m, rigid: Some(rigid) })
        }
        Some(b) => {
            let clamped = modal_fem::fix_box(&mesh.nodes, b);
            if !clamped.iter().any(|&c| c) {
                return Err(StudyError::NothingClamped);
            }
            let r = modal_fem::restrict(&assembly.k, &assembly.m, &clamped)?;
            Ok(System { k: r.k, m: r.m, rigid: None })
        }
    }
}

fn solve(system: &System, modes: usize) -> Result<EigenSolution, StudyError> {
    let options = EigenOptions {
        min_freq_hz: 1.0,
        max_freq_hz: 1e7,
        max_modes: modes,
        threads: 1,
        ..EigenOptions::default()
    };
    let rigid = system.rigid.as_ref().map(|r| r.as_ref());
    Ok(modal_eigen::solve(&system.k, &system.m, rigid, &options, &mut |_| {})?)
}
