//! Errors of the radiation solve.

use thiserror::Error;

/// What can go wrong in a radiation solve.
#[derive(Debug, Error, PartialEq)]
pub enum RadiationError {
    /// The surface has no triangles.
    #[error("the surface has no triangles")]
    EmptySurface,
    /// A surface position is NaN or infinite.
    #[error("surface vertex {vertex} has a non-finite position")]
    NonFinitePosition {
        /// Vertex index.
        vertex: usize,
    },
    /// A triangle names a vertex that does not exist.
    #[error("surface triangle {triangle} names a vertex that does not exist")]
    BadTriangle {
        /// Triangle index.
        triangle: usize,
    },
    /// A triangle has (numerically) zero area.
    #[error("surface triangle {triangle} has zero area")]
    DegenerateTriangle {
        /// Triangle index.
        triangle: usize,
    },
    /// A frequency is not finite and positive.
    #[error("frequency {0} Hz is not finite and positive")]
    BadFrequency(f64),
    /// Air density or sound speed is not finite or outside the ranges of
    /// gases and liquids ([`crate::bem::DENSITY_RANGE_KG_M3`],
    /// [`crate::bem::SOUND_SPEED_RANGE_M_S`]).
    #[error(
        "air density {} kg/m³ and sound speed {} m/s must lie within {} – {} kg/m³ and {} – {} m/s \
         (gases and liquids)",
        modal_mesh::readable(*density),
        modal_mesh::readable(*speed),
        crate::bem::DENSITY_RANGE_KG_M3.0,
        crate::bem::DENSITY_RANGE_KG_M3.1,
        crate::bem::SOUND_SPEED_RANGE_M_S.0,
        crate::bem::SOUND_SPEED_RANGE_M_S.1
    )]
    BadAir {
        /// Density [kg/m³].
        density: f64,
        /// Sound speed [m/s].
        speed: f64,
    },
    /// A normal-velocity field has the wrong length or is not finite.
    #[error("velocity field {field} has {got} values or non-finite ones, expected {expected} finite values")]
    BadVelocity {
        /// Field index.
        field: usize,
        /// Values given.
        got: usize,
        /// Panels of the mesh.
        expected: usize,
    },
    /// The mode has no surface velocity to radiate.
    #[error("mode {mode} has no normal surface velocity (all zero): nothing radiates")]
    NoSurfaceVelocity {
        /// Mode index in the bank.
        mode: usize,
    },
    /// A field point lies inside the vibrating body.
    #[error("point ({x:?}, {y:?}, {z:?}) lies inside the body: pressure is only defined outside it")]
    PointInsideBody {
        /// x [m].
        x: f64,
        /// y [m].
        y: f64,
        /// z [m].
        z: f64,
    },
    /// A field point lies on the surface, or closer to it than the
    /// representation formula is accurate
    /// ([`crate::geometry::ON_SURFACE_RATIO`]).
    #[error(
        "point ({x:?}, {y:?}, {z:?}) lies on the body's surface ({} m from it): pressure is evaluated only \
         in the air; move the point at least {} m away from the surface",
        metres(*.distance_m),
        metres(*.tolerance_m)
    )]
    PointOnSurface {
        /// x [m].
        x: f64,
        /// y [m].
        y: f64,
        /// z [m].
        z: f64,
        /// Distance to the nearest panel [m].
        distance_m: f64,
        /// Distance the point must keep from the surface [m].
        tolerance_m: f64,
    },
    /// A field point so far away that f64 distances no longer resolve the
    /// body ([`crate::geometry::MAX_FIELD_COORDINATE_M`]).
    #[error(
        "point ({x:?}, {y:?}, {z:?}) m is out of range: each coordinate must be within ±{max_m:e} m (farther, \
         the distances lose the body's size to rounding; the far field is p·r = const)"
    )]
    PointOutOfRange {
        /// x [m].
        x: f64,
        /// y [m].
        y: f64,
        /// z [m].
        z: f64,
        /// The largest coordinate magnitude accepted [m].
        max_m: f64,
    },
    /// The dense solve failed (singular system).
    #[error("the boundary-element system at {frequency_hz} Hz is singular")]
    Singular {
        /// Frequency [Hz].
        frequency_hz: f64,
    },
    /// GMRES did not converge on a system too large for the dense fallback
    /// (a full-resolution solve above [`crate::modes::MAX_DENSE_PANELS`]).
    #[error(
        "the boundary-element system at {frequency_hz} Hz ({unknowns} unknowns) did not converge, and is too \
         large for the dense solve ({max}): drop --full-resolution"
    )]
    NotConverged {
        /// Frequency [Hz].
        frequency_hz: f64,
        /// Unknowns of the system.
        unknowns: usize,
        /// The dense solve's limit.
        max: usize,
    },
    /// The surface turns too sharply between neighbouring panels for its
    /// pressure to be grouped into few enough unknowns.
    #[error(
        "at {frequency_hz:.0} Hz the surface cannot be grouped into {max} pressure unknowns: its neighbouring \
         panels turn too sharply (a rough or spiky mesh); --full-resolution solves it with one unknown per panel, \
         or smooth the mesh"
    )]
    TooRuggedToCluster {
        /// Frequency [Hz].
        frequency_hz: f64,
        /// Most unknowns of a clustered solve.
        max: usize,
    },
    /// The system would hold more memory than the guard allows
    /// ([`crate::modes::RadiationOptions::memory_limit_bytes`]).
    #[error(
        "the boundary-element system at {frequency_hz:.0} Hz ({unknowns} unknowns) needs more than the memory \
         limit of {:.2} GB (MODAL_MEMORY_LIMIT_GB, or 75 % of the available memory): solve the lower modes \
         only (--max-freq), drop --full-resolution if it was given, or free memory",
        *limit_bytes as f64 / 1e9
    )]
    OutOfMemory {
        /// Frequency [Hz].
        frequency_hz: f64,
        /// Unknowns of the system.
        unknowns: usize,
        /// Bytes held when the solve stopped (a lower bound of the need).
        needed_bytes: u64,
        /// The limit [bytes].
        limit_bytes: u64,
    },
    /// The surface has more panels than a solve with one unknown per panel takes.
    #[error(
        "the surface has {panels} panels, more than the {max} unknowns a full-resolution solve takes: drop \
         --full-resolution, or mesh the object coarser (--cell for a surface mesh, --h for a generated one)"
    )]
    TooManyPanels {
        /// Panels of the solve.
        panels: usize,
        /// The limit.
        max: usize,
    },
    /// A screen has more interior nodes than one dense screen solve takes.
    #[error("the screen has {unknowns} interior nodes, more than the {max} of one dense screen solve")]
    ScreenTooLarge {
        /// Interior nodes (unknowns) of the screen.
        unknowns: usize,
        /// The limit ([`crate::screen::MAX_SCREEN_UNKNOWNS`]).
        max: usize,
    },
    /// Refining the creases made more panels than a full-resolution solve takes.
    #[error(
        "{rounds} round(s) of crease refinement make {panels} panels, more than the {max} unknowns a \
         full-resolution solve takes: use fewer --refine-creases rounds"
    )]
    TooManyRefinedPanels {
        /// Panels after the refinement.
        panels: usize,
        /// The limit.
        max: usize,
        /// Rounds of refinement asked for.
        rounds: usize,
    },
    /// A mode index is out of range.
    #[error("mode {mode} does not exist (the bank has {count})")]
    NoSuchMode {
        /// Requested mode.
        mode: usize,
        /// Modes in the bank.
        count: usize,
    },
    /// The bank's surface or shapes are unusable.
    #[error("bank surface: {0}")]
    Bank(String),
}

/// A length for an error line: `0` exactly, else three significant digits.
fn metres(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.2e}")
    }
}
