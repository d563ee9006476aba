//! Parts lost at the body's cell, meshed on their own.
//!
//! One cell size serves the whole surface, chosen for its bulk. A separate
//! part much thinner than that cell (a 2 mm plate beside a 4 cm block, a
//! lamp's shade beside its base) then received no tet at all: the mesh
//! silently lost a body, with only a warning that the surface was missed.
//! Separate parts do not share nodes, so such a part can be meshed alone,
//! at its own default size (in layers if it is a shell), and its tets
//! appended: the stiffness and mass matrices are block-diagonal over parts.
//!
//! A "part" here is a cluster of closed components whose bounding boxes
//! overlap (so overlapping and nested pieces stay together, as the winding
//! number joins them). Only parts whose box is at least
//! [`RESCUE_MIN_FRACTION`] of the whole diagonal are met again: a scan's
//! floating specks stay dropped. An explicit cell applies to the part too
//! (a thin shell is layered with edges up to that cell; a small solid may
//! find no tet at it, which a warning says).

use modal_mesh::{Cells, TetMesh};

use crate::diagnose::Repaired;
use crate::geom::{cross, dot, norm, orient6, sub, V3};
use crate::stuff::Stuffed;
use crate::{tetrahedralize, TetOptions, TetReport, TriSurface};

/// Smallest part worth meshing on its own, as a fraction of the whole
/// surface's bounding-box diagonal (its own box's diagonal).
pub const RESCUE_MIN_FRACTION: f64 = 0.05;

/// Closed components whose boxes overlap, with their joint box.
#[derive(Clone, Debug)]
pub(crate) struct Part {
    /// Triangles of the repaired surface.
    pub triangles: Vec<usize>,
    pub lo: V3,
    pub hi: V3,
    /// Every component of it is closed (it can be meshed alone).
    pub closed: bool,
}

impl Part {
    fn diagonal(&self) -> f64 {
        norm(sub(self.hi, self.lo))
    }

    fn overlaps(&self, other: &Part, tol: f64) -> bool {
        (0..3).all(|k| self.lo[k] <= other.hi[k] + tol && other.lo[k] <= self.hi[k] + tol)
    }

    fn absorb(&mut self, other: Part) {
        self.triangles.extend(other.triangles);
        self.closed &= other.closed;
        for k in 0..3 {
            (self.lo[k], self.hi[k]) = (self.lo[k].min(other.lo[k]), self.hi[k].max(other.hi[k]));
        }
    }

    fn contains(&self, p: V3, tol: f64) -> bool {
        (0..3).all(|c| p[c] >= self.lo[c] - tol && p[c] <= self.hi[c] + tol)
    }

