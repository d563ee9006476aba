//! Input diagnostics and orientation repair of a triangle surface.
//!
//! Steps: weld vertices closer than 1e-10 × the bounding-box diagonal (count
//! duplicates), drop triangles that collapse at that tolerance or fill a
//! split edge (count degenerates), split edges at T-junctions (module
//! `tjunction`), drop faces written twice (module `coincident`), classify
//! edges (open boundary = 1 triangle, manifold = 2, non-manifold = 3 or more), then orient triangles consistently across manifold edges per
//! connected component (breadth-first) and flip a component whose signed
//! volume is negative, except the inner walls of hollow objects, which keep
//! facing inward (module `nesting`). The repaired surface is put in a
//! canonical order (module `canonical`), so that its mesh depends on the
//! geometry alone, not on the file's order. The repaired triangles feed the
//! winding number. A surface that the weld leaves open is repaired again
//! with a weld at 10⁻⁶ of the diagonal, kept when it closes edges without
//! making any non-manifold (a soup cracked by an exporter's rounding).

use std::collections::HashMap;

use crate::canonical::{canonical, Canonical};
use crate::coincident::{drop_coincident, Coincident, Sheets};
use crate::geom::{add, area_vector, cross, dot, norm, scale, sub, V3};
use crate::nesting::{nest, Component};
use crate::tjunction::{inside_segment, split_t_junctions};
use crate::TriSurface;

/// What was wrong with an input surface (all counts refer to the input).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct SurfaceReport {
    /// Number of input triangles.
    pub triangles: usize,
    /// Number of input vertices.
    pub vertices: usize,
    /// Part names, in file order.
    pub parts: Vec<String>,
    /// Bounding box minimum corner (m).
    pub bbox_min: [f64; 3],
    /// Bounding box maximum corner (m).
    pub bbox_max: [f64; 3],
    /// Bounding-box diagonal (m).
    pub diagonal_m: f64,
    /// Vertices merged into an earlier one at the same position.
    pub duplicate_vertices: usize,
    /// Triangles of zero area (or repeated corners) that were ignored.
    pub degenerate_triangles: usize,
    /// Corners of one triangle found on an open edge of another (a
    /// T-junction), where that edge was split so the seam closes.
    pub t_junctions: usize,
    /// Triangles that repeat another with the same winding (a duplicated
    /// export), ignored.
    pub repeated_triangles: usize,
    /// Faces written once for each side (a double-sided export): one
    /// triangle of each such pair was ignored.
    pub double_sided_faces: usize,
    /// Faces of open sheets written once for each side: a sheet without
    /// thickness encloses nothing, so both sides were ignored.
    pub double_sided_sheet_faces: usize,
    /// Triangles where two parts touch face to face (opposite pairs), both
    /// ignored: the parts are meshed as one body.
    pub touching_triangles: usize,
    /// Edges used by exactly one triangle (holes, open sheets).
    pub open_boundary_edges: usize,
    /// Edges used by three or more triangles.
    pub non_manifold_edges: usize,
    /// Manifold edges whose two triangles traverse it the same way.
    pub inconsistent_edges: usize,
    /// Triangles whose orientation the repair reversed.
    pub flipped_faces: usize,
    /// Edge-connected components (after welding).
    pub components: usize,
    /// Closed components inside another closed one that face the other way
    /// in the input: inner walls of hollow objects, kept facing inward.
    pub cavities: usize,
    /// Signed volume of the oriented components summed (m³): outer parts
    /// add, cavities subtract (exact for closed surfaces; overlapping parts
    /// are counted twice).
    pub enclosed_volume_m3: f64,
    /// Human-readable warnings, e.g. the unit hint pointing to `--scale`.
    pub warnings: Vec<String>,
}

impl SurfaceReport {
    /// True when the surface is a closed, consistently oriented, outward
    /// manifold without duplicates or degenerate triangles.
    pub fn is_clean(&self) -> bool {
        self.duplicate_vertices == 0
            && self.degenerate_triangles == 0
            && self.t_junctions == 0
            && self.repeated_triangles == 0
            && self.double_sided_faces == 0
            && self.double_sided_sheet_faces == 0
            && self.touching_triangles == 0
            && self.open_boundary_edges == 0
            && self.non_manifold_edges == 0
            && self.inconsistent_edges == 0
            && self.flipped_faces == 0
    }
}

