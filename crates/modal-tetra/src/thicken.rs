//! Open sheets given a thickness (`--sheet-thickness`).
//!
//! Game and CAD assets often model sheet-like objects (a cymbal, a gong, a
//! sign, a leaf, sheet metal) as one surface with no thickness. As a solid
//! such a surface encloses nothing, and its winding number fills an
//! arbitrary slab. Given the real thickness `t`, every open part (an
//! edge-connected component with a boundary edge) becomes a closed shell:
//! two offset copies of it, `x ± d(x)·t/2`, the lower one reversed so both
//! face out, joined along every boundary edge by a strip of two triangles.
//! The shell then meshes like any thin wall (in layers, module `shell`).
//!
//! The offset direction at a vertex is the area-weighted mean of its
//! triangles' normals, lengthened by `1 / min_f (n̂·n_f)` (at most 2) so the
//! wall keeps its thickness across a crease (a mitre: `√2` at a 90° fold).
//! Closed parts are kept as they are, so a solid with a sheet attached (a
//! post and its sign) is the union of both.

use std::collections::HashMap;

use crate::diagnose::repair_keeping_sheets;
use crate::geom::{add, area_vector, dot, norm, scale, V3};
use crate::stuff::edge_triangles;
use crate::{TetraError, TriSurface};

/// Largest mitre factor of an offset (a fold sharper than 120° gets no more).
pub const MAX_MITRE: f64 = 2.0;

/// A thickness above this share of the sheets' size (√ of their area) is
/// warned about: likely a thickness in millimetres given as metres.
pub const SLAB_SHARE: f64 = 0.25;

/// What thickening did.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Thickened {
    /// Open parts turned into shells.
    pub(crate) sheets: usize,
    /// Their area, one side [m²].
    pub(crate) sheet_area_m2: f64,
}

impl Thickened {
    /// A warning when `thickness_m` is more than [`SLAB_SHARE`] of the sheets' size.
    pub(crate) fn slab_warning(&self, thickness_m: f64) -> Option<String> {
        let size = self.sheet_area_m2.sqrt();
        (self.sheets > 0 && thickness_m > SLAB_SHARE * size).then(|| {
            format!(
                "the sheet thickness {thickness_m} m is more than a quarter of the open parts' size (√area = \
                 {size:.3e} m): they became slabs; is the thickness in metres?"
            )
        })
    }
}

/// `surface` with every open part a closed shell of `thickness_m` (module doc).
pub(crate) fn thicken_open_sheets(
    surface: &TriSurface,
    thickness_m: f64,
) -> Result<(TriSurface, Thickened), TetraError> {
    if !(thickness_m.is_finite() && thickness_m > 0.0) {
        return Err(TetraError::InvalidOption {
            name: "sheet thickness",
            reason: format!("{thickness_m} is not a positive length in metres"),
        });
    }
    // Welded, degenerate triangles dropped, each component oriented consistently.
    let repaired = repair_keeping_sheets(surface);
    let (vertices, triangles) = (&repaired.vertices, &repaired.triangles);
    let edges = edge_triangles(triangles);
    // Components joined across manifold edges only, so a closed part with a sheet
    // fixed along one of its edges (three triangles there) stays closed.
    let mut component = vec![0; triangles.len()];
    for (c, part) in repaired.components.iter().enumerate() {
        part.triangles.iter().for_each(|&t| component[t] = c);
    }
    let mut open = vec![false; repaired.components.len()];
    for tris in edges.values().filter(|t| t.len() == 1) {
        open[component[tris[0]]] = true;
    }
    let mut out = TriSurface { vertices: vertices.clone(), ..Default::default() };
    let mut report = Thickened { sheets: open.iter().filter(|&&o| o).count(), ..Default::default() };
    // Per vertex of an open part: the indices of its upper and lower copies.
    let mut copies: HashMap<usize, (usize, usize)> = HashMap::new();
    let offsets = offset_directions(vertices, triangles, |t| open[component[t]]);
    for (t, tri) in triangles.iter().enumerate() {
        if !open[component[t]] {
            out.triangles.push(*tri);
            continue;
        }
        report.sheet_area_m2 += norm(area_vector(vertices[tri[0]], vertices[tri[1]], vertices[tri[2]]));
        let [a, b, c] = tri.map(|v| {
            *copies.entry(v).or_insert_with(|| {
                let d = scale(offsets[&v], 0.5 * thickness_m);
                out.vertices.push(add(vertices[v], d));
                out.vertices.push(add(vertices[v], scale(d, -1.0)));
                (out.vertices.len() - 2, out.vertices.len() - 1)
            })
        });
        out.triangles.push([a.0, b.0, c.0]);
        out.triangles.push([a.1, c.1, b.1]);
    }
    // Rims: each boundary edge a → b (in its triangle's order) gets the strip
    // (a⁺, a⁻, b⁻), (a⁺, b⁻, b⁺), which faces out across the edge.
    let mut rims: Vec<(usize, usize)> = edges
        .iter()
        .filter(|(_, t)| t.len() == 1)
        .map(|(&(u, v), t)| directed(triangles[t[0]], u, v))
        .collect();
    rims.sort_unstable();
    for (a, b) in rims {
        let ((a_up, a_down), (b_up, b_down)) = (copies[&a], copies[&b]);
        out.triangles.push([a_up, a_down, b_down]);
        out.triangles.push([a_up, b_down, b_up]);
    }
    out.parts.push(("surface".to_string(), 0..out.triangles.len()));
    Ok((out, report))
}

