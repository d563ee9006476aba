//! modal-eigen: the lowest modes of the generalized symmetric eigenproblem `K w = λ M w`.
//!
//! Input: stiffness K (positive semi-definite) and mass M (positive definite), n × n sparse in
//! full symmetric storage, 3 DOFs per node (DOF `3i + c` belongs to node `i`), SI units; raw
//! rigid-body fields to deflate. Output ([`EigenSolution`]): elastic eigenvalues λ = ω² in a
//! frequency band, M-orthonormal mode shapes, per-mode relative residuals and a Sylvester
//! inertia proof that no eigenvalue below the check shift was missed.
//!
//! Method: METIS nested-dissection ordering of the node graph, one symbolic Cholesky analysis
//! reused for every shift (it can be made from the pattern alone while K and M are assembled:
//! [`analyze`], [`solve_analyzed`]), a numeric Cholesky split over two cores along the
//! elimination tree, shift-invert around a shift scaled to the problem, restarted block
//! Krylov–Schur in the M-inner product with explicit rigid-mode deflation; its block solves
//! run on the Cholesky factor repacked into row tiles, split over two cores along the
//! elimination tree, its Gram–Schmidt products on row-major blocks (see [`solve`] and the
//! module docs of `krylov`, `factor`, `supernodal`, `tiled`, `cgs`, `ordering`).
//!
//! Reproducibility: for a given build and CPU the result is bit-identical whatever the
//! thread count (parallel work is split at fixed points) and whatever else runs in the
//! process (METIS calls, which share global state, take turns). Any change here that alters
//! results, even in the last bit, must bump `modal_precompute::SOLVER_VERSION` (cached banks
//! would otherwise differ from fresh solves, and scenes promise the same WAV either way).

mod block;
mod cgs;
mod factor;
mod krylov;
mod ordering;
mod simd;
mod solve;
mod supernodal;
#[cfg(test)]
mod test_support;
mod tiled;
mod types;

pub use factor::Analysis;
pub use krylov::{attainable as residual_bound, STALL_RESTARTS};
pub use solve::{analyze, default_memory_limit, solve, solve_analyzed, vector_bytes_per_dof};
pub use types::*;