    /// The volume its oriented triangles enclose (cavities subtract).
    fn enclosed_volume(&self, repaired: &Repaired) -> f64 {
        let o = self.lo;
        self.triangles
            .iter()
            .map(|&t| {
                let [a, b, c] = repaired.triangles[t].map(|v| sub(repaired.vertices[v], o));
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    /// The part's triangles as a surface of their own (oriented as repaired).
    pub fn surface(&self, repaired: &Repaired) -> TriSurface {
        let mut index = vec![usize::MAX; repaired.vertices.len()];
        let mut out = TriSurface::default();
        for &t in &self.triangles {
            let tri = repaired.triangles[t].map(|v| {
                if index[v] == usize::MAX {
                    index[v] = out.vertices.len();
                    out.vertices.push(repaired.vertices[v]);
                }
                index[v]
            });
            out.triangles.push(tri);
        }
        out.parts.push(("part".into(), 0..out.triangles.len()));
        out
    }
}

/// Most components the parts are formed from; a surface of more (a voxel
/// export, a soup of closed pieces) gets no rescue, so the joining stays cheap.
pub const MAX_COMPONENTS: usize = 2_000;

/// Most parts of [`RESCUE_MIN_FRACTION`] or more that are looked at.
pub const MAX_RESCUED_PARTS: usize = 64;

/// The parts of a repaired surface: components joined while their boxes
/// overlap (within `tol`), so no two parts' boxes overlap. Open components
/// take part in the joining (their tets must not be taken for a part's)
/// but make their part unfit for meshing alone.
pub(crate) fn parts(repaired: &Repaired, tol: f64) -> Vec<Part> {
    if repaired.components.len() > MAX_COMPONENTS {
        return Vec::new();
    }
    let mut parts: Vec<Part> = repaired
        .components
        .iter()
        .map(|c| {
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for &t in &c.triangles {
                for &v in &repaired.triangles[t] {
                    let p = repaired.vertices[v];
                    (0..3).for_each(|k| (lo[k], hi[k]) = (lo[k].min(p[k]), hi[k].max(p[k])));
                }
            }
            Part { triangles: c.triangles.clone(), lo, hi, closed: c.closed }
        })
        .collect();
    // Passes of pairwise joins until none is left: a joined box may reach
    // parts its members did not.
    let mut joined = true;
    while joined {
        joined = false;
        let mut i = 0;
        while i < parts.len() {
            let mut j = i + 1;
            while j < parts.len() {
                if parts[i].overlaps(&parts[j], tol) {
                    let other = parts.swap_remove(j);
                    parts[i].absorb(other);
                    joined = true;
                } else {
                    j += 1;
                }
            }
            i += 1;
        }
    }
    parts.sort_by_key(|p| p.triangles.iter().min().copied());
    parts
}

/// Fraction of a part's enclosed volume below which its tets count as lost:
/// what is left of a plate thinner than the cell is slivers hanging on
/// edges, not the plate.
pub const LOST_VOLUME_FRACTION: f64 = 0.5;

/// The parts of at least [`RESCUE_MIN_FRACTION`] of `diagonal` whose tets
/// (by centroid) fill less than [`LOST_VOLUME_FRACTION`] of their enclosed
/// volume; none when clearing them would leave no tet, or when there are
/// more than [`MAX_RESCUED_PARTS`] such parts.
pub(crate) fn lost<'a>(
    parts: &'a [Part],
    repaired: &Repaired,
    mesh: &Stuffed,
    diagonal: f64,
) -> Vec<&'a Part> {
    let candidates: Vec<&Part> =
        parts.iter().filter(|p| p.closed && p.diagonal() >= RESCUE_MIN_FRACTION * diagonal).collect();
    if parts.len() < 2 || candidates.is_empty() || candidates.len() > MAX_RESCUED_PARTS {
        return Vec::new();
    }
    let meshed = meshed_per_part(&candidates, mesh, diagonal);
    let lost: Vec<usize> = (0..candidates.len())
        .filter(|&i| meshed[i].0 < LOST_VOLUME_FRACTION * candidates[i].enclosed_volume(repaired))
        .collect();
    // Clearing them must leave tets to keep.
    let cleared: usize = lost.iter().map(|&i| meshed[i].1).sum();
    if cleared == mesh.tets.len() {
        return Vec::new();
    }
    lost.into_iter().map(|i| candidates[i]).collect()
}

/// Per part, the volume and number of the tets whose centroid is in its box.
fn meshed_per_part(parts: &[&Part], mesh: &Stuffed, diagonal: f64) -> Vec<(f64, usize)> {
    let tol = 1e-6 * diagonal;
    let mut meshed = vec![(0.0, 0usize); parts.len()];
    for t in &mesh.tets {
        let p = t.map(|v| mesh.nodes[v]);
        let centroid: V3 = std::array::from_fn(|c| (p[0][c] + p[1][c] + p[2][c] + p[3][c]) / 4.0);
        if let Some(i) = parts.iter().position(|part| part.contains(centroid, tol)) {
            meshed[i].0 += orient6(p[0], p[1], p[2], p[3]).abs() / 6.0;
            meshed[i].1 += 1;
        }
    }
    meshed
}

/// Specks: separate parts below [`RESCUE_MIN_FRACTION`] of `diagonal` (a
/// scan's floating debris) that got no tet. They are left out on purpose,
/// so the surface they leave unmeshed is not a gap of the body's mesh (a
/// coin with five 0.2 mm cubes beside it was warned of missing 37 % of its
/// diagonal, "a smaller --cell keeps it").
pub(crate) fn specks<'a>(parts: &'a [Part], mesh: &Stuffed, diagonal: f64) -> Vec<&'a Part> {
    let small: Vec<&Part> = parts.iter().filter(|p| p.diagonal() < RESCUE_MIN_FRACTION * diagonal).collect();
    if parts.len() < 2 || small.is_empty() {
        return Vec::new();
    }
    let meshed = meshed_per_part(&small, mesh, diagonal);
    small.into_iter().zip(meshed).filter(|(_, (_, tets))| *tets == 0).map(|(p, _)| p).collect()
}

