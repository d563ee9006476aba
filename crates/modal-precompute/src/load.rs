//! Stage 1–2: get a checked tet mesh from a file (tet or surface mesh) or memory.

use std::path::{Path, PathBuf};

use modal_mesh::TetMesh;

use crate::PrecomputeError;

/// Where the geometry comes from.
#[derive(Clone, Debug)]
pub enum MeshSource {
    /// A tet mesh (.msh, .node/.ele, .mesh) or surface mesh (.obj, .stl, .ply).
    File(PathBuf),
    /// A mesh built in memory (e.g. by a generator), with a text that
    /// identifies it uniquely for the cache (e.g. the generator parameters).
    Memory {
        /// The mesh, coordinates in metres (before `scale`).
        mesh: TetMesh,
        /// Identity of the mesh for the cache key.
        identity: String,
    },
}

/// Options for filling a surface mesh with tets.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceMeshing {
    /// Lattice cell size [m]; `None` picks the documented default.
    pub cell: Option<f64>,
    /// Object of a multi-object surface file; `None` meshes all as one body.
    pub part: Option<String>,
    /// Wall thickness [m] given to open parts (sheets modelled as one
    /// surface): `modal_tetra::TetOptions::sheet_thickness`.
    pub sheet_thickness: Option<f64>,
    /// Flat walls are sized to resolve this many modes
    /// (`modal_tetra::TetOptions::resolved_modes`); `None`: the mesher's
    /// default, or, through a [`crate::Request`], its mode count.
    pub resolved_modes: Option<usize>,
}

impl SurfaceMeshing {
    /// The mesher options these settings stand for.
    pub fn tet_options(&self) -> modal_tetra::TetOptions {
        let defaults = modal_tetra::TetOptions::default();
        modal_tetra::TetOptions {
            cell: self.cell,
            sheet_thickness: self.sheet_thickness,
            resolved_modes: self.resolved_modes.unwrap_or(defaults.resolved_modes),
            ..defaults
        }
    }
}

/// A checked tet mesh and what was found on the way.
#[derive(Clone, Debug)]
pub struct LoadedMesh {
    /// The mesh: positively oriented, unused nodes dropped, metres.
    pub mesh: TetMesh,
    /// Number of connected parts.
    pub parts: usize,
    /// Connected part of every node.
    pub part_of_node: Vec<usize>,
    /// Things the user should know (reoriented tets, dropped nodes, unit hints).
    pub warnings: Vec<String>,
    /// The tetrahedralizer's cell size [m] (`TetReport::cell_m`) for a surface
    /// mesh; `None` for a tet mesh.
    pub cell_m: Option<f64>,
    /// The surface was meshed in layers across a thin wall (`TetReport::wall_layers` > 0).
    pub layered: bool,
    /// Separate bodies of the input surface (its components, a hollow body's
    /// inner wall not counted); `None` for a tet mesh.
    pub surface_bodies: Option<usize>,
    /// The tet mesh's volume over the volume its surface encloses (a part
    /// thinner than the cells is lost); `None` for a tet mesh or a surface
    /// enclosing no volume (a sheet).
    pub volume_kept: Option<f64>,
}

/// How a discretization level (`crate::levels`) sizes a surface mesh's tets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum LevelSize {
    /// The tetrahedralizer's cell [m]: a stuffed solid's whole sizing field scales with it.
    Cell(f64),
    /// Every default size times this factor (`TetOptions::size_factor`): a thin
    /// shell meshed in layers, whose edges along a slender wall's axis are
    /// longer than around it (an explicit cell would make them one size, and
    /// the coarser level of a chime the same mesh as the finer).
    Factor(f64),
}

impl LevelSize {
    /// This level's size scaled by `factor`.
    pub(crate) fn scaled(self, factor: f64) -> LevelSize {
        match self {
            LevelSize::Cell(c) => LevelSize::Cell(c * factor),
            LevelSize::Factor(f) => LevelSize::Factor(f * factor),
        }
    }
}

