//! Public parameter, result, progress and error types of the eigensolver.
//!
//! Units: eigenvalues λ = ω² in rad²/s², frequencies f = √λ / 2π in Hz.

use std::fmt;

/// Fill-reducing ordering used for the sparse factorization of `K − σM`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Default)]
pub enum Ordering {
    /// METIS nested dissection (`METIS_NodeND`) on the node graph (3 DOFs per node),
    /// expanded to DOFs. Falls back to AMD if the DOF count is not a multiple of 3.
    Metis,
    /// faer's approximate minimum degree on the DOF graph.
    Amd,
    /// Pick the measured best: METIS for node-structured problems, AMD otherwise.
    #[default]
    Auto,
}

/// Options of [`crate::solve`].
#[derive(Clone, Debug)]
pub struct EigenOptions {
    /// Lower edge of the wanted band in Hz (inclusive). Default 20 Hz.
    pub min_freq_hz: f64,
    /// Upper edge of the wanted band in Hz (inclusive), no upper cap. Default 20 kHz.
    pub max_freq_hz: f64,
    /// At most this many elastic modes (the lowest in the band). Default 64.
    pub max_modes: usize,
    /// Per-mode relative residual ‖Kw − λMw‖ / (λ‖Mw‖) to reach. Default 1e-8.
    pub tolerance: f64,
    /// Block size of the block Krylov–Schur iteration (columns per block solve). Default 8.
    pub block_size: usize,
    /// Fill-reducing ordering. Default [`Ordering::Auto`].
    pub ordering: Ordering,
    /// Solver threads (0: one per core). Sparse products run by row ranges, tall dense
    /// products as two fixed row halves, the Cholesky factorization and the block solves as
    /// two fixed parts of the elimination tree on these threads; the result does not depend
    /// on the count. Default 0.
    pub threads: usize,
    /// Refuse to factor if the estimated memory exceeds this many bytes.
    /// `None`: 75 % of `MemAvailable` from /proc/meminfo (no limit if unreadable).
    pub memory_limit_bytes: Option<u64>,
    /// Maximum number of Krylov–Schur restarts per search. Default 200.
    pub max_restarts: usize,
    /// Start the upper inertia check (an LDLᵀ of `K − σ'M`) as a second task as soon as the
    /// Ritz values fix σ', overlapping it with the rest of the iteration; needs one more factor
    /// in memory (skipped if that exceeds the memory limit). The proof is unchanged: if the
    /// early σ' does not fit the converged modes, the check is redone at the final σ'.
    /// Default true.
    pub overlap_check: bool,
}

impl Default for EigenOptions {
    fn default() -> Self {
        Self {
            min_freq_hz: 20.0,
            max_freq_hz: 20_000.0,
            max_modes: 64,
            tolerance: 1e-8,
            block_size: 8,
            ordering: Ordering::Auto,
            threads: 0,
            memory_limit_bytes: None,
            max_restarts: 200,
            overlap_check: true,
        }
    }
}

/// Which ordering was actually used.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum OrderingUsed {
    /// METIS nested dissection on the node graph.
    Metis,
    /// faer's AMD.
    Amd,
}