/// A welded, consistently oriented copy of a surface (degenerates removed).
#[derive(Clone, Debug)]
pub(crate) struct Repaired {
    pub vertices: Vec<V3>,
    pub triangles: Vec<[usize; 3]>,
    pub report: SurfaceReport,
    /// The components `triangles` fall into, joined across manifold edges only.
    pub components: Vec<Component>,
}

impl Repaired {
    /// Area of the solid's boundary (m²): the triangles, plus, for each open
    /// part that encloses a volume, the caps its holes are closed by (the
    /// winding number caps a planar hole flat). A cap's area is at least the
    /// length of the part's vector area `|Σ_t (b − a) × (c − a) / 2|` (a closed
    /// surface has none; equal for a planar hole). Without the caps, `2V/A` read
    /// an open cymbal, filled to its rim, as a wall twice as thick as it is. A
    /// part enclosing less than [`CAPPED_DEPTH`] of its cap's size (a flat sheet,
    /// whose cap is the sheet itself and whose solid is empty) gets none.
    pub(crate) fn solid_area(&self) -> f64 {
        let triangle = |t: usize| {
            let [a, b, c] = self.triangles[t].map(|v| self.vertices[v]);
            area_vector(a, b, c)
        };
        let sides: f64 = (0..self.triangles.len()).map(|t| norm(triangle(t))).sum();
        let caps: f64 = self
            .components
            .iter()
            .filter(|c| !c.closed)
            .map(|c| (c.volume, norm(c.triangles.iter().fold([0.0; 3], |sum, &t| add(sum, triangle(t))))))
            .filter(|&(volume, cap)| volume > CAPPED_DEPTH * cap.powf(1.5))
            .map(|(_, cap)| cap)
            .sum();
        sides + caps
    }
}

/// Volume over cap area^(3/2) below which an open part is a sheet, not a
/// vessel (a shallow cymbal 2 cm deep and 30 cm across has 0.037; a sheet
/// bent by 1° about 10⁻³).
const CAPPED_DEPTH: f64 = 1e-3;

/// Diagnoses `surface` (see the module doc). Never fails; an empty surface
/// gives an all-zero report.
pub fn diagnose(surface: &TriSurface) -> SurfaceReport {
    repair(surface).report
}

/// Vertices closer than this fraction of the bounding-box diagonal are one
/// vertex, and a triangle that thin has no area.
const WELD_TOLERANCE: f64 = 1e-10;

/// Welds, cleans and orients `surface` (module doc). A double-sided open
/// sheet is dropped: it encloses nothing.
pub(crate) fn repair(surface: &TriSurface) -> Repaired {
    repair_with(surface, Sheets::Drop)
}

/// As [`repair`], but a double-sided open sheet keeps one side: for a
/// caller that gives open sheets a thickness.
pub(crate) fn repair_keeping_sheets(surface: &TriSurface) -> Repaired {
    repair_with(surface, Sheets::Keep)
}

/// Welds at [`WELD_TOLERANCE`]; when that leaves the surface open, welds
/// again at [`CRACK_TOLERANCE`] and keeps that if it closes edges without
/// making any non-manifold. A soup whose copies of a corner were written
/// apart by rounding (per-face transforms, single precision: 10⁻⁷ of the
/// diagonal) stayed a cloud of loose triangles: no part had a volume, so
/// no wall sized the cells, and pairs of faces written twice were not found
/// (a cracked soup of the mug kept 57 % of its volume; a box with half its
/// faces written twice, half).
fn repair_with(surface: &TriSurface, sheets: Sheets) -> Repaired {
    let tight = repair_at(surface, sheets, WELD_TOLERANCE);
    if tight.report.open_boundary_edges == 0 {
        return tight;
    }
    let mut loose = repair_at(surface, sheets, CRACK_TOLERANCE);
    let (open, non_manifold) = (loose.report.open_boundary_edges, loose.report.non_manifold_edges);
    if open >= tight.report.open_boundary_edges || non_manifold > tight.report.non_manifold_edges {
        return tight;
    }
    let joined = loose.report.duplicate_vertices.saturating_sub(tight.report.duplicate_vertices);
    let metres = |fraction: f64| fraction * loose.report.diagonal_m;
    loose.report.warnings.insert(
        0,
        format!(
            "the surface is cracked: {joined} corner(s) lie apart from their copies by more than {:.1e} m; \
             welded within {:.1e} m (10⁻⁶ of the diagonal), as rounding in an exporter leaves them",
            metres(WELD_TOLERANCE),
            metres(CRACK_TOLERANCE),
        ),
    );
    loose
}