/// The memory a surface's 10-node tets may take, known before meshing.
///
/// The solve holds K and M, at least
/// [`modal_fem::min_quadratic_matrices_bytes`] (270 stored entries a tet, whatever
/// the mesh), the factor of `K − σM`, at least the lower triangle of that
/// pattern (135 values of 8 bytes a tet), and the eigensolver's dense vectors for
/// at least 3 DOF a tet: all lower bounds, so a mesh refused here
/// could not have been solved within the limit, and it is refused in a second
/// instead of after minutes of meshing and assembly (a thin bowl at a 1.2 mm cell:
/// 1.6 M tets in 23 s, then refused for the matrices' 23 GB).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TetBudget {
    /// The memory guard [bytes].
    pub limit_bytes: u64,
    /// The eigensolver's dense vectors per DOF [bytes] ([`modal_eigen::vector_bytes_per_dof`]);
    /// a 10-node tet mesh has at least 3 DOF per tet (a node per edge, and E ≥ T).
    pub vector_bytes_per_dof: u64,
}

impl TetBudget {
    /// Bytes of the factor's values a 10-node tet brings at least (see the type doc).
    const FACTOR_BYTES_PER_TET: u64 = 9 * modal_fem::MIN_NODE_PAIRS_PER_QUADRATIC_TET * 8;

    /// The fewest bytes a solve of `tets` 10-node tets holds.
    fn min_bytes(&self, tets: u64) -> u64 {
        modal_fem::min_quadratic_matrices_bytes(tets)
            + Self::FACTOR_BYTES_PER_TET * tets
            + 3 * self.vector_bytes_per_dof * tets
    }

    /// The most tets whose solve can fit.
    pub(crate) fn max_tets(&self) -> usize {
        usize::try_from(self.limit_bytes / self.min_bytes(1).max(1)).unwrap_or(usize::MAX)
    }

    fn refusal(&self, estimated: u64) -> PrecomputeError {
        let needed_bytes = self.min_bytes(estimated);
        let vectors = 3 * self.vector_bytes_per_dof * estimated;
        PrecomputeError::Memory {
            message: format!(
                "the surface would be meshed into about {estimated} tets, whose stiffness, mass, factor and the \
                 eigensolver's vectors need at least {:.1} GB, above the memory limit of {:.1} GB; {}",
                needed_bytes as f64 / 1e9,
                self.limit_bytes as f64 / 1e9,
                crate::pipeline::memory_remedy(vectors, needed_bytes, self.limit_bytes, "a larger --cell")
            ),
            needed_bytes,
            limit_bytes: self.limit_bytes,
        }
    }
}

/// True for file types that hold a surface to be tetrahedralized: the formats
/// `modal_tetra` reads ([`modal_tetra::SurfaceFormat::from_path`]).
pub fn is_surface_file(path: &Path) -> bool {
    modal_tetra::SurfaceFormat::from_path(path).is_some()
}

/// The factor applied to a mesh file's coordinates (0.001 for millimetres),
/// and whether the caller stated it. Files carry no unit, so a file whose
/// object would be larger than [`modal_mesh::LARGEST_PLAIN_DIAGONAL_M`] under
/// an unstated scale is refused before any work as a file in another unit
/// ([`modal_mesh::unstated_size_refusal`]); a stated scale takes any size as meant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale {
    /// Factor applied to all coordinates.
    pub factor: f64,
    /// The caller stated `factor` (a flag, a manifest's or a scene's key).
    pub stated: bool,
}

impl Scale {
    /// True when `warning` is the unit warning of an object `diagonal_m` across and
    /// this scale was stated: the user said which unit the file is in.
    fn answers(&self, warning: &str, diagonal_m: f64) -> bool {
        self.stated && modal_mesh::unit_warning(diagonal_m).is_some_and(|w| w == warning)
    }

    /// The refusal of an object `diagonal_m` across under this scale, if any.
    fn check(&self, diagonal_m: f64) -> Result<(), PrecomputeError> {
        match modal_mesh::unstated_size_refusal(diagonal_m).filter(|_| !self.stated) {
            Some(message) => Err(PrecomputeError::Invalid(message)),
            None => Ok(()),
        }
    }
}

/// Loads, (tetrahedralizes,) scales and checks a mesh.
pub fn load_mesh(
    source: &MeshSource,
    scale: Scale,
    surface: &SurfaceMeshing,
) -> Result<LoadedMesh, PrecomputeError> {
    load_mesh_sized(source, scale, surface, None, None)
}