/// Counters and timings of one solve.
#[derive(Clone, Debug, Default)]
pub struct SolveStats {
    /// Number of rigid-body fields deflated (rank of the M-orthonormalized fields).
    pub rigid_modes_removed: usize,
    /// Sylvester inertia: number of eigenvalues below the upper check shift σ'.
    pub inertia_expected: usize,
    /// Eigenvalues known below σ': rigid + elastic below the band + returned + converged beyond the cap.
    pub inertia_found: usize,
    /// Upper check shift σ' (rad²/s²).
    pub inertia_shift: f64,
    /// Elastic eigenvalues below `min_freq_hz` (known from the lower inertia count).
    pub elastic_below_band: usize,
    /// Numeric factorizations performed (shift-invert and inertia checks).
    pub factorizations: usize,
    /// Block solves (each `block_size` columns).
    pub block_solves: usize,
    /// Explicit residual checks of candidate Ritz pairs during the iteration.
    pub residual_checks: usize,
    /// Krylov–Schur restarts over all searches.
    pub iterations: usize,
    /// Stored entries of the factor L.
    pub factor_nnz: usize,
    /// Estimated memory of factor + workspace + Krylov basis (bytes).
    pub memory_estimate_bytes: u64,
    /// Shift σ of the shift-invert operator (rad²/s²).
    pub shift: f64,
    /// Seconds in ordering + symbolic analysis.
    pub symbolic_s: f64,
    /// Seconds in numeric factorizations of the operator shift.
    pub factor_s: f64,
    /// Seconds in the Krylov iteration (block solves, orthogonalization, Rayleigh–Ritz).
    pub solve_s: f64,
    /// Seconds in final residuals and inertia checks.
    pub check_s: f64,
    /// Of `solve_s`: seconds in block solves with the factor.
    pub block_solve_s: f64,
    /// Of `solve_s`: seconds orthogonalizing new blocks (CGS2 + SVQB, incl. M products).
    pub orthogonalize_s: f64,
    /// Of `solve_s`: seconds in explicit residual checks of candidate Ritz pairs.
    pub residual_check_s: f64,
    /// Ordering used.
    pub ordering: Option<OrderingUsed>,
    /// Spectrum scale maxᵢ Kᵢᵢ/Mᵢᵢ (rad²/s²); each mode's residual bound is
    /// [`crate::residual_bound`]`(tolerance, λ, lambda_scale)`.
    pub lambda_scale: f64,
}

/// Result of [`crate::solve`].
#[derive(Clone, Debug)]
pub struct EigenSolution {
    /// Elastic eigenvalues λ = ω² (rad²/s²), ascending, within the band, at most `max_modes`.
    pub eigenvalues: Vec<f64>,
    /// Mode shapes, n × k, M-orthonormal (Wᵀ M W = I).
    pub vectors: faer::Mat<f64>,
    /// Relative residual ‖Kw − λMw‖₂ / (λ‖Mw‖₂) of each mode.
    pub residuals: Vec<f64>,
    /// Counters and timings.
    pub stats: SolveStats,
}

impl EigenSolution {
    /// Natural frequencies √λ / 2π in Hz, ascending.
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.eigenvalues.iter().map(|&l| lambda_to_hz(l)).collect()
    }
}

/// Converts λ = ω² (rad²/s²) to Hz.
pub fn lambda_to_hz(lambda: f64) -> f64 {
    lambda.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
}

/// Converts Hz to λ = ω² (rad²/s²).
pub fn hz_to_lambda(hz: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI * hz;
    w * w
}

/// Phases reported through [`Progress`].
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Fill-reducing ordering and symbolic factorization.
    Symbolic,
    /// Numeric factorization of `K − σM`.
    Factor,
    /// Block Krylov–Schur iteration.
    Iterate,
    /// Final residuals and Sylvester inertia checks.
    Check,
}

impl fmt::Display for Phase {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Phase::Symbolic => "ordering",
            Phase::Factor => "factor",
            Phase::Iterate => "iterate",
            Phase::Check => "check",
        })
    }
}

/// Progress events; the library never prints, the caller renders these.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Progress {
    /// A phase begins.
    PhaseStart(Phase),
    /// A phase ended after `seconds`.
    PhaseEnd {
        /// The phase.
        phase: Phase,
        /// Wall time in seconds.
        seconds: f64,
    },
    /// One Krylov–Schur restart finished.
    Iteration {
        /// Restart index (over all searches).
        restart: usize,
        /// Block solves so far.
        block_solves: usize,
        /// Wanted Ritz pairs converged so far.
        converged: usize,
        /// Ritz pairs wanted.
        wanted: usize,
    },
}

