//! The tetrahedralizer: options, report and the pipeline
//! repair → winding-number BVH → BCC lattice → isosurface stuffing → checks.

use modal_mesh::{Cells, DisjointSets, TetMesh};
use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::curve::curve;
use crate::diagnose::repair;
use crate::diagnose::Repaired;
use crate::features::{features, snap};
use crate::geom::{dihedral_angles_deg, orient6, V3};
use crate::graded::MAX_LEVELS;
use crate::lattice::Lattice;
use crate::rescue::{clear, lost, mesh_alone, parts, specks, specks_warning, triangles_outside, Part};
use crate::second_try::Smoothed;
use crate::shell::{layered, LayerSizing, Layered, NotLayered};
use crate::sizing::{surface_gap, Sizing};
use crate::stuff::{background, stuff, Stuffed};
use crate::thicken::thicken_open_sheets;
use crate::{TetraError, TriSurface};

/// Default resolution: cell size = bounding-box diagonal / this, and at most
/// [`DEFAULT_CELLS_PER_THICKNESS`]⁻¹ of the mean thickness 2V/A.
///
/// On a sphere this gives ≈ 19.5 k tets and a volume 0.5 % below the
/// polyhedron's; with 10-node tets the first 27 Lamb modes are expected
/// within ≈ 1 % (an estimate, to be confirmed by the accuracy study).
pub const DEFAULT_CELLS_PER_DIAGONAL: f64 = 25.0;

/// Default: at least this many cells across the mean wall thickness 2V/A
/// (V enclosed volume, A surface area; 2V/A is the wall thickness of a thin
/// shell and 2/3 of the radius of a ball), so thin shells are not too coarse.
pub const DEFAULT_CELLS_PER_THICKNESS: f64 = 1.5;

/// Default: the cell grows (never beyond the thickness bound) until the solid
/// holds at most about this many tets (12 per cube of h³).
///
/// diagonal / 25 suits slender and thin objects, but a compact solid fills
/// its bounding box: the corpus box ("soup") got 163 k DOF, 95 s and 5.1 GB
/// at diagonal / 25 (release build, load 9 on 2 cores), and still 101 k DOF
/// and 41 s with a 20 k cap, for first-10-mode errors of 0.00 % against its
/// converged reference, far below the 1 % the accuracy target asks. A
/// sphere (≈ 18.9 k tets at diagonal / 25) gets cells 1.16 × larger. The
/// per-mode error estimate (and `--accuracy`, which refines when it is
/// missed) checks the coarser default.
pub const DEFAULT_MAX_TETS: usize = 12_000;

/// Tetrahedralization options. Resolution: `cell` wins over `target_tets`;
/// with neither, `cell = diagonal / cells_per_diagonal`.
#[derive(Clone, Debug, PartialEq)]
pub struct TetOptions {
    /// BCC cube edge h (m); tets have edges of about 0.87 h to h.
    pub cell: Option<f64>,
    /// Aim for about this many tets (the cell size is derived from the
    /// enclosed volume: one cube of h³ holds 12 tets).
    pub target_tets: Option<usize>,
    /// Cells per bounding-box diagonal when neither `cell` nor `target_tets` is set.
    pub cells_per_diagonal: f64,
    /// Minimum cells across the mean thickness 2V/A in that default case.
    pub cells_per_thickness: f64,
    /// Refuse resolutions estimated to give more tets than this (also
    /// bounds the lattice: at most this many cubes; default 2 M).
    pub max_tets: usize,
    /// Move boundary nodes onto sharp input edges and corners (see
    /// [`crate::FEATURE_ANGLE_DEG`]), keeping the quality bound.
    pub preserve_features: bool,
    /// Output 10-node tets whose boundary mid-edge nodes lie on the input
    /// surface (module `curve`; default); `false` gives the 4-node tets.
    /// The corner tets are the same either way.
    pub curved: bool,
    /// Grade the mesh by the local thickness (opt-in; default `false` until
    /// its quality is fixed: measured dihedral angles 3.5°–172.4° on the test
    /// shapes, against 9°–166° uniform): the lattice cell is
    /// the bulk size (`cell`, else diagonal / `cells_per_diagonal`) and is
    /// refined by bisection (module `graded`) down to thickness /
    /// `cells_per_thickness` near thin walls, handles and legs (module
    /// `sizing`), growing back by [`crate::GRADING`] per unit distance. The
    /// whole field scales with `cell` (relative to the default bulk size)
    /// and with `size_factor`. `false` (default): one uniform cell,
    /// min(bulk, 2V/A / `cells_per_thickness`) when no `cell` is given.
    pub graded: bool,
    /// With neither `cell` nor `target_tets`: coarsen the cell until the
    /// solid holds about this many tets, within the thickness bound
    /// (default [`DEFAULT_MAX_TETS`]; `usize::MAX` turns it off).
    pub default_max_tets: usize,
    /// Multiplies every element size the other fields give (default 1):
    /// 2 coarsens the whole mesh by two, ½ refines it (two-level error
    /// estimates use it).
    pub size_factor: f64,
    /// Give every open part (a component with a boundary edge) this wall
    /// thickness [m] before meshing: a sheet modelled as one surface (a
    /// cymbal, a sign) becomes a closed shell (module `thicken`). `None`
    /// (default): open parts are filled as their winding number encloses.
    pub sheet_thickness: Option<f64>,
    /// The modes the bank keeps: a flat layered wall (a plate, a cymbal) gets
    /// edges of a twelfth of the bending wavelength of the half of them
    /// (module `wall_rule`); below twice [`crate::FLAT_RESOLVED_MODES`] the
    /// plate is sized for that many (default), so only a bank of more than 128
    /// modes gets a finer plate.
    pub resolved_modes: usize,
}