/// The warning for `specks` left out ([`specks`]), if any.
pub(crate) fn specks_warning(specks: &[&Part]) -> Option<String> {
    let largest = specks.iter().max_by(|a, b| a.diagonal().total_cmp(&b.diagonal()))?;
    let at = largest.lo;
    Some(format!(
        "{} separate speck(s) smaller than {:.0} % of the object (the largest {:.3e} m across, near ({:.4}, {:.4}, \
         {:.4}) m) got no tets and are left out, as floating debris",
        specks.len(),
        100.0 * RESCUE_MIN_FRACTION,
        largest.diagonal(),
        at[0],
        at[1],
        at[2]
    ))
}

/// Removes the tets (by centroid) of the `lost` parts and the nodes only they used.
pub(crate) fn clear(mesh: &mut Stuffed, lost: &[&Part], diagonal: f64) {
    if lost.is_empty() {
        return;
    }
    let tol = 1e-6 * diagonal;
    let nodes = mesh.nodes.clone();
    mesh.retain_tets(|t| {
        let centroid: V3 = std::array::from_fn(|c| t.iter().map(|&v| nodes[v][c]).sum::<f64>() / 4.0);
        !lost.iter().any(|part| part.contains(centroid, tol))
    });
}

/// The repaired triangles outside the `lost` parts.
pub(crate) fn triangles_outside(repaired: &Repaired, lost: &[&Part]) -> Vec<[usize; 3]> {
    let mut inside = vec![false; repaired.triangles.len()];
    lost.iter().flat_map(|p| &p.triangles).for_each(|&t| inside[t] = true);
    repaired.triangles.iter().zip(&inside).filter(|(_, &i)| !i).map(|(t, _)| *t).collect()
}

/// Meshes each `lost` part alone (same options, no sheet thickening: the
/// surface is thickened already) and appends it to `mesh`; says so in
/// `warnings`, and returns the reports of the parts that meshed.
pub(crate) fn mesh_alone(
    mesh: &mut TetMesh,
    lost: &[&Part],
    repaired: &Repaired,
    options: &TetOptions,
    cell_m: f64,
    warnings: &mut Vec<String>,
) -> Vec<TetReport> {
    let alone = TetOptions { sheet_thickness: None, ..options.clone() };
    let mut reports = Vec::new();
    for part in lost {
        let at = part.lo;
        let near = format!("a separate part near ({:.4}, {:.4}, {:.4}) m", at[0], at[1], at[2]);
        match tetrahedralize(&part.surface(repaired), &alone) {
            Ok((part_mesh, r)) => {
                let layers = if r.wall_layers > 0 {
                    format!(", {} layer(s) across its wall", r.wall_layers)
                } else {
                    String::new()
                };
                warnings.push(format!(
                    "{near} is thinner than the cell ({cell_m:.3e} m) and got slivers or no tets: it is meshed on its \
                     own ({} tets{layers})",
                    r.tets
                ));
                warnings.extend(r.warnings.iter().map(|w| format!("that part: {w}")));
                append(mesh, part_mesh);
                reports.push(r);
            }
            Err(e) => warnings.push(format!("{near} got no tets at the cell {cell_m:.3e} m, nor alone: {e}")),
        }
    }
    reports
}