/// Copies of a corner closer than this fraction of the diagonal are welded
/// when the [`WELD_TOLERANCE`] leaves the surface open: the distance within
/// which a corner counts as lying on an edge (about ten single-precision
/// roundings of a coordinate), far below any cell.
const CRACK_TOLERANCE: f64 = crate::tjunction::ON_EDGE;

fn repair_at(surface: &TriSurface, sheets: Sheets, weld_fraction: f64) -> Repaired {
    let mut report = SurfaceReport {
        triangles: surface.triangles.len(),
        vertices: surface.vertices.len(),
        parts: surface.parts.iter().map(|(n, _)| n.clone()).collect(),
        ..Default::default()
    };
    if let Some((lo, hi)) = surface.bounding_box() {
        report.bbox_min = lo;
        report.bbox_max = hi;
        report.diagonal_m = norm(sub(hi, lo));
    }
    let weld_tol = report.diagonal_m * weld_fraction;
    let on_edge = report.diagonal_m * crate::tjunction::ON_EDGE;
    let (vertices, map, duplicates) = weld(surface, weld_tol);
    report.duplicate_vertices = duplicates;
    let mut triangles = Vec::with_capacity(surface.triangles.len());
    for t in &surface.triangles {
        let t = t.map(|v| map[v]);
        let corners = t.map(|v| vertices[v]);
        if t[0] == t[1]
            || t[1] == t[2]
            || t[0] == t[2]
            || collapses(corners, weld_tol)
            || fills(corners, on_edge)
        {
            report.degenerate_triangles += 1;
        } else {
            triangles.push(t);
        }
    }
    // In canonical order from here on, so that which copy of a face is kept,
    // where a split goes and every sum depend on the geometry, not the file.
    let Canonical { mut vertices, mut triangles, .. } = canonical(&vertices, &triangles);
    report.t_junctions = split_t_junctions(&mut vertices, &mut triangles, report.diagonal_m);
    let coincident = drop_coincident(&mut triangles, sheets);
    report.repeated_triangles = coincident.repeated;
    report.double_sided_faces = coincident.double_sided;
    report.double_sided_sheet_faces = coincident.double_sided_sheet;
    report.touching_triangles = coincident.touching;
    let (flips, components) = orient(&vertices, &mut triangles, &mut report);
    report.flipped_faces = flips;
    let (vertices, triangles, components) =
        in_canonical_order(&vertices, &triangles, components, &mut report);
    report.warnings.extend(modal_mesh::unit_warning(report.diagonal_m));
    report.warnings.extend(coincident_warning(&coincident));
    report.warnings.extend(sheet_sides_warning(coincident.double_sided_sheet));
    report.warnings.extend(open_warning(report.open_boundary_edges));
    Repaired { vertices, triangles, report, components }
}

/// The oriented surface in canonical order again (orientation and the
/// T-junction splits changed it), its components renumbered and their
/// volumes, and the enclosed volume, summed anew in that order.
fn in_canonical_order(
    vertices: &[V3],
    triangles: &[[usize; 3]],
    mut components: Vec<Component>,
    report: &mut SurfaceReport,
) -> (Vec<V3>, Vec<[usize; 3]>, Vec<Component>) {
    let c = canonical(vertices, triangles);
    for component in &mut components {
        component.triangles.iter_mut().for_each(|t| *t = c.position_of[*t]);
        component.triangles.sort_unstable();
    }
    components.sort_by_key(|component| component.triangles.first().copied());
    let unflipped = vec![false; c.triangles.len()];
    report.enclosed_volume_m3 = 0.0;
    for component in &mut components {
        let signed =
            signed_volume(&c.vertices, &c.triangles, &component.triangles, &unflipped, component.closed);
        component.volume = signed.abs();
        report.enclosed_volume_m3 += signed;
    }
    (c.vertices, c.triangles, components)
}