impl Default for TetOptions {
    fn default() -> Self {
        TetOptions {
            cell: None,
            target_tets: None,
            cells_per_diagonal: DEFAULT_CELLS_PER_DIAGONAL,
            cells_per_thickness: DEFAULT_CELLS_PER_THICKNESS,
            max_tets: 2_000_000,
            preserve_features: true,
            curved: true,
            graded: false,
            default_max_tets: DEFAULT_MAX_TETS,
            size_factor: 1.0,
            sheet_thickness: None,
            resolved_modes: crate::FLAT_RESOLVED_MODES,
        }
    }
}

impl TetOptions {
    /// The fields that change the output mesh, as `key=value` pairs joined by
    /// `;`, plus the algorithm version; meant for the pipeline's cache key.
    pub fn cache_key_fields(&self) -> String {
        // Fields added later appear only when set, so older keys stay valid.
        let sheet = self.sheet_thickness.map(|t| format!(";sheet_thickness={t}")).unwrap_or_default();
        // Only the mode that sizes a flat wall changes the mesh.
        let sized = crate::wall_rule::flat_sized_mode(self.resolved_modes);
        let modes = if sized > crate::FLAT_RESOLVED_MODES {
            format!(";flat_sized_mode={sized}")
        } else {
            String::new()
        };
        format!(
            "tetra=stuffing-v15;cell={:?};target_tets={:?};cells_per_diagonal={};cells_per_thickness={};features={};curved={};graded={};default_max_tets={};size_factor={}",
            self.cell,
            self.target_tets,
            self.cells_per_diagonal,
            self.cells_per_thickness,
            self.preserve_features,
            self.curved,
            self.graded,
            self.default_max_tets,
            self.size_factor
        ) + &sheet
            + &modes
    }
}

/// Below this fraction of the volume the surface encloses kept by the tet
/// mesh, a warning says how much of the object is missing (ordinary assets
/// keep 97–100 %).
pub const VOLUME_KEPT_WARNING: f64 = 0.9;

/// What the tetrahedralizer produced.
#[derive(Clone, Debug, PartialEq)]
pub struct TetReport {
    /// Number of tets.
    pub tets: usize,
    /// Number of nodes.
    pub nodes: usize,
    /// Cell size h of the lattice (m): the bulk size of a graded mesh.
    pub cell_m: f64,
    /// Shortest edge of the background mesh after grading (m); on the
    /// uniform lattice it is the red edge √3/2 × `cell_m`.
    pub min_cell_m: f64,
    /// Surface samples whose local thickness asked for cells finer than
    /// `cell_m` (0 when not graded).
    pub thin_samples: usize,
    /// Smallest local thickness found (m), if any sample was thin.
    pub min_thickness_m: Option<f64>,
    /// Smallest dihedral angle over all (corner) tets (degrees).
    pub min_dihedral_deg: f64,
    /// Largest dihedral angle over all tets (degrees).
    pub max_dihedral_deg: f64,
    /// Tet mesh volume (m³), exact for curved 10-node tets.
    pub volume_m3: f64,
    /// Volume enclosed by the (repaired) input surface (m³).
    pub surface_volume_m3: f64,
    /// Largest distance from a boundary node of the mesh (corner or
    /// mid-edge) to the input surface (m).
    pub max_surface_deviation_m: f64,
    /// Largest distance from the input surface (where it bounds the solid)
    /// to the mesh boundary (m): parts lost because they are thinner than
    /// the cells show here. Above [`GAP_WARNING`] × the diagonal, a warning
    /// names the place.
    pub max_surface_gap_m: f64,
    /// Boundary mid-edge nodes placed on the input surface (0 when not `curved`).
    pub curved_edges: usize,
    /// Elements whose boundary edges were left straight because curving
    /// them would make det J too small (see `curve::MIN_JACOBIAN_RATIO`).
    pub straightened_elements: usize,
    /// Zero-volume slivers dropped by the stencils (expected 0).
    pub dropped_degenerate: usize,
    /// Boundary nodes moved onto sharp input edges and corners.
    pub feature_nodes_snapped: usize,
    /// Small pieces that hung on a larger one by an edge or a vertex only
    /// (zero-stiffness hinges) and were dropped (see [`HINGED_DROP_FRACTION`]).
    pub hinged_pieces_dropped: usize,
    /// Tets in those pieces.
    pub hinged_tets_dropped: usize,
    /// Contacts between larger pieces through edges or vertices only, split
    /// so that the pieces are separate bodies (node copies).
    pub hinges_split: usize,
    /// Tet layers across the wall when the surface was meshed as a thin
    /// shell (module `shell`: prisms between paired skins; `cell_m` is then
    /// the longest edge along the wall and `min_thickness_m` the median
    /// wall); 0 when stuffed.
    pub wall_layers: usize,
    /// Open parts given [`TetOptions::sheet_thickness`] (0 without it).
    pub sheets_thickened: usize,
    /// What the user should know about the mesh (one line each).
    pub warnings: Vec<String>,
}

