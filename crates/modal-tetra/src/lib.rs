//! `modal-tetra`: surface meshes (OBJ/STL/PLY/OFF/glTF) in, quality tet meshes out.
//!
//! Inputs: a triangle surface file in metres ([`read_surface`]; `scale`
//! multiplies, a unit warning points to `--scale`), possibly with holes,
//! flipped or inconsistently oriented triangles, duplicate vertices,
//! degenerate triangles, self-intersections or several parts.
//! Output: a [`modal_mesh::TetMesh`] of positively oriented tets with no
//! unused nodes, plus a [`TetReport`] (quality, volume, surface deviation).
//! By default ([`TetOptions::curved`]) the tets have 10 nodes and the
//! mid-edge nodes of boundary edges lie on the input surface; otherwise 4.
//!
//! Pipeline ([`tetrahedralize`]):
//! 1. [`diagnose`]: weld, drop degenerates, classify edges, orient triangles
//!    consistently per component, outward by signed volume ([`SurfaceReport`]),
//!    and put the surface in a canonical order (module `canonical`): the mesh
//!    depends on the geometry, not on the order of the file's triangles.
//! 2. Inside/outside: generalized winding number ≥ ½ (Jacobson et al. 2013)
//!    with a BVH dipole far field (module `bvh`).
//! 3. Isosurface stuffing on a BCC lattice of cell size h (Labelle & Shewchuk
//!    2007, module `stuff`): cut points on lattice edges at the exact surface
//!    crossing, lattice points near the surface snapped onto it, stencils clip
//!    lattice tets to the inside. Dihedral angles stay within [9°, 166°]
//!    (checked by the tests on every output).
//! 4. Hinges: small face-connected pieces that touch the rest only at an
//!    edge or a vertex are dropped ([`HINGED_DROP_FRACTION`]); larger ones
//!    get their own copies of the shared nodes (separate bodies), so no
//!    output tets are joined by an edge or a vertex only.
//! 5. Sharp features (module `features`): boundary nodes near sharp input
//!    edges and corners are moved onto them when quality allows; only edges
//!    in chains a cell can follow count, not a dense scan's noise (module
//!    `chains`).
//! 6. Curved boundary (module `curve`): 10-node tets, boundary mid-edge
//!    nodes moved to the closest surface point, guarded by a Jacobian check
//!    with a straight fallback per element ([`MIN_JACOBIAN_RATIO`]).
//!
//! Thin shells (module `shell`): when the cell would be at least
//! [`LAYERED_MIN_CELLS_PER_WALL`] wall thicknesses (2V/A), steps 3–5 are
//! replaced, if the surface is a shell (paired skins joined at rims), by one
//! layer of prisms across the wall, three tets each, with edges along the
//! wall of at most [`LAYERED_CELL_PER_WALL`] thicknesses (or `cell`), up to
//! [`LAYERED_STRAIGHT_CELL_PER_WALL`] along directions in which the wall of
//! a slender shell, curved across them, is straight (a chime's axis), and
//! where the wall is flat (a plate, a cymbal) up to
//! [`FLAT_CELLS_PER_WAVELENGTH`] edges per bending wavelength of the mode
//! half-way up the bank ([`TetOptions::resolved_modes`]; at least the
//! [`FLAT_RESOLVED_MODES`]-th) when that is longer; a solid that is no
//! shell (a handle, a thick foot) is stuffed as before. Open parts given
//! [`TetOptions::sheet_thickness`] become such shells first (module `thicken`).
//!
//! Resolution: [`TetOptions::cell`] (the BCC cube edge h), else
//! [`TetOptions::target_tets`], else
//! h = min(max(diagonal / 25, (12 V / 12 000)^⅓), 2V/A / 1.5)
//! (V enclosed volume, A area: 2V/A is the wall thickness of a thin shell;
//! the middle term, [`DEFAULT_MAX_TETS`], keeps compact solids from getting
//! far more tets than their first modes need).
//! A sphere gets ≈ 12 k tets; the enclosed volume is met within 0.5 %.
//!
//! Failure modes are typed ([`TetraError`]), never panics: unreadable or
//! malformed files, NaN coordinates, out-of-range indices, no triangles, an
//! unknown part, bad options, a resolution above [`TetOptions::max_tets`],
//! or a surface enclosing nothing at the chosen cell size. The third-party
//! parsers additionally run under `catch_unwind` (a parser panic becomes a
//! [`TetraError::Parse`]; the default panic hook may still print it).

mod bvh;
mod canonical;
mod chains;
mod coarsen;
mod coincident;
pub mod corpus;
mod curve;
mod diagnose;
mod error;
mod features;
mod geom;
mod graded;
mod lattice;
mod mesher;
mod nesting;
mod pairing;
mod read;
mod rescue;
mod second_try;
pub mod shapes;
mod shell;
mod sizing;
mod smooth;
mod stuff;
mod surface;
mod thicken;
mod tjunction;
mod wall_rule;

pub use chains::MIN_CHAIN_FRACTION;
pub use curve::{MAX_BULGE, MIN_JACOBIAN_RATIO};
pub use diagnose::{diagnose, SurfaceReport};
pub use error::TetraError;
pub use features::{FEATURE_ANGLE_DEG, GUARD_DEG, SNAP_FRACTION};
pub use geom::dihedral_angles_deg;
pub use graded::MAX_LEVELS;
pub use mesher::{
    tetrahedralize, TetOptions, TetReport, DEFAULT_CELLS_PER_DIAGONAL, DEFAULT_CELLS_PER_THICKNESS,
    DEFAULT_MAX_TETS, GAP_WARNING, HINGED_DROP_FRACTION, LAYERED_CELL_PER_WALL, LAYERED_MIN_CELLS_PER_WALL,
    LAYERED_STRAIGHT_CELL_PER_WALL, VOLUME_KEPT_WARNING,
};
pub use read::{gltf_buffers, gltf_uri_buffers, parse_surface, read_surface, SurfaceFormat};
pub use sizing::{CONE_DEG, GRADING};
pub use stuff::{ALPHA_LONG, ALPHA_SHORT};
pub use surface::{write_obj, TriSurface};
pub use thicken::MAX_MITRE;
pub use wall_rule::{FLAT_CELLS_PER_WAVELENGTH, FLAT_RESOLVED_MODES};

/// Bounds every uniform output of [`tetrahedralize`] is tested against (degrees).
pub const DIHEDRAL_BOUNDS_DEG: (f64, f64) = (9.0, 166.0);

/// Bounds the graded tests ([`TetOptions::graded`], background refined
/// below the lattice cell) check (degrees). The paper's α values are tuned
/// for the BCC tet; on bisected tets they give flatter pieces: 3.5°–172.4°
/// were seen on rotated test shapes, which is why grading is opt-in.
pub const GRADED_DIHEDRAL_BOUNDS_DEG: (f64, f64) = (3.0, 175.0);