/// True when the triangle collapses at the weld tolerance `tol`: a corner
/// lies within `tol` of the line through the opposite (longest) edge, as two
/// corners within `tol` of each other are welded into one. Its height is
/// `|(b − a) × (c − a)| / ℓ`, ℓ the longest edge. An exact zero test kept the
/// slivers exporters leave at a split edge (a corner interpolated on the
/// opposite edge, off it by rounding): their edges made the edge they lie on
/// non-manifold, and the repair of the faces around it went wrong.
fn collapses([a, b, c]: [V3; 3], tol: f64) -> bool {
    let n = norm(cross(sub(b, a), sub(c, a)));
    let longest = [sub(b, a), sub(c, b), sub(a, c)].iter().map(|e| dot(*e, *e)).fold(0.0, f64::max);
    n <= tol * longest.sqrt()
}

/// True when a corner lies on the opposite edge, strictly inside it, within
/// `tol` ([`crate::tjunction::ON_EDGE`] of the diagonal): a sliver filling
/// the gap between an edge and the same edge split at that corner, as some
/// exporters close a T-junction. Written with 6 or 9 digits, its corner is
/// off the edge by the rounding, far more than the weld tolerance, so
/// [`collapses`] keeps it; its edges then made the edge non-manifold. Dropped,
/// it leaves a T-junction, which is stitched. (A needle, whose corner is near
/// an end of the opposite edge, is not a filler: dropping it would open a
/// hole nothing closes.)
fn fills(corners: [V3; 3], tol: f64) -> bool {
    (0..3).any(|k| inside_segment(corners[k], corners[(k + 1) % 3], corners[(k + 2) % 3], tol).is_some())
}

/// Merges vertices on a grid of spacing `tol`; returns the welded vertices,
/// the old → new map and the number of merged vertices. A vertex joins the
/// first vertex of its own cell (closer than `tol` in every coordinate). A
/// vertex alone in its cell joins the nearest first vertex of a neighbouring
/// cell within `tol / 2` in every coordinate (the lowest-numbered on ties):
/// copies of one corner rounded apart fell into neighbouring cells whenever
/// they straddled a cell boundary, however close they were. Within `tol / 2`,
/// a neighbour can only lie across the boundaries the vertex is nearer to:
/// seven cells to look in, not 26.
fn weld(surface: &TriSurface, tol: f64) -> (Vec<V3>, Vec<usize>, usize) {
    let tol = if tol > 0.0 { tol } else { f64::MIN_POSITIVE };
    let mut index: HashMap<[i64; 3], usize> = HashMap::with_capacity(surface.vertices.len());
    let mut used = vec![false; surface.vertices.len()];
    for t in &surface.triangles {
        for &v in t {
            used[v] = true;
        }
    }
    let mut vertices: Vec<V3> = Vec::new();
    let mut duplicates = 0;
    let mut map = Vec::with_capacity(surface.vertices.len());
    for (p, &u) in surface.vertices.iter().zip(&used) {
        let key = p.map(|c| (c / tol).round() as i64);
        let joined = index.get(&key).copied().or_else(|| neighbour_within(&index, &vertices, *p, tol));
        map.push(match joined {
            Some(i) => {
                duplicates += usize::from(u);
                i
            }
            None => {
                vertices.push(*p);
                index.insert(key, vertices.len() - 1);
                vertices.len() - 1
            }
        });
    }
    (vertices, map, duplicates)
}

/// The first vertex of one of the seven cells across the boundaries nearest
/// to `p` that lies within `tol / 2` of `p` in every coordinate: the nearest,
/// the lowest-numbered on ties.
fn neighbour_within(index: &HashMap<[i64; 3], usize>, vertices: &[V3], p: V3, tol: f64) -> Option<usize> {
    let scaled = p.map(|c| c / tol);
    let key = scaled.map(|c| c.round() as i64);
    let toward: [i64; 3] = std::array::from_fn(|c| if scaled[c] >= key[c] as f64 { 1 } else { -1 });
    let mut best: Option<(f64, usize)> = None;
    for step in 1..8 {
        let cell: [i64; 3] = std::array::from_fn(|c| key[c] + toward[c] * ((step >> c) & 1));
        let Some(&i) = index.get(&cell) else { continue };
        let gap = (0..3).map(|c| (vertices[i][c] - p[c]).abs()).fold(0.0, f64::max);
        if gap <= 0.5 * tol && best.is_none_or(|(g, j)| (gap, i) < (g, j)) {
            best = Some((gap, i));
        }
    }
    best.map(|(_, i)| i)
}