/// A face-connected piece of the stuffed mesh that touches a larger piece
/// only at edges or vertices is dropped when it holds at most this fraction
/// of all tets: such pieces are lattice artefacts where the solid is thinner
/// than the cell, and would be zero-stiffness mechanisms. Larger hinged
/// pieces are kept as separate bodies (their shared nodes are duplicated).
pub const HINGED_DROP_FRACTION: f64 = 0.01;

struct HingedDrop {
    pieces: usize,
    tets: usize,
    split: usize,
    warnings: Vec<String>,
}

/// Drops small hinged pieces (see [`HINGED_DROP_FRACTION`]) and the nodes
/// only they used, then splits the remaining hinges (the pieces become
/// separate bodies), so no two output tets share only an edge or a vertex
/// without being joined through faces.
fn drop_hinged(stuffed: &mut crate::stuff::Stuffed) -> HingedDrop {
    let mesh = TetMesh {
        nodes: std::mem::take(&mut stuffed.nodes),
        cells: Cells::Tet4(std::mem::take(&mut stuffed.tets)),
        groups: Vec::new(),
    };
    let parts = modal_mesh::face_parts(&mesh);
    let Cells::Tet4(tets) = mesh.cells else { unreachable!("built as Tet4 above") };
    (stuffed.nodes, stuffed.tets) = (mesh.nodes, tets);
    let limit = HINGED_DROP_FRACTION * stuffed.tets.len() as f64;
    // Clusters of pieces linked by hinges (chains included): each keeps its
    // largest piece; the others that are small are dropped.
    let mut cluster = DisjointSets::new(parts.count);
    for h in &parts.hinges {
        cluster.join(h.parts[0], h.parts[1]);
    }
    let mut largest = vec![usize::MAX; parts.count];
    for p in 0..parts.count {
        let r = cluster.root(p);
        if largest[r] == usize::MAX || parts.tets[p] > parts.tets[largest[r]] {
            largest[r] = p;
        }
    }
    let mut drop = vec![false; parts.count];
    let mut places = Vec::new();
    for h in &parts.hinges {
        for p in h.parts {
            let r = cluster.root(p);
            if p != largest[r] && parts.tets[p] as f64 <= limit && !drop[p] {
                drop[p] = true;
                places.push(h.at);
            }
        }
    }
    let pieces = drop.iter().filter(|&&d| d).count();
    let mut warnings = Vec::new();
    let mut dropped = 0;
    if pieces > 0 {
        let mut tet = 0;
        dropped = stuffed.retain_tets(|_| {
            tet += 1;
            !drop[parts.part_of_tet[tet - 1]]
        });
        let p = places[0];
        warnings.push(format!(
            "dropped {pieces} small piece(s) of the tet mesh ({dropped} tets) that hung on the rest by an edge or a \
             vertex only, first near ({:.4}, {:.4}, {:.4}) m: the solid is thinner than the cell there (a smaller \
             --cell keeps it)",
            p[0], p[1], p[2]
        ));
    }
    // Larger hinged pieces become separate bodies: each gets its own nodes.
    let mut mesh = TetMesh {
        nodes: std::mem::take(&mut stuffed.nodes),
        cells: Cells::Tet4(std::mem::take(&mut stuffed.tets)),
        groups: Vec::new(),
    };
    let parts = modal_mesh::face_parts(&mesh);
    let mut split = 0;
    if !parts.hinges.is_empty() {
        split = parts.hinges.len();
        let added = modal_mesh::split_hinges(&mut mesh, &parts);
        warnings.push(format!(
            "{} pieces of the tet mesh touch only at edges or vertices ({added} nodes duplicated): {}; they are \
             solved as separate bodies (a smaller --cell may join them through faces)",
            parts.count,
            modal_mesh::describe_hinges(&parts, 3)
        ));
    }
    let Cells::Tet4(tets) = mesh.cells else { unreachable!("built as Tet4 above") };
    stuffed.nodes = mesh.nodes;
    stuffed.tets = tets;
    HingedDrop { pieces, tets: dropped, split, warnings }
}