/// Errors of [`crate::solve`].
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EigenError {
    /// K and M have different or non-square shapes.
    #[error("matrix shape mismatch: K is {k_rows}x{k_cols}, M is {m_rows}x{m_cols}")]
    Shape {
        /// K rows.
        k_rows: usize,
        /// K columns.
        k_cols: usize,
        /// M rows.
        m_rows: usize,
        /// M columns.
        m_cols: usize,
    },
    /// The rigid fields have the wrong number of rows.
    #[error("rigid fields have {rows} rows, expected {expected}")]
    RigidShape {
        /// Rows given.
        rows: usize,
        /// Rows expected (DOFs).
        expected: usize,
    },
    /// NaN or infinity in an input.
    #[error("non-finite value in {matrix} at row {row}, column {col}")]
    NonFinite {
        /// "K", "M" or "rigid fields".
        matrix: &'static str,
        /// Row.
        row: usize,
        /// Column.
        col: usize,
    },
    /// An option is out of range.
    #[error("invalid option {name}: {reason}")]
    InvalidOption {
        /// Option name.
        name: &'static str,
        /// Why.
        reason: String,
    },
    /// `K − σM` with σ below the spectrum is not positive definite (M not positive definite,
    /// or K has negative eigenvalues: inverted or degenerate elements).
    #[error("K - sigma*M is not positive definite at pivot (DOF in elimination order) {pivot}; check M > 0 and for inverted elements")]
    NotPositiveDefinite {
        /// Pivot index in elimination order.
        pivot: usize,
    },
    /// A diagonal entry of M is not positive (M must be positive definite).
    #[error("mass matrix diagonal at DOF {dof} is not positive")]
    MassNotPositive {
        /// DOF index.
        dof: usize,
    },
    /// An indefinite LDLᵀ hit an exactly zero pivot.
    #[error("LDL^T of K - sigma*M hit a zero pivot at {pivot} (sigma = {shift:e})")]
    ZeroPivot {
        /// Pivot index.
        pivot: usize,
        /// Shift.
        shift: f64,
    },
    /// Estimated memory above the limit.
    #[error("{}", memory_limit_message(*estimated, *limit, *search_space, *modes))]
    MemoryLimit {
        /// Estimated bytes.
        estimated: u64,
        /// Limit in bytes.
        limit: u64,
        /// Of `estimated`, the search space's vectors [bytes], which grow
        /// with the number of modes asked for (the rest is the factor).
        search_space: u64,
        /// Modes asked for.
        modes: usize,
    },
    /// Iteration limit reached before all wanted modes converged.
    #[error("eigensolver did not converge: {converged} of {wanted} wanted modes converged")]
    NoConvergence {
        /// Converged.
        converged: usize,
        /// Wanted.
        wanted: usize,
    },
    /// A search gained no converged mode for [`crate::STALL_RESTARTS`] restarts in a row
    /// and was stopped early; `hint` says why and what to change.
    #[error("eigensolver stalled after {restarts} restarts: {converged} of {wanted} wanted modes converged, none more in the last {} restarts; {hint}", crate::STALL_RESTARTS)]
    Stalled {
        /// Converged.
        converged: usize,
        /// Wanted.
        wanted: usize,
        /// Restarts done over all searches.
        restarts: usize,
        /// Why it stalled and what to change (filled in by the driver).
        hint: String,
    },
    /// The Sylvester inertia count disagrees with the modes found, even after searching again.
    #[error("inertia check failed: {expected} eigenvalues below the check shift, {found} found")]
    InertiaMismatch {
        /// Count by Sylvester inertia.
        expected: usize,
        /// Count found.
        found: usize,
    },
    /// faer or METIS failed (out of memory, index overflow).
    #[error("sparse factorization failed: {0}")]
    Factorization(String),
}

/// What [`EigenError::MemoryLimit`] says: the remedy for what dominates the
/// estimate (a mesh's factor, or the vectors of too many modes when the
/// factor alone would fit).
fn memory_limit_message(estimated: u64, limit: u64, search_space: u64, modes: usize) -> String {
    let mb = |bytes: u64| bytes / 1_000_000;
    // Fewer modes help only when the rest (the factor) would fit.
    if search_space > estimated / 2 && estimated - search_space.min(estimated) <= limit {
        format!(
            "the search space for {modes} modes needs about {} MB (with the factorization {} MB) but the \
             limit is {} MB; ask for fewer modes",
            mb(search_space),
            mb(estimated),
            mb(limit)
        )
    } else {
        format!(
            "the factorization needs about {} MB but the limit is {} MB; use --order 1 or a coarser mesh",
            mb(estimated),
            mb(limit)
        )
    }
}