/// Orients triangles consistently per component; returns how many were
/// flipped, and the components. Fills the edge and component counts of `report`.
fn orient(
    vertices: &[V3],
    triangles: &mut [[usize; 3]],
    report: &mut SurfaceReport,
) -> (usize, Vec<Component>) {
    // (min vertex, max vertex, triangle, traversed min→max)
    let mut edges: Vec<(usize, usize, usize, bool)> = Vec::with_capacity(3 * triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), t, a < b));
        }
    }
    edges.sort_unstable();
    // Adjacency across manifold edges: (neighbour, same traversal direction).
    let mut adjacency: Vec<Vec<(usize, bool)>> = vec![Vec::new(); triangles.len()];
    let mut start = 0;
    while start < edges.len() {
        let mut end = start + 1;
        while end < edges.len() && edges[end].0 == edges[start].0 && edges[end].1 == edges[start].1 {
            end += 1;
        }
        match end - start {
            1 => report.open_boundary_edges += 1,
            2 => {
                let (s, t) = (edges[start], edges[start + 1]);
                let same = s.3 == t.3;
                report.inconsistent_edges += usize::from(same);
                adjacency[s.2].push((t.2, same));
                adjacency[t.2].push((s.2, same));
            }
            _ => report.non_manifold_edges += 1,
        }
        start = end;
    }
    let mut flip = vec![false; triangles.len()];
    let mut seen = vec![false; triangles.len()];
    let mut components = Vec::new();
    for seed in 0..triangles.len() {
        if seen[seed] {
            continue;
        }
        seen[seed] = true;
        let mut component = vec![seed];
        let mut next = 0;
        while next < component.len() {
            let t = component[next];
            next += 1;
            for &(n, same) in &adjacency[t] {
                if !seen[n] {
                    seen[n] = true;
                    flip[n] = flip[t] ^ same;
                    component.push(n);
                }
            }
        }
        let closed = component.iter().all(|&t| adjacency[t].len() == 3);
        let volume = signed_volume(vertices, triangles, &component, &flip, closed);
        let reverse = volume < 0.0;
        component.iter().for_each(|&t| flip[t] ^= reverse);
        let turned = component.iter().filter(|&&t| flip[t]).count();
        components.push(Component {
            closed,
            volume: volume.abs(),
            given_outward: 2 * turned <= component.len(),
            triangles: component,
        });
    }
    report.components = components.len();
    let outward: Vec<[usize; 3]> =
        triangles.iter().zip(&flip).map(|(t, &f)| if f { [t[0], t[2], t[1]] } else { *t }).collect();
    let nesting = nest(vertices, &outward, &components);
    for (c, component) in components.iter().enumerate() {
        let inward = nesting.inward[c];
        report.enclosed_volume_m3 += if inward { -component.volume } else { component.volume };
        report.cavities += usize::from(inward);
        component.triangles.iter().for_each(|&t| flip[t] ^= inward);
    }
    if let Some(&first) = nesting.same_facing.first() {
        report.warnings.push(same_facing_warning(
            vertices,
            &outward,
            &components[first],
            nesting.same_facing.len(),
        ));
    }
    let mut flipped = 0;
    for (t, f) in triangles.iter_mut().zip(flip) {
        if f {
            t.swap(1, 2);
            flipped += 1;
        }
    }
    (flipped, components)
}

/// Says that closed parts inside others were kept solid, and how a cavity is marked.
fn same_facing_warning(vertices: &[V3], triangles: &[[usize; 3]], first: &Component, count: usize) -> String {
    let p = vertices[triangles[first.triangles[0]][0]];
    format!(
        "{count} closed part(s) lie inside another closed part and face the same way, first near ({:.4}, {:.4}, \
         {:.4}) m: meshed as solid; if a part is the inner wall of a hollow object, orient its triangles inward \
         (towards the cavity)",
        p[0], p[1], p[2]
    )
}