/// Tetrahedralizes the solid bounded by `surface` (see the crate doc).
///
/// The result has 4-node, positively oriented tets and no unused nodes;
/// small pieces that would hang on the rest by an edge or a vertex only are
/// dropped ([`HINGED_DROP_FRACTION`]).
pub fn tetrahedralize(
    surface: &TriSurface,
    options: &TetOptions,
) -> Result<(TetMesh, TetReport), TetraError> {
    surface.validate()?;
    let thickened = match options.sheet_thickness {
        Some(t) => Some(thicken_open_sheets(surface, t)?),
        None => None,
    };
    let sheets_thickened = thickened.as_ref().map_or(0, |(_, report)| report.sheets);
    let slab_warning =
        thickened.as_ref().zip(options.sheet_thickness).and_then(|((_, r), t)| r.slab_warning(t));
    let surface = thickened.as_ref().map_or(surface, |(thick, _)| thick);
    let repaired = repair(surface);
    if repaired.triangles.is_empty() {
        let reason = if repaired.report.double_sided_sheet_faces > 0 {
            "the surface is an open sheet written once for each side (a double-sided export), which encloses \
             nothing: give it a thickness (--sheet-thickness M)"
        } else {
            "every triangle has zero area"
        };
        return Err(TetraError::NothingLeft { reason: reason.into() });
    }
    let (lo, hi) = surface.bounding_box().ok_or(TetraError::Empty)?;
    let diagonal = repaired.report.diagonal_m;
    let area = repaired.solid_area();
    let volume = repaired.report.enclosed_volume_m3;
    let h0 = cell_size(options, diagonal, volume, area)?;
    let tris: Vec<[V3; 3]> = repaired.triangles.iter().map(|t| t.map(|v| repaired.vertices[v])).collect();
    let bvh = Bvh::new(tris);
    let mut warnings: Vec<String> = slab_warning.into_iter().collect();
    let mut not_layered = None;
    let layered =
        try_layered(&repaired, &bvh, options, (diagonal, volume, area), &mut warnings, &mut not_layered)?;
    let (mut stuffed, h, thin_samples, min_thickness_m, wall_layers, smoothed) = match layered {
        Some(LayeredWall { mesh: l, smoothed }) => {
            let stuffed = Stuffed { nodes: l.nodes, tets: l.tets, dropped: 0, min_cell: l.shortest_edge_m };
            (stuffed, l.longest_edge_m, 0, Some(l.wall_m), l.layers, smoothed)
        }
        None => {
            let (stuffed, h, thin_samples, min_thickness_m) =
                stuff_surface(&repaired, &bvh, options, (lo, hi), (h0, diagonal, volume), &mut warnings)?;
            // Why it was not layered matters when the stuffing costs more than
            // a default mesh (a mug with a handle); a solid bar of 9 k tets
            // was told its "thin walls" made it slower, which they did not.
            if stuffed.tets.len() > DEFAULT_MAX_TETS {
                warnings.extend(not_layered.take());
            }
            (stuffed, h, thin_samples, min_thickness_m, 0, None)
        }
    };
    // A smoothed surface is the one the curved boundary follows; the
    // deviations reported stay against the input.
    let follow = smoothed.as_ref().unwrap_or(&bvh);
    // Separate parts far thinner than this cell got slivers or nothing: they
    // are meshed alone below (module `rescue`); the gap is measured on the rest.
    let all_parts = parts(&repaired, 1e-6 * diagonal);
    let lost_parts = lost(&all_parts, &repaired, &stuffed, diagonal);
    clear(&mut stuffed, &lost_parts, diagonal);
    let hinged = drop_hinged(&mut stuffed);
    let boundary = boundary_nodes(&stuffed.tets);
    // A layered wall's nodes are on its skins already; snapping within a
    // fraction of the in-plane cell could move them across the wall.
    let feature_nodes_snapped = if options.preserve_features && wall_layers == 0 {
        let (segments, corners) = features(&repaired.vertices, &repaired.triangles, &bvh, h);
        snap(&mut stuffed.nodes, &stuffed.tets, &boundary, &segments, &corners, h)
    } else {
        0
    };
    let (mut min_dihedral_deg, mut max_dihedral_deg, mut volume_m3) = quality(&stuffed.nodes, &stuffed.tets);
    let mut max_surface_deviation_m = deviation(&stuffed.nodes, &boundary, &bvh);
    let mesh_boundary =
        Bvh::new(boundary_faces(&stuffed.tets).into_iter().map(|f| f.map(|v| stuffed.nodes[v])).collect());
    let specks = specks(&all_parts, &stuffed, diagonal);
    warnings.extend(specks_warning(&specks));
    let unmeshed: Vec<&Part> = lost_parts.iter().chain(&specks).copied().collect();
    let kept_triangles = triangles_outside(&repaired, &unmeshed);
    let (max_surface_gap_m, gap_at) =
        surface_gap(&repaired.vertices, &kept_triangles, &bvh, &mesh_boundary, 0.5 * h0);
    if max_surface_gap_m > GAP_WARNING * diagonal {
        warnings.push(format!(
            "the mesh misses part of the surface by up to {max_surface_gap_m:.3e} m ({:.1} % of the diagonal) near \
             ({:.4}, {:.4}, {:.4}) m: a part there is thinner or smaller than the cells (a smaller --cell keeps it)",
            100.0 * max_surface_gap_m / diagonal,
            gap_at[0],
            gap_at[1],
            gap_at[2]
        ));
    }
    let (mesh, curved_edges, straightened_elements) = if options.curved {
        let curved = curve(stuffed.nodes, stuffed.tets, follow);
        volume_m3 = modal_mesh::mesh_volume(&curved.mesh);
        max_surface_deviation_m =
            max_surface_deviation_m.max(deviation(&curved.mesh.nodes, &curved.boundary_mids, &bvh));
        (curved.mesh, curved.curved_edges, curved.straightened_elements)
    } else {
        (TetMesh { nodes: stuffed.nodes, cells: Cells::Tet4(stuffed.tets), groups: Vec::new() }, 0, 0)
    };
    let mut mesh = mesh;
    for r in mesh_alone(&mut mesh, &lost_parts, &repaired, options, h, &mut warnings) {
        volume_m3 += r.volume_m3;
        max_surface_deviation_m = max_surface_deviation_m.max(r.max_surface_deviation_m);
        min_dihedral_deg = min_dihedral_deg.min(r.min_dihedral_deg);
        max_dihedral_deg = max_dihedral_deg.max(r.max_dihedral_deg);
    }
    let enclosed_m3 = repaired.report.enclosed_volume_m3;
    if enclosed_m3 > 0.0 && volume_m3 < VOLUME_KEPT_WARNING * enclosed_m3 {
        // The gap warning gives the place; this, how much of the body (and its mass) is gone.
        warnings.push(format!(
            "the tet mesh holds {:.0} % of the volume the surface encloses: parts thinner than the cells are \
             missing, and with them mass and modes (a smaller --cell keeps them)",
            100.0 * volume_m3 / enclosed_m3
        ));
    }
    let report = TetReport {
        tets: mesh.cells.len(),
        nodes: mesh.nodes.len(),
        cell_m: h,
        min_cell_m: stuffed.min_cell,
        thin_samples,
        min_thickness_m,
        min_dihedral_deg,
        max_dihedral_deg,
        volume_m3,
        surface_volume_m3: repaired.report.enclosed_volume_m3,
        max_surface_deviation_m,
        max_surface_gap_m,
        curved_edges,
        straightened_elements,
        dropped_degenerate: stuffed.dropped,
        feature_nodes_snapped,
        hinged_pieces_dropped: hinged.pieces,
        hinged_tets_dropped: hinged.tets,
        hinges_split: hinged.split,
        wall_layers,
        sheets_thickened,
        warnings: warnings.into_iter().chain(hinged.warnings).collect(),
    };
    Ok((mesh, report))
}

