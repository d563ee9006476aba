//! `modal-precompute`: the offline pipeline, mesh → FEM → eigen → mode bank,
//! served from a content-addressed cache when the same inputs were solved before.
//!
//! Input: a [`Request`] (a mesh file or an in-memory mesh, material, element
//! order, band, constraints). Output: a [`modal_bank::ModeBank`] plus what
//! happened on the way ([`Outcome`]: cache hit or miss, mesh report, warnings).
//!
//! Stages (each reported through the progress callback):
//! 1. load — read the tet mesh, or tetrahedralize a surface mesh (OBJ/STL/PLY/OFF/glTF);
//! 2. check — orientation, degeneracy, unused nodes, connected parts;
//! 3. assemble — K and M at the requested order (default 2, quadratic tets);
//! 4. solve — shift-invert block Lanczos with rigid modes deflated, inertia check;
//! 5. bank — mode shapes restricted to the surface, damping from Rayleigh α, β.

pub mod accuracy;
mod key;
mod levels;
mod load;
mod pipeline;

pub use key::cache_key;
pub use levels::{
    remeshable, AccuracyTarget, BAND_MARGIN, COARSE_FACTOR, DEFAULT_ACCURACY_MODES, LEVELS_VERSION,
    MAX_REFINEMENTS, MAX_STEP, MIN_STEP, PRESCRIBED_NOTE,
};
pub use load::{is_surface_file, load_mesh, LoadedMesh, MeshSource, Scale, SurfaceMeshing};
pub use pipeline::{
    assemble_matrices, check_threads, precompute, residual_floor_warning, Assembled, Outcome, Request, Stage,
    DEFAULT_MAX_FREQ_HZ, MAX_MODES, MAX_THREADS, TARGET_RESIDUAL,
};

/// Version of the numerical pipeline; part of every cache key, so changing
/// anything that alters results — even in the last bit, e.g. the order of a
/// sum in the eigensolver — must bump it: scenes promise the same WAV whether
/// a bank came from the cache or from a fresh solve, and the basis chosen
/// within a repeated eigenvalue follows every rounding.
/// History: 2 — session 3's parallel sparse/dense products in modal-eigen; 3 — the
/// block solves run on the factor repacked into row tiles (`modal-eigen` `tiled`); 4 — the
/// Cholesky factorization of large factors runs in parallel (two tasks); 5 — Gram–Schmidt
/// products of the Krylov blocks on a row-major copy (`modal-eigen` `cgs`); 6 — our own
/// two-core numeric Cholesky for factors below 40 M entries (`modal-eigen` `supernodal`); 7 —
/// the bank's surface leaves out coincident boundary faces, an internal crack
/// (`modal_mesh::boundary_surface`); 8 — a hollow surface keeps its cavity
/// (`modal-tetra` nesting) and the bank's surface leaves out sealed cavities' walls.
pub const SOLVER_VERSION: &str = "modal-precompute-8";

/// Everything that can stop the pipeline, each naming the stage it came from.
#[derive(Debug, thiserror::Error)]
pub enum PrecomputeError {
    /// The input file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// A tet mesh that cannot be used.
    #[error(transparent)]
    Mesh(#[from] modal_mesh::MeshError),
    /// A surface mesh that cannot be tetrahedralized.
    #[error(transparent)]
    Tetra(#[from] modal_tetra::TetraError),
    /// Finite-element assembly failed (e.g. an inverted curved element).
    #[error(transparent)]
    Fem(#[from] modal_fem::FemError),
    /// The eigen solve failed.
    #[error(transparent)]
    Eigen(#[from] modal_eigen::EigenError),
    /// Reading or writing a bank failed.
    #[error(transparent)]
    Bank(#[from] modal_bank::BankError),
    /// Parameters that make no sense.
    #[error("{0}")]
    Invalid(String),
    /// The mesh's solve cannot fit the memory guard (found before the work).
    #[error("{message}")]
    Memory {
        /// What needs how much, and what to do.
        message: String,
        /// The least memory the solve would hold [bytes].
        needed_bytes: u64,
        /// The memory guard [bytes].
        limit_bytes: u64,
    },
}

impl PrecomputeError {
    /// `(needed, limit)` [bytes] when the solve was refused for the memory
    /// guard (here, in the assembly's pattern, or in the eigensolver's plan).
    pub fn memory_overrun(&self) -> Option<(u64, u64)> {
        match self {
            PrecomputeError::Memory { needed_bytes, limit_bytes, .. } => Some((*needed_bytes, *limit_bytes)),
            PrecomputeError::Fem(modal_fem::FemError::TooLarge { needed_bytes, limit_bytes, .. }) => {
                Some((*needed_bytes, *limit_bytes))
            }
            PrecomputeError::Eigen(modal_eigen::EigenError::MemoryLimit { estimated, limit, .. }) => {
                Some((*estimated, *limit))
            }
            _ => None,
        }
    }
}