/// Appends `part`'s nodes and cells to `mesh` (both of one element order).
fn append(mesh: &mut TetMesh, part: TetMesh) {
    let offset = mesh.nodes.len();
    mesh.nodes.extend(part.nodes);
    match (&mut mesh.cells, part.cells) {
        (Cells::Tet4(a), Cells::Tet4(b)) => a.extend(b.into_iter().map(|t| t.map(|v| v + offset))),
        (Cells::Tet10(a), Cells::Tet10(b)) => a.extend(b.into_iter().map(|t| t.map(|v| v + offset))),
        _ => debug_assert!(false, "one element order for the whole mesh"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::repair;
    use crate::shapes::cuboid;

    /// Boxes at the given offsets, sizes as given, as one surface.
    fn boxes(specs: &[([f64; 3], [f64; 3])]) -> TriSurface {
        let mut out = TriSurface::default();
        for &(at, size) in specs {
            let b = cuboid(size[0], size[1], size[2]);
            let base = out.vertices.len();
            out.vertices.extend(b.vertices.iter().map(|p| std::array::from_fn(|c| p[c] + at[c])));
            out.triangles.extend(b.triangles.iter().map(|t| t.map(|v| v + base)));
        }
        out.parts.push(("boxes".into(), 0..out.triangles.len()));
        out
    }

    #[test]
    fn overlapping_boxes_are_one_part_and_a_separate_one_another() {
        let s = boxes(&[
            ([0.0; 3], [0.1, 0.06, 0.04]),
            ([0.05, 0.02, 0.02], [0.1, 0.01, 0.01]),
            ([0.3, 0.0, 0.0], [0.1, 0.06, 0.002]),
        ]);
        let repaired = repair(&s);
        let p = parts(&repaired, 1e-9);
        assert_eq!(p.len(), 2);
        assert_eq!((p[0].triangles.len(), p[1].triangles.len()), (24, 12));
        assert!((p[0].hi[0] - 0.15).abs() < 1e-15 && (p[1].lo[0] - 0.3).abs() < 1e-15);
        assert!((p[1].enclosed_volume(&repaired) - 0.1 * 0.06 * 0.002).abs() < 1e-15);
    }

    #[test]
    fn a_part_with_slivers_only_is_lost_unless_small_or_alone() {
        // A tetrahedron (the body), a plate and a speck.
        let mut s = boxes(&[([0.3, 0.0, 0.0], [0.1, 0.06, 0.002]), ([0.0, 0.2, 0.0], [0.001; 3])]);
        let base = s.vertices.len();
        s.vertices.extend([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.06, 0.0], [0.0, 0.0, 0.04]]);
        s.triangles.extend([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]].map(|t| t.map(|v| v + base)));
        s.parts = vec![("all".into(), 0..s.triangles.len())];
        let repaired = repair(&s);
        let all = parts(&repaired, 1e-9);
        assert_eq!(all.len(), 3);
        // One tet filling the tetrahedron, one sliver in the plate, none in the speck.
        let mesh = Stuffed {
            nodes: vec![
                [0.0, 0.0, 0.0],
                [0.1, 0.0, 0.0],
                [0.0, 0.06, 0.0],
                [0.0, 0.0, 0.04],
                [0.3, 0.0, 0.0],
                [0.31, 0.0, 0.0],
                [0.3, 0.01, 0.0],
                [0.3, 0.0, 0.001],
            ],
            tets: vec![[0, 1, 2, 3], [4, 5, 6, 7]],
            dropped: 0,
            min_cell: 0.01,
        };
        let diagonal = 0.5;
        let lost_parts = lost(&all, &repaired, &mesh, diagonal);
        assert_eq!(lost_parts.len(), 1, "the plate; the body has its tet and the speck is too small");
        assert!((lost_parts[0].lo[0] - 0.3).abs() < 1e-15);
        let mut cleared = mesh.clone();
        clear(&mut cleared, &lost_parts, diagonal);
        assert_eq!((cleared.tets.len(), cleared.nodes.len()), (1, 4));
        // Where every part would be lost, nothing would be left: none is.
        let plate_and_speck_only = Stuffed { tets: vec![[4, 5, 6, 7]], ..mesh };
        let plates = boxes(&[([0.3, 0.0, 0.0], [0.1, 0.06, 0.002]), ([0.0, 0.2, 0.0], [0.1, 0.06, 0.002])]);
        let repaired = repair(&plates);
        assert!(lost(&parts(&repaired, 1e-9), &repaired, &plate_and_speck_only, diagonal).is_empty());
    }

    #[test]
    fn append_offsets_the_part_s_nodes() {
        let mut a =
            TetMesh { nodes: vec![[0.0; 3]; 4], cells: Cells::Tet4(vec![[0, 1, 2, 3]]), groups: Vec::new() };
        let b =
            TetMesh { nodes: vec![[1.0; 3]; 4], cells: Cells::Tet4(vec![[3, 2, 1, 0]]), groups: Vec::new() };
        append(&mut a, b);
        assert_eq!(a.nodes.len(), 8);
        assert_eq!(a.cells, Cells::Tet4(vec![[0, 1, 2, 3], [7, 6, 5, 4]]));
    }
}