/// A solid whose stuffing cell would be at least this many wall thicknesses
/// (2V/A) is tried as a thin shell, meshed in layers across its wall
/// (module `shell`): stuffing would need cells finer than the wall everywhere.
pub const LAYERED_MIN_CELLS_PER_WALL: f64 = 1.5;

/// Edges along a layered wall, in wall thicknesses, by default: the curved-wall
/// rule of the generated bowls (`modal_mesh::MAX_CURVED_CELL_PER_WALL`,
/// measured 0.12 % at 2 on a 10 cm glass bowl with a 2 mm wall).
pub const LAYERED_CELL_PER_WALL: f64 = 2.0;

/// Edges along a layered wall of a slender shell that is straight along
/// them and curved across them (a chime's axis), in wall thicknesses, by
/// default: the generated tubes' axial cell (`modal_mesh`: at most 16 walls
/// along a long tube's axis; a 1 m chime within 0.42 % of 3 mm cells).
pub const LAYERED_STRAIGHT_CELL_PER_WALL: f64 = 16.0;

/// The thin-shell mesh of the surface (module `shell`) when its wall is
/// thinner than the cell asks for and it is a shell; `None`: stuff it, with
/// why in `not_layered` when it was tried (said if the stuffing is costly).
fn try_layered(
    repaired: &Repaired,
    bvh: &Bvh,
    options: &TetOptions,
    (diagonal, volume, area): (f64, f64, f64),
    warnings: &mut Vec<String>,
    not_layered: &mut Option<String>,
) -> Result<Option<LayeredWall>, TetraError> {
    if options.graded || options.target_tets.is_some() || !(volume > 0.0 && area > 0.0) {
        return Ok(None);
    }
    let wall = 2.0 * volume / area;
    let size = options.cell.unwrap_or_else(|| bulk_cell(options, diagonal, volume)) * options.size_factor;
    if size.is_nan() || size < LAYERED_MIN_CELLS_PER_WALL * wall {
        return Ok(None);
    }
    let sizing = LayerSizing {
        in_plane_m: options.cell.map(|c| c * options.size_factor),
        wall_cells: LAYERED_CELL_PER_WALL * options.size_factor,
        straight_wall_cells: LAYERED_STRAIGHT_CELL_PER_WALL * options.size_factor,
        size_factor: options.size_factor,
        max_in_plane_m: size,
        max_tets: options.max_tets,
        resolved_modes: options.resolved_modes,
    };
    let volume_m3 = repaired.report.enclosed_volume_m3;
    // A hollow body's outer and inner walls are two components of one body.
    let bodies = repaired.report.components - repaired.report.cavities;
    let shape = (volume_m3, bodies);
    let too_many = |estimated: usize, in_plane_m: f64| {
        // Tets go as cell⁻² here; the error's hint assumes cell⁻³.
        let ratio = estimated as f64 / options.max_tets as f64;
        TetraError::TooManyTets {
            cell_m: in_plane_m,
            estimated: (options.max_tets as f64 * ratio.powf(1.5)) as u64,
            limit: options.max_tets,
        }
    };
    let reason = match layered(&repaired.vertices, &repaired.triangles, bvh, diagonal, shape, sizing, false) {
        Ok(l) => return Ok(Some(LayeredWall { mesh: l, smoothed: None })),
        Err(NotLayered::TooMany { estimated, in_plane_m }) => return Err(too_many(estimated, in_plane_m)),
        Err(reason) => reason,
    };
    if let Some(smoothed) = Smoothed::if_only_noise(repaired, bvh, wall) {
        match smoothed.layered(repaired, diagonal, shape, sizing) {
            Ok(mesh) => {
                warnings.push(smoothed.warning(&reason, mesh.wall_m));
                return Ok(Some(LayeredWall { mesh, smoothed: Some(smoothed.surface) }));
            }
            Err(NotLayered::TooMany { estimated, in_plane_m }) => {
                return Err(too_many(estimated, in_plane_m))
            }
            Err(_) => {}
        }
    }
    *not_layered = Some(not_layered_warning(&reason, wall));
    Ok(None)
}