/// Edge `{u, v}` in the order triangle `tri` runs along it.
fn directed(tri: [usize; 3], u: usize, v: usize) -> (usize, usize) {
    let k = tri.iter().position(|&x| x == u).unwrap_or(0);
    if tri[(k + 1) % 3] == v {
        (u, v)
    } else {
        (v, u)
    }
}

/// The mitred offset direction (module doc) of every vertex of the
/// triangles `selected` picks.
fn offset_directions(
    vertices: &[V3],
    triangles: &[[usize; 3]],
    selected: impl Fn(usize) -> bool,
) -> HashMap<usize, V3> {
    let mut sums: HashMap<usize, (V3, Vec<V3>)> = HashMap::new();
    for (_, tri) in triangles.iter().enumerate().filter(|&(t, _)| selected(t)) {
        let area = area_vector(vertices[tri[0]], vertices[tri[1]], vertices[tri[2]]);
        let unit = scale(area, 1.0 / norm(area));
        for &v in tri {
            let entry = sums.entry(v).or_insert(([0.0; 3], Vec::new()));
            entry.0 = add(entry.0, area);
            entry.1.push(unit);
        }
    }
    sums.into_iter()
        .map(|(v, (sum, normals))| {
            // Faces that cancel (a sheet folded flat onto itself): take the first face's normal.
            let mean = if norm(sum) > 0.0 { scale(sum, 1.0 / norm(sum)) } else { normals[0] };
            let worst = normals.iter().map(|&n| dot(mean, n)).fold(1.0, f64::min);
            (v, scale(mean, 1.0 / worst.max(1.0 / MAX_MITRE)))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> TriSurface {
        TriSurface {
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            parts: vec![("sheet".into(), 0..2)],
        }
    }

    #[test]
    fn a_square_sheet_becomes_a_closed_slab_of_the_thickness() {
        let (slab, report) = thicken_open_sheets(&square(), 0.1).unwrap();
        assert_eq!(report, Thickened { sheets: 1, sheet_area_m2: 1.0 });
        assert_eq!(report.slab_warning(0.1), None);
        // 2 given for 2 mm: a 1 m sheet 2 m thick is a slab, and the user is told.
        assert!(report.slab_warning(2.0).is_some_and(|w| w.contains("in metres")));
        let diagnosis = crate::diagnose(&slab);
        assert_eq!(diagnosis.open_boundary_edges, 0, "{diagnosis:?}");
        assert!((diagnosis.enclosed_volume_m3 - 0.1).abs() < 1e-12, "{}", diagnosis.enclosed_volume_m3);
        assert_eq!(slab.triangles.len(), 4 + 8);
    }

    #[test]
    fn a_fold_keeps_the_wall_thickness_and_closed_parts_are_kept() {
        // An L of two unit squares folded at 90° along the y axis: the mitre keeps the
        // wall 0.1 thick on both legs, so the volume is 2 × 0.1 less the corner's overlap.
        let mut l = square();
        l.vertices.extend([[0.0, 0.0, 1.0], [0.0, 1.0, 1.0]]);
        l.triangles.extend([[0, 3, 5], [0, 5, 4]]);
        let cube = crate::shapes::cuboid(0.1, 0.1, 0.1);
        let shift = l.vertices.len();
        l.vertices.extend(cube.vertices.iter().map(|p| [p[0] + 5.0, p[1], p[2]]));
        l.triangles.extend(cube.triangles.iter().map(|t| t.map(|v| v + shift)));
        let (out, report) = thicken_open_sheets(&l, 0.1).unwrap();
        assert_eq!(report.sheets, 1, "the cube is closed and kept");
        let diagnosis = crate::diagnose(&out);
        assert_eq!(diagnosis.open_boundary_edges, 0);
        // The L's cross-section: two 1 × 0.1 legs centred on the sheet, a mitred corner.
        let l_volume = 2.0 * 0.1 * 1.0;
        assert!(
            (diagnosis.enclosed_volume_m3 - (l_volume + 1e-3)).abs() < 1e-9,
            "{}",
            diagnosis.enclosed_volume_m3
        );
    }

    #[test]
    fn a_closed_part_with_a_fin_on_one_of_its_edges_is_kept() {
        // A 0.1 m cube and a 0.1 m square fin standing up from its top front
        // edge (three triangles on that edge). Joined across every edge they were
        // one open part, and the cube was doubled into offset copies; now only
        // the fin gets the wall: the cube's 12 triangles as they were, the fin's
        // two faces (4) and a rim strip on its three free edges (6).
        let mut s = crate::shapes::cuboid(0.1, 0.1, 0.1);
        let shift = s.vertices.len();
        let corner = |x: f64, z: f64| s.vertices.iter().position(|v| *v == [x, 0.1, z]).unwrap();
        let (a, b) = (corner(0.0, 0.1), corner(0.1, 0.1));
        s.vertices.extend([[0.0, 0.2, 0.1], [0.1, 0.2, 0.1]]);
        s.triangles.extend([[a, b, shift + 1], [a, shift + 1, shift]]);
        let (out, report) = thicken_open_sheets(&s, 0.01).unwrap();
        assert_eq!(report.sheets, 1);
        let cube_kept = s.vertices[..shift].iter().all(|p| out.vertices.contains(p));
        assert!(cube_kept && out.triangles.len() == 12 + 4 + 2 * 3, "{} triangles", out.triangles.len());
    }

    #[test]
    fn a_thickness_that_is_not_a_length_is_refused() {
        for t in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(thicken_open_sheets(&square(), t), Err(TetraError::InvalidOption { .. })));
        }
    }
}