/// Signed volume of a component under the given flips, by the divergence
/// theorem: `V = Σ_t (a − o)·((b − o) × (c − o)) / 6`. On a closed component
/// every origin `o` gives the same; on an open one `o` decides how its holes
/// are closed (by cones from `o` to their rims), so `o` is the mean of the
/// open edges' ends: a planar hole is capped flat, as the winding number
/// caps it, whatever the order of the triangles. (About the first corner of
/// the first triangle, an open cymbal read 2.3·10⁻⁴ or 7.0·10⁻⁴ m³ by the
/// order of its triangles, and the cell size followed.)
fn signed_volume(
    vertices: &[V3],
    triangles: &[[usize; 3]],
    component: &[usize],
    flip: &[bool],
    closed: bool,
) -> f64 {
    let first = vertices[triangles[component[0]][0]];
    let origin = if closed { first } else { rim_centre(vertices, triangles, component).unwrap_or(first) };
    let (mut volume, mut area) = (0.0, 0.0);
    for &t in component {
        let [a, b, c] = triangles[t].map(|v| sub(vertices[v], origin));
        let v = dot(a, cross(b, c)) / 6.0;
        volume += if flip[t] { -v } else { v };
        area += norm(area_vector(a, b, c));
    }
    // A flat part (a lone triangle of a cracked soup, a flat sheet) encloses
    // nothing, but its sum is rounding of either sign: read as a volume it
    // would turn the part at random and size the cells by 2V/A ≈ 10⁻¹⁸ m.
    if volume.abs() <= FLAT_VOLUME * area.powf(1.5) {
        0.0
    } else {
        volume
    }
}

/// Volume over area^(3/2) at or below which a part is flat: far above the
/// rounding of its sum (≈ 10⁻¹³ for a 1 mm triangle 1 m from the origin),
/// far below a real body (a 10 µm foil 10 cm across has 4·10⁻⁷).
const FLAT_VOLUME: f64 = 1e-9;

/// The mean of the ends of the component's open edges (those of one of its
/// triangles only), summed in vertex order; `None` when it has none.
fn rim_centre(vertices: &[V3], triangles: &[[usize; 3]], component: &[usize]) -> Option<V3> {
    let mut edges: Vec<(usize, usize)> = component
        .iter()
        .flat_map(|&t| (0..3).map(move |k| (triangles[t][k], triangles[t][(k + 1) % 3])))
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    edges.sort_unstable();
    let mut ends = Vec::new();
    for (i, e) in edges.iter().enumerate() {
        let repeated = (i > 0 && edges[i - 1] == *e) || edges.get(i + 1) == Some(e);
        if !repeated {
            ends.extend([e.0, e.1]);
        }
    }
    if ends.is_empty() {
        return None;
    }
    ends.sort_unstable();
    let sum = ends.iter().fold([0.0; 3], |s, &v| add(s, vertices[v]));
    Some(scale(sum, 1.0 / ends.len() as f64))
}

/// Says which faces were written twice and were meshed once. Touching
/// parts are not mentioned: they were one body before as well.
fn coincident_warning(c: &Coincident) -> Option<String> {
    let mut said = Vec::new();
    if c.double_sided > 0 {
        said.push(format!(
            "{} face(s) are written once for each side (a double-sided export)",
            c.double_sided
        ));
    }
    if c.repeated > 0 {
        said.push(format!("{} triangle(s) repeat another (a duplicated export)", c.repeated));
    }
    (!said.is_empty()).then(|| format!("{}: each face is meshed once", said.join("; ")))
}

/// Says that a double-sided open sheet was left out, and how to keep it.
fn sheet_sides_warning(faces: usize) -> Option<String> {
    (faces > 0).then(|| {
        format!(
            "{faces} face(s) of an open sheet are written once for each side (a double-sided export): a sheet \
             without thickness encloses nothing, so they are left out; give it a thickness (--sheet-thickness M) \
             to mesh it"
        )
    })
}

/// An open surface (holes, a sheet without thickness) is meshed as the
/// solid its winding number encloses: a hole is capped, an open shell is
/// filled. Said, because that may not be the object the user meant (an
/// open hemisphere of zero thickness became an 8 kg half-ball).
fn open_warning(open_edges: usize) -> Option<String> {
    (open_edges > 0).then(|| {
        format!(
            "the surface is open ({open_edges} edges belong to one triangle only): it is meshed as the solid its \
             winding number encloses, so holes are capped and an open shell is filled; close the surface, or give \
             a sheet its thickness (--sheet-thickness M), if that is not the object"
        )
    })
}

impl SurfaceReport {
    /// Removes the warnings about open sheets (the open surface, a
    /// double-sided sheet left out): for a caller that gives open parts a
    /// thickness (`TetOptions::sheet_thickness`), where they do not hold.
    pub fn drop_open_warning(&mut self) {
        let sheet_warnings =
            [open_warning(self.open_boundary_edges), sheet_sides_warning(self.double_sided_sheet_faces)];
        for w in sheet_warnings.into_iter().flatten() {
            self.warnings.retain(|x| *x != w);
        }
    }
}