/// A layered mesh, and the smoothed surface it was made from, if any
/// (its curved boundary follows that surface, not the noise).
pub(crate) struct LayeredWall {
    mesh: Layered,
    smoothed: Option<Bvh>,
}

/// Why a thin-walled solid was stuffed with cells of its wall's size instead
/// of meshed in layers (slower, and a warning says so).
fn not_layered_warning(reason: &NotLayered, wall: f64) -> String {
    format!(
        "thin walls (mean thickness 2V/A = {wall:.3e} m), not meshed in layers across the wall: {}; \
         filled with cells of the wall's size instead (more tets, slower)",
        not_layered_reason(reason)
    )
}

/// Why a surface was not meshed in layers, in a user's words.
pub(crate) fn not_layered_reason(reason: &NotLayered) -> String {
    match reason {
        NotLayered::Unpaired { paired_fraction } => {
            format!("only {:.0} % of its surface lies in walls with a facing side", 100.0 * paired_fraction)
        }
        NotLayered::Skins => {
            "it is no shell: its surface faces itself across a part (a solid bar or rod, a handle) \
             instead of a second skin, or its walls' sides do not pair up"
                .into()
        }
        NotLayered::Column { at } | NotLayered::Fold { at } => {
            format!("layers across its wall would fold near ({:.4}, {:.4}, {:.4}) m", at[0], at[1], at[2])
        }
        NotLayered::Volume { ratio } => {
            format!("its walls hold only {:.1} % of its volume (a thick part)", 100.0 * ratio)
        }
        NotLayered::TooMany { .. } => "it needs too many layered tets".into(),
    }
}