/// [`load_mesh`] with a surface mesh's tets sized by `level` when given (the
/// discretization levels of `crate::levels`), refused before meshing when the
/// tetrahedralizer estimates more than `budget`'s tets. Tet meshes are not touched.
pub(crate) fn load_mesh_sized(
    source: &MeshSource,
    scale: Scale,
    surface: &SurfaceMeshing,
    level: Option<LevelSize>,
    budget: Option<TetBudget>,
) -> Result<LoadedMesh, PrecomputeError> {
    let factor = scale.factor;
    if let Some(why) = modal_mesh::scale_refusal(factor) {
        return Err(PrecomputeError::Invalid(format!("--scale {why}")));
    }
    let mut warnings = Vec::new();
    let (mut cell_m, mut layered, mut surface_bodies, mut volume_kept) = (None, false, None, None);
    let raw = match source {
        MeshSource::File(path) if is_surface_file(path) => {
            let (surf, mut report) = modal_tetra::read_surface(path, factor, surface.part.as_deref())?;
            scale.check(report.diagonal_m)?;
            surface_bodies = Some(report.components.saturating_sub(report.cavities).max(1));
            if surface.sheet_thickness.is_some() {
                report.drop_open_warning();
            }
            warnings.extend(report.warnings.iter().filter(|w| !scale.answers(w, report.diagonal_m)).cloned());
            let mut options = surface.tet_options();
            match level {
                Some(LevelSize::Cell(c)) => options.cell = Some(c),
                Some(LevelSize::Factor(f)) => options.size_factor = f,
                None => {}
            }
            if let Some(budget) = budget {
                options.max_tets = options.max_tets.min(budget.max_tets());
            }
            let (mesh, tet_report) =
                modal_tetra::tetrahedralize(&surf, &options).map_err(|e| match (e, budget) {
                    (modal_tetra::TetraError::TooManyTets { estimated, .. }, Some(b))
                        if estimated > b.max_tets() as u64 =>
                    {
                        b.refusal(estimated)
                    }
                    (e, _) => e.into(),
                })?;
            warnings.extend(tet_report.warnings);
            cell_m = Some(tet_report.cell_m);
            layered = tet_report.wall_layers > 0;
            // As the mesher measured it (and warns when it is small).
            volume_kept = (tet_report.surface_volume_m3 > 0.0)
                .then(|| tet_report.volume_m3 / tet_report.surface_volume_m3);
            mesh
        }
        MeshSource::File(path) => {
            // Surface meshing options do not apply to a tet mesh: say so rather than drop them.
            let ignored: Vec<&str> = [
                (surface.cell.is_some(), "--cell"),
                (surface.part.is_some(), "--part"),
                (surface.sheet_thickness.is_some(), "--sheet-thickness"),
            ]
            .into_iter()
            .filter_map(|(given, name)| given.then_some(name))
            .collect();
            if !ignored.is_empty() {
                warnings.push(format!(
                    "{} appl{} to surface meshes only: {} is a tet mesh, used as it is",
                    ignored.join(", "),
                    if ignored.len() == 1 { "ies" } else { "y" },
                    path.display()
                ));
            }
            let mesh = modal_mesh::read_mesh(path, factor)?;
            let diagonal_m = modal_mesh::bounding_diagonal(&mesh.nodes);
            scale.check(diagonal_m)?;
            warnings.extend(modal_mesh::unit_warning(diagonal_m).filter(|w| !scale.answers(w, diagonal_m)));
            mesh
        }
        MeshSource::Memory { mesh, .. } => {
            let mut mesh = mesh.clone();
            mesh.nodes.iter_mut().flatten().for_each(|x| *x *= factor);
            mesh
        }
    };
    let (mesh, report) = modal_mesh::check(raw)?;
    warnings.extend(report.warnings.iter().cloned());
    let (parts, part_of_node) = modal_mesh::connected_parts(&mesh);
    Ok(LoadedMesh { mesh, parts, part_of_node, warnings, cell_m, layered, surface_bodies, volume_kept })
}
