//! `modal-radiation`: what a listener hears of each mode — per-mode
//! acoustic transfer by a boundary-element solve.
//!
//! Input: a closed triangulated surface (one or more bodies, outward
//! triangles; a bank's surface) and, per mode, the normal surface velocity
//! at the mode's frequency. Output: the surface pressure ([`SurfaceField`]),
//! pressure anywhere in the air, radiated power and radiation efficiency,
//! and a compact outgoing [`Multipole`] expansion about the centre of mass
//! with its order chosen to a stated error.
//!
//! Method ([`bem`]): exterior Neumann Helmholtz problem, time convention
//! `e^{−iωt}`, the conventional equation below the body's lowest interior
//! resonance (a rigorous bound on it, [`resonance`]) and Burton–Miller above (no
//! fictitious interior resonances), constant flat panels with centroid collocation, dense
//! complex LU (faer, sequential) for small systems and restarted GMRES
//! ([`gmres`]) for large ones, rayon row assembly: results are
//! bit-identical for any thread count.
//!
//! - [`BoundaryMesh`]: panels, inside test;
//! - [`solve`]: surface pressure for several velocity fields at one frequency;
//! - [`cluster`]: fewer pressure unknowns where the wavelength allows ([`solve_clustered`]);
//! - [`hmatrix`]: the system compressed (far blocks low rank by ACA) for large solves;
//! - [`near`]: the geometry-only part of the near panel integrals, once per mesh ([`Discretization`]);
//! - [`multipole::fit`]: the far-field representation;
//! - [`radiate_modes`]: every requested mode of a `modal_bank::ModeBank`;
//! - [`precond`]: the block-Jacobi preconditioner of the GMRES solves;
//! - [`normals`]: smooth-surface node normals fitted to the local surface, never across creases;
//! - [`mfs`]: equivalent sources, the independent method of the cross-checks;
//! - [`continuous`]: Burton–Miller with a continuous pressure in its hypersingular term (a dense study: not better at practical sizes; not used by the solves);
//! - [`screen`]: an open screen's pressure jump by Galerkin (the thin-wall probe; not used by the solves);
//! - [`resonance`]: a lower bound on the body's lowest interior resonance (where the conventional equation is safe);
//! - [`walls`]: how much of a surface is a wall thinner than its panels;
//! - [`special`]: spherical Hankel functions and spherical harmonics;
//!
//! The reference sphere surface of the tests is `modal_mesh::icosphere`.

#![warn(missing_docs)]

mod aca;
pub mod assembly;
mod batch;
pub mod bem;
pub mod cluster;
pub mod continuous;
mod error;
pub mod geometry;
pub mod gmres;
pub mod hmatrix;
pub mod kernels;
pub mod lowrank;
pub mod mfs;
pub mod modes;
pub mod multipole;
pub mod near;
pub mod normals;
pub mod precond;
pub mod quadrature;
pub mod refine;
pub mod resonance;
pub mod screen;
mod sincos;
pub mod special;
mod velocity;
pub mod walls;

pub use bem::{solve, solve_clustered, solve_on, Air, Discretization, Formulation, SolverPath, SurfaceField};
pub use cluster::{Adjacency, Clusters};
pub use error::RadiationError;
/// Complex f64 (`num_complex::Complex<f64>`), the amplitude type of every field.
pub use faer::c64;
pub use geometry::{BoundaryMesh, Panel};
pub use modes::{radiate_modes, ModeRadiation, Progress, RadiationOptions};
pub use multipole::Multipole;
pub use near::NearField;