/// The uniform (or graded) isosurface stuffing of the surface at cell `h0`,
/// with the finer fallback cells of a solid thinner than the cell: the
/// tets, the cell used, and the graded mesh's thin samples and thinnest wall.
fn stuff_surface(
    repaired: &Repaired,
    bvh: &Bvh,
    options: &TetOptions,
    (lo, hi): (V3, V3),
    (h0, diagonal, volume): (f64, f64, f64),
    warnings: &mut Vec<String>,
) -> Result<(Stuffed, f64, usize, Option<f64>), TetraError> {
    let mut h = h0;
    let sizing = options.graded.then(|| {
        // Scale of the whole field: the bulk cell relative to the default one.
        let ratio = h0 / (diagonal / options.cells_per_diagonal);
        Sizing::new(&repaired.vertices, &repaired.triangles, bvh, h0, options.cells_per_thickness / ratio)
    });
    let mut stuffed = stuff_at(lo, hi, h, volume, options.max_tets, bvh, sizing.as_ref())?;
    if stuffed.tets.is_empty() {
        if volume <= SHEET_VOLUME * diagonal.powi(3) {
            return Err(TetraError::NoVolume {
                cell_m: h0,
                hint: "the surface encloses no volume at all (an open sheet without thickness): close it, or give it a thickness (--sheet-thickness M)".into(),
            });
        }
        // Thinner than the cell: try finer cells (within the size limit).
        let mut found = None;
        for _ in 0..FALLBACK_HALVINGS {
            h *= 0.5;
            match stuff_at(lo, hi, h, volume, options.max_tets, bvh, None) {
                Ok(s) if !s.tets.is_empty() => {
                    found = Some(s);
                    break;
                }
                Ok(_) => {}
                Err(_) => break,
            }
        }
        match (found, options.cell) {
            (Some(s), None) => {
                warnings.push(format!(
                    "no tets at the default cell {h0:.3e} m (the solid is thinner than that); used --cell {h:.3e} m"
                ));
                stuffed = s;
            }
            (Some(s), Some(_)) => {
                return Err(TetraError::NoVolume {
                    cell_m: h0,
                    hint: format!(
                        "the solid is thinner than the cell; --cell {h:.3e} works ({} tets)",
                        s.tets.len()
                    ),
                });
            }
            (None, _) => {
                return Err(TetraError::NoVolume {
                    cell_m: h0,
                    hint: format!(
                        "the solid is thinner than the cell, and cells down to {h:.3e} m found none either (is it an open sheet, or much thinner than its size?)"
                    ),
                });
            }
        }
    }
    let floor = h0 / f64::from(1u32 << MAX_LEVELS);
    let (thin_samples, min_thickness_m) = match &sizing {
        Some(sizing) => {
            let thin = sizing.thin();
            let thinnest = thin.iter().min_by(|a, b| a.thickness.total_cmp(&b.thickness));
            let below: Vec<_> = thin.iter().filter(|t| t.size < floor).collect();
            if let (Some(t), false) = (thinnest, below.is_empty()) {
                warnings.push(format!(
                    "{} surface samples are thinner than the mesher can resolve with {} cells across (its floor is \
                     the cell / {} = {floor:.3e} m): the thinnest is {:.3e} m near ({:.4}, {:.4}, {:.4}) m; \
                     a smaller --cell refines it",
                    below.len(),
                    options.cells_per_thickness,
                    1u32 << MAX_LEVELS,
                    t.thickness,
                    t.at[0],
                    t.at[1],
                    t.at[2]
                ));
            }
            (thin.len(), thinnest.map(|t| t.thickness))
        }
        None => (0, None),
    };
    Ok((stuffed, h, thin_samples, min_thickness_m))
}

fn cell_size(options: &TetOptions, diagonal: f64, volume: f64, area: f64) -> Result<f64, TetraError> {
    let positive = |name: &'static str, x: f64| {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(TetraError::InvalidOption { name, reason: format!("{x} is not a positive finite number") })
        }
    };
    let factor = positive("size_factor", options.size_factor)?;
    Ok(factor * base_cell_size(options, diagonal, volume, area)?)
}

fn base_cell_size(options: &TetOptions, diagonal: f64, volume: f64, area: f64) -> Result<f64, TetraError> {
    let positive = |name: &'static str, x: f64| {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(TetraError::InvalidOption { name, reason: format!("{x} is not a positive finite number") })
        }
    };
    if let Some(h) = options.cell {
        return positive("cell", h);
    }
    if let Some(n) = options.target_tets {
        if n == 0 {
            return Err(TetraError::InvalidOption {
                name: "target_tets",
                reason: "must be at least 1".into(),
            });
        }
        let v = if volume > 0.0 { volume } else { diagonal.powi(3) / 27.0 };
        return positive("target_tets", (12.0 * v / n as f64).cbrt());
    }
    positive("cells_per_diagonal", options.cells_per_diagonal)?;
    positive("cells_per_thickness", options.cells_per_thickness)?;
    let mut h = bulk_cell(options, diagonal, volume);
    if !options.graded && volume > 0.0 && area > 0.0 {
        h = h.min(2.0 * volume / area / options.cells_per_thickness);
    }
    positive("cell", h)
}

/// The default cell before the thickness bound: diagonal / `cells_per_diagonal`,
/// coarsened until the solid holds about `default_max_tets` tets (0 or `usize::MAX`: no cap).
fn bulk_cell(options: &TetOptions, diagonal: f64, volume: f64) -> f64 {
    let h = diagonal / options.cells_per_diagonal;
    if volume > 0.0 && options.default_max_tets > 0 && options.default_max_tets < usize::MAX {
        h.max((12.0 * volume / options.default_max_tets as f64).cbrt())
    } else {
        h
    }
}

/// Halvings of the cell tried when the first cell gives no tets.
const FALLBACK_HALVINGS: usize = 2;
/// Enclosed volume (× diagonal³) at or below which a surface is a sheet.
const SHEET_VOLUME: f64 = 1e-9;

/// Stuffs the solid on a lattice of cell `h` after checking its size,
/// graded by `sizing` when given.
fn stuff_at(
    lo: V3,
    hi: V3,
    h: f64,
    volume: f64,
    max_tets: usize,
    bvh: &Bvh,
    sizing: Option<&Sizing>,
) -> Result<crate::stuff::Stuffed, TetraError> {
    let lattice = Lattice::covering(lo, hi, h, 2);
    check_size(&lattice, volume, max_tets)?;
    let size_at = |x: V3| sizing.map_or(h, |s| s.size(x));
    // The background holds the outside tets near the surface too.
    let limit = 2 * max_tets;
    let bg = background(&lattice, bvh, sizing.is_some().then_some(&size_at as _), limit)
        .map_err(|live| TetraError::TooManyTets { cell_m: h, estimated: live as u64, limit: max_tets })?;
    Ok(stuff(bg, bvh))
}

fn check_size(lattice: &Lattice, volume: f64, limit: usize) -> Result<(), TetraError> {
    let h = lattice.h;
    let cubes = lattice.n.iter().map(|&n| n as f64).product::<f64>();
    // The lattice itself (≈ 2 points per cube) must fit as well as the output.
    let estimated = (12.0 * volume / (h * h * h)).max(cubes);
    if estimated > limit as f64 {
        return Err(TetraError::TooManyTets { cell_m: h, estimated: estimated as u64, limit });
    }
    Ok(())
}

/// (min dihedral, max dihedral, volume) over all tets.
fn quality(nodes: &[V3], tets: &[[usize; 4]]) -> (f64, f64, f64) {
    tets.par_iter()
        .map(|t| {
            let p = t.map(|i| nodes[i]);
            let a = dihedral_angles_deg(p);
            let lo = a.iter().copied().fold(180.0, f64::min);
            let hi = a.iter().copied().fold(0.0, f64::max);
            (lo, hi, orient6(p[0], p[1], p[2], p[3]) / 6.0)
        })
        .reduce(|| (180.0, 0.0, 0.0), |x, y| (x.0.min(y.0), x.1.max(y.1), x.2 + y.2))
}

/// A surface gap above this fraction of the bounding-box diagonal is a warning.
pub const GAP_WARNING: f64 = 0.01;

/// Faces that belong to exactly one tet.
fn boundary_faces(tets: &[[usize; 4]]) -> Vec<[usize; 3]> {
    let mut faces: Vec<[usize; 3]> = Vec::with_capacity(4 * tets.len());
    for t in tets {
        for skip in 0..4 {
            let mut f = [t[(skip + 1) % 4], t[(skip + 2) % 4], t[(skip + 3) % 4]];
            f.sort_unstable();
            faces.push(f);
        }
    }
    faces.sort_unstable();
    faces.chunk_by(|a, b| a == b).filter(|run| run.len() == 1).map(|run| run[0]).collect()
}

/// Nodes on faces that belong to exactly one tet, sorted.
fn boundary_nodes(tets: &[[usize; 4]]) -> Vec<usize> {
    let mut nodes: Vec<usize> = boundary_faces(tets).into_iter().flatten().collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

/// Largest distance from the given nodes to the input surface (m).
fn deviation(nodes: &[V3], boundary: &[usize], bvh: &Bvh) -> f64 {
    boundary.par_iter().map(|&v| bvh.distance(nodes[v])).reduce(|| 0.0, f64::max)
}
