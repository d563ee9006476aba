//! Thin walls meshed in layers: prisms across the wall, three tets each.
//!
//! A shell (a bell, a bowl, a cup, a closed plate, a pipe) is a closed
//! surface whose area lies in pairs of skins a wall thickness `t` apart,
//! joined at rims. Stuffing needs cells finer than `t` everywhere (the
//! corpus bell, `t` = 1.5 mm on 20 cm: 2 M tets, refused); a layer of
//! 10-node tets across the wall, with edges along it of two wall
//! thicknesses, keeps the bending modes of the generated bowls within about
//! 1 % (`modal_mesh::MAX_CURVED_CELL_PER_WALL`).
//!
//! Steps ([`layered`]):
//! 1. **Pairs.** From each triangle's centroid a ray along −n: the triangle
//!    is paired when the ray leaves the solid, within [`MAX_WALL_FRACTION`]
//!    of the diagonal, through an opposite-facing triangle (`n·n' < −½`).
//! 2. **Skins.** Paired triangles joined by manifold edges; each skin's
//!    partner is the skin most of its rays (by area) reach. Skins must pair
//!    two by two (outer ↔ inner); a skin that faces itself (a handle's tube)
//!    or several others means the body is no shell, and stuffing is used.
//!    Paired triangles must hold [`MIN_PAIRED_AREA`] of the area (the rest
//!    are rims).
//! 3. **Master skin**, the larger of each pair, refined by edge bisection
//!    until no edge exceeds the in-plane size (conforming: a triangle splits
//!    by how many of its edges were split).
//! 4. **Columns.** From each master vertex a ray along −n_v (the area-weighted
//!    normal of its master triangles) to the opposite skin, divided into
//!    `layers` equal steps.
//! 5. **Prisms** between a master triangle and its columns, split into three
//!    tets by the smallest-vertex rule (Dompierre et al. 1999, "How to
//!    subdivide pyramids, prisms and hexahedra into tetrahedra"): each quad
//!    face's diagonal starts at its lowest-numbered column's outer node, so
//!    two prisms sharing a face cut it alike and the mesh is conforming.
//! 6. **Checks**: every tet keeps at least [`MIN_VOLUME_RATIO`] of the volume
//!    its place in an ideal straight prism would have (no folds), and the
//!    mesh volume is within [`VOLUME_TOLERANCE`] of the enclosed volume (a
//!    thick part no pair of skins covers fails it).
//!
//! The rims are replaced by the prisms' side faces (a bell's lip band of
//! height `t/2` below its walls' ends is not meshed: it moves the rim by at
//! most `t/2`).

use std::collections::HashMap;

use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::geom::{add, area_vector, dot, norm, orient6, scale, sub, V3};

/// Walls up to this fraction of the bounding-box diagonal can pair.
pub const MAX_WALL_FRACTION: f64 = 0.1;

/// Paired skins must hold at least this fraction of the surface area.
pub const MIN_PAIRED_AREA: f64 = 0.8;

/// A skin's partner must receive at least this fraction (by area) of its rays.
pub const MIN_PARTNER_SHARE: f64 = 0.8;

/// Each tet keeps at least this fraction of its ideal-prism volume.
pub const MIN_VOLUME_RATIO: f64 = 0.05;

/// Largest relative difference between the mesh volume and the enclosed one.
pub const VOLUME_TOLERANCE: f64 = 0.05;

/// Refinement passes of the master skin (each at least halves the longest edge).
const MAX_PASSES: usize = 12;

/// A layered mesh of a thin-walled solid.
#[derive(Clone, Debug)]
pub(crate) struct Layered {
    /// Node positions [m].
    pub nodes: Vec<V3>,
    /// Positively oriented 4-node tets.
    pub tets: Vec<[usize; 4]>,
    /// Tet layers across the wall.
    pub layers: usize,
    /// Area-weighted median wall thickness of the paired triangles [m].
    pub wall_m: f64,
    /// Longest master-skin edge after refinement [m].
    pub longest_edge_m: f64,
    /// Shortest edge of the tets [m].
    pub shortest_edge_m: f64,
}

/// Why a surface was not meshed in layers (stuffing is used instead).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum NotLayered {
    /// Too little of the area lies in paired skins.
    Unpaired { paired_fraction: f64 },
    /// The skins do not pair two by two.
    Skins,
    /// The column at this point found no opposite skin.
    Column { at: V3 },
    /// A tet at this point folded (its volume changed sign or nearly vanished).
    Fold { at: V3 },
    /// The layers miss part of the volume (a thick part).
    Volume { ratio: f64 },
    /// More tets than allowed at in-plane size `in_plane_m`.
    TooMany { estimated: usize, in_plane_m: f64 },
}

/// The size of the layered mesh: the in-plane edge and the tet limit.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LayerSizing {
    /// Longest edge along the wall [m]; `None`: [`wall_cells`] wall thicknesses.
    pub in_plane_m: Option<f64>,
    /// Edges along the wall in wall thicknesses when `in_plane_m` is `None`.
    pub wall_cells: f64,
    /// Upper bound of the in-plane edge when it follows the wall [m].
    pub max_in_plane_m: f64,
    /// Refuse (as [`NotLayered::TooMany`]) beyond this many tets.
    pub max_tets: usize,
}

/// Meshes the closed, outward-oriented surface (`vertices`, `triangles`,
/// with `bvh` over the same triangles) in layers, if it is a shell (module doc).
pub(crate) fn layered(
    vertices: &[V3],
    triangles: &[[usize; 3]],
    bvh: &Bvh,
    diagonal: f64,
    enclosed_volume: f64,
    sizing: LayerSizing,
) -> Result<Layered, NotLayered> {
    let pairs = pair_triangles(vertices, triangles, bvh, diagonal);
    let total_area: f64 = pairs.iter().map(|p| p.area).sum();
    let paired_area: f64 = pairs.iter().filter(|p| p.partner.is_some()).map(|p| p.area).sum();
    let paired_fraction = if total_area > 0.0 { paired_area / total_area } else { 0.0 };
    if paired_fraction < MIN_PAIRED_AREA {
        return Err(NotLayered::Unpaired { paired_fraction });
    }
    let (master, opposite) = master_triangles(triangles, &pairs)?;
    let wall_m = median_wall(&pairs);
    let in_plane = sizing.in_plane_m.unwrap_or((sizing.wall_cells * wall_m).min(sizing.max_in_plane_m));
    let layers = ((wall_m / in_plane).round() as usize).max(1);
    let master_area: f64 = master.iter().map(|&t| pairs[t].area).sum();
    // Refined triangles ≈ area / (√3/4 · h²); three tets per prism and layer.
    let estimated = (3.0 * layers as f64 * master_area / (0.433 * in_plane * in_plane)) as usize;
    if estimated > sizing.max_tets {
        return Err(NotLayered::TooMany { estimated, in_plane_m: in_plane });
    }
    let mut skin = Skin::from_triangles(vertices, triangles, &master);
    skin.refine(in_plane, sizing.max_tets / (3 * layers) + 1)
        .map_err(|count| NotLayered::TooMany { estimated: 3 * layers * count, in_plane_m: in_plane })?;
    let opposite = Bvh::new(opposite.iter().map(|&t| triangles[t].map(|v| vertices[v])).collect());
    let ends = skin.column_ends(&opposite, 3.0 * max_wall(&pairs))?;
    let mesh = skin.prisms(&ends, layers)?;
    let volume: f64 = mesh
        .tets
        .iter()
        .map(|t| orient6(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]) / 6.0)
        .sum();
    let ratio = volume / enclosed_volume;
    if !((1.0 - VOLUME_TOLERANCE)..=(1.0 + VOLUME_TOLERANCE)).contains(&ratio) {
        return Err(NotLayered::Volume { ratio });
    }
    let longest_edge_m = skin.longest_edge();
    let shortest_edge_m = shortest_edge(&mesh.nodes, &mesh.tets);
    Ok(Layered { nodes: mesh.nodes, tets: mesh.tets, layers, wall_m, longest_edge_m, shortest_edge_m })
}

/// A triangle's pairing: its area, its wall thickness and the triangle its ray reached.
#[derive(Clone, Copy, Debug)]
struct Pair {
    area: f64,
    thickness: f64,
    partner: Option<usize>,
}

fn unit(v: V3) -> V3 {
    let n = norm(v);
    if n > 0.0 {
        scale(v, 1.0 / n)
    } else {
        v
    }
}

/// Step 1 of the module doc, per triangle.
fn pair_triangles(vertices: &[V3], triangles: &[[usize; 3]], bvh: &Bvh, diagonal: f64) -> Vec<Pair> {
    let normals: Vec<V3> =
        triangles.iter().map(|t| area_vector(vertices[t[0]], vertices[t[1]], vertices[t[2]])).collect();
    let eps = 1e-7 * diagonal;
    let reach = MAX_WALL_FRACTION * diagonal;
    triangles
        .par_iter()
        .enumerate()
        .map(|(i, t)| {
            let area = norm(normals[i]);
            let n = unit(normals[i]);
            let c = scale(add(add(vertices[t[0]], vertices[t[1]]), vertices[t[2]]), 1.0 / 3.0);
            let from = sub(c, scale(n, eps));
            let to = sub(c, scale(n, reach));
            let hit =
                bvh.first_crossing(from, to).filter(|&(_, j)| j != i && dot(n, unit(normals[j])) < -0.5);
            match hit {
                Some((s, j)) => Pair { area, thickness: eps + s * (reach - eps), partner: Some(j) },
                None => Pair { area, thickness: f64::INFINITY, partner: None },
            }
        })
        .collect()
}

/// Step 2: the master triangles (the larger skin of each pair) and the
/// others of the paired skins, or why there are none.
fn master_triangles(
    triangles: &[[usize; 3]],
    pairs: &[Pair],
) -> Result<(Vec<usize>, Vec<usize>), NotLayered> {
    let skin_of = paired_components(triangles, pairs);
    let skins = skin_of.iter().flatten().map(|&s| s + 1).max().unwrap_or(0);
    // Area of each skin and, per skin, the area its rays send to each other skin.
    let mut area = vec![0.0; skins];
    let mut sent: Vec<HashMap<usize, f64>> = vec![HashMap::new(); skins];
    for (t, p) in pairs.iter().enumerate() {
        let (Some(s), Some(j)) = (skin_of[t], p.partner) else { continue };
        area[s] += p.area;
        if let Some(r) = skin_of[j] {
            *sent[s].entry(r).or_default() += p.area;
        }
    }
    let partner: Vec<Option<usize>> = (0..skins)
        .map(|s| {
            let best = sent[s].iter().max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(a.0)));
            best.filter(|&(&r, &a)| r != s && a >= MIN_PARTNER_SHARE * area[s]).map(|(&r, _)| r)
        })
        .collect();
    let mut is_master = vec![false; skins];
    for s in 0..skins {
        let r = partner[s].ok_or(NotLayered::Skins)?;
        if partner[r] != Some(s) {
            return Err(NotLayered::Skins);
        }
        is_master[s] = area[s] > area[r] || (area[s] == area[r] && s < r);
    }
    let paired = (0..triangles.len()).filter(|&t| skin_of[t].is_some());
    Ok(paired.partition(|&t| skin_of[t].is_some_and(|s| is_master[s])))
}

/// Connected components of the paired triangles over manifold edges.
fn paired_components(triangles: &[[usize; 3]], pairs: &[Pair]) -> Vec<Option<usize>> {
    let mut by_edge: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            by_edge.entry((a.min(b), a.max(b))).or_default().push(t);
        }
    }
    let mut skin_of: Vec<Option<usize>> = vec![None; triangles.len()];
    let mut next = 0;
    for start in 0..triangles.len() {
        if pairs[start].partner.is_none() || skin_of[start].is_some() {
            continue;
        }
        skin_of[start] = Some(next);
        let mut stack = vec![start];
        while let Some(t) = stack.pop() {
            for k in 0..3 {
                let (a, b) = (triangles[t][k], triangles[t][(k + 1) % 3]);
                let shared = &by_edge[&(a.min(b), a.max(b))];
                if shared.len() != 2 {
                    continue;
                }
                let u = if shared[0] == t { shared[1] } else { shared[0] };
                if pairs[u].partner.is_some() && skin_of[u].is_none() {
                    skin_of[u] = Some(next);
                    stack.push(u);
                }
            }
        }
        next += 1;
    }
    skin_of
}

/// Area-weighted median thickness of the paired triangles.
fn median_wall(pairs: &[Pair]) -> f64 {
    let mut walls: Vec<(f64, f64)> =
        pairs.iter().filter(|p| p.partner.is_some()).map(|p| (p.thickness, p.area)).collect();
    walls.sort_by(|a, b| a.0.total_cmp(&b.0));
    let half = 0.5 * walls.iter().map(|w| w.1).sum::<f64>();
    let mut acc = 0.0;
    for (t, a) in &walls {
        acc += a;
        if acc >= half {
            return *t;
        }
    }
    walls.last().map_or(0.0, |w| w.0)
}

fn max_wall(pairs: &[Pair]) -> f64 {
    pairs.iter().filter(|p| p.partner.is_some()).map(|p| p.thickness).fold(0.0, f64::max)
}

/// The master skin as its own triangle mesh: vertex positions, triangles
/// (outward, counter-clockwise) and, per triangle, the input triangle it lies in.
struct Skin {
    vertices: Vec<V3>,
    triangles: Vec<[usize; 3]>,
}

/// The layered tets and their nodes.
struct Prisms {
    nodes: Vec<V3>,
    tets: Vec<[usize; 4]>,
}

impl Skin {
    fn from_triangles(vertices: &[V3], triangles: &[[usize; 3]], master: &[usize]) -> Skin {
        let mut index: HashMap<usize, usize> = HashMap::new();
        let mut out = Skin { vertices: Vec::new(), triangles: Vec::with_capacity(master.len()) };
        for &t in master {
            let tri = triangles[t].map(|v| {
                *index.entry(v).or_insert_with(|| {
                    out.vertices.push(vertices[v]);
                    out.vertices.len() - 1
                })
            });
            out.triangles.push(tri);
        }
        out
    }

    fn longest_edge(&self) -> f64 {
        self.triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .map(|(a, b)| norm(sub(self.vertices[a], self.vertices[b])))
            .fold(0.0, f64::max)
    }

    /// Splits every edge longer than `h` at its midpoint until none is;
    /// `Err(count)` when the triangles would exceed `max_triangles`.
    fn refine(&mut self, h: f64, max_triangles: usize) -> Result<(), usize> {
        for _ in 0..MAX_PASSES {
            let mut mid: HashMap<(usize, usize), usize> = HashMap::new();
            for t in &self.triangles {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    let key = (a.min(b), a.max(b));
                    if !mid.contains_key(&key) && norm(sub(self.vertices[a], self.vertices[b])) > h {
                        let m = scale(add(self.vertices[a], self.vertices[b]), 0.5);
                        self.vertices.push(m);
                        mid.insert(key, self.vertices.len() - 1);
                    }
                }
            }
            if mid.is_empty() {
                return Ok(());
            }
            let split = |a: usize, b: usize| mid.get(&(a.min(b), a.max(b))).copied();
            let mut next = Vec::with_capacity(2 * self.triangles.len());
            for &t in &self.triangles {
                self.split_triangle(t, &split, &mut next);
            }
            self.triangles = next;
            if self.triangles.len() > max_triangles {
                return Err(self.triangles.len());
            }
        }
        Ok(())
    }

    /// Appends the pieces of triangle `t` given its split edges (orientation kept).
    fn split_triangle(
        &self,
        t: [usize; 3],
        split: &impl Fn(usize, usize) -> Option<usize>,
        out: &mut Vec<[usize; 3]>,
    ) {
        let m: [Option<usize>; 3] = std::array::from_fn(|k| split(t[k], t[(k + 1) % 3]));
        match m.iter().filter(|x| x.is_some()).count() {
            0 => out.push(t),
            3 => {
                let [ab, bc, ca] = m.map(|x| x.unwrap_or_default());
                out.extend([[t[0], ab, ca], [ab, t[1], bc], [ca, bc, t[2]], [ab, bc, ca]]);
            }
            1 => {
                // Rotate so the split edge is (a, b).
                let k = m.iter().position(|x| x.is_some()).unwrap_or(0);
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let ab = m[k].unwrap_or_default();
                out.extend([[a, ab, c], [ab, b, c]]);
            }
            _ => {
                // Rotate so the unsplit edge is (c, a): (a, b) and (b, c) are split.
                let k = (m.iter().position(|x| x.is_none()).unwrap_or(0) + 1) % 3;
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let (ab, bc) = (m[k].unwrap_or_default(), m[(k + 1) % 3].unwrap_or_default());
                out.push([ab, b, bc]);
                // The quad a, ab, bc, c by its shorter diagonal.
                let p = |v: usize| self.vertices[v];
                if norm(sub(p(a), p(bc))) <= norm(sub(p(ab), p(c))) {
                    out.extend([[a, ab, bc], [a, bc, c]]);
                } else {
                    out.extend([[a, ab, c], [ab, bc, c]]);
                }
            }
        }
    }

    /// Step 4: where each vertex's column ends: the closest point of the
    /// opposite skins, within `reach`. Closest points, not rays along the
    /// vertex normals: at a crease (a bell's lip) normals tilt by half its
    /// angle and neighbouring rays cross inside a wall narrower than that
    /// tilt; the closest-point map of two skins closer than their radii of
    /// curvature does not fold, and no ray can slip through a seam.
    fn column_ends(&self, opposite: &Bvh, reach: f64) -> Result<Vec<V3>, NotLayered> {
        self.vertices
            .par_iter()
            .map(|&v| {
                let end = opposite.closest(v).filter(|&e| norm(sub(e, v)) <= reach);
                end.ok_or(NotLayered::Column { at: v })
            })
            .collect()
    }

    /// Step 5: the prisms of every triangle and layer, split into tets, checked for folds.
    fn prisms(&self, ends: &[V3], layers: usize) -> Result<Prisms, NotLayered> {
        let per = layers + 1;
        let mut nodes = Vec::with_capacity(self.vertices.len() * per);
        for (&v, &e) in self.vertices.iter().zip(ends) {
            for k in 0..per {
                nodes.push(add(v, scale(sub(e, v), k as f64 / layers as f64)));
            }
        }
        let tets: Result<Vec<Vec<[usize; 4]>>, NotLayered> = self
            .triangles
            .par_iter()
            .map(|&t| {
                let mut out = Vec::with_capacity(3 * layers);
                for k in 0..layers {
                    for tet in split_prism(t, k, per) {
                        out.push(self.oriented(tet, t, &nodes, ends, per)?);
                    }
                }
                Ok(out)
            })
            .collect();
        Ok(Prisms { nodes, tets: tets?.into_iter().flatten().collect() })
    }

    /// `tet` (of the prism on triangle `t`) positively oriented, if it keeps
    /// the sign and at least [`MIN_VOLUME_RATIO`] of its volume in the ideal
    /// prism (columns along the triangle's own normal, each as long as the
    /// mean of its three columns).
    fn oriented(
        &self,
        tet: [usize; 4],
        t: [usize; 3],
        nodes: &[V3],
        ends: &[V3],
        per: usize,
    ) -> Result<[usize; 4], NotLayered> {
        let layers = (per - 1) as f64;
        let length = t.iter().map(|&c| norm(sub(ends[c], self.vertices[c]))).sum::<f64>() / 3.0;
        let normal = unit(area_vector(self.vertices[t[0]], self.vertices[t[1]], self.vertices[t[2]]));
        let ideal: [V3; 4] =
            tet.map(|n| sub(self.vertices[n / per], scale(normal, length * (n % per) as f64 / layers)));
        let expected = orient6(ideal[0], ideal[1], ideal[2], ideal[3]);
        let actual = orient6(nodes[tet[0]], nodes[tet[1]], nodes[tet[2]], nodes[tet[3]]);
        if expected == 0.0 || actual * expected.signum() < MIN_VOLUME_RATIO * expected.abs() {
            return Err(NotLayered::Fold { at: self.vertices[t[0]] });
        }
        Ok(if expected > 0.0 { tet } else { [tet[0], tet[1], tet[3], tet[2]] })
    }
}

/// The three tets of the prism on triangle `t` between layers `k` (outer)
/// and `k + 1`, by the smallest-vertex rule (module doc, step 5); node of
/// column `c`, layer `l` is `c · per + l`.
fn split_prism(t: [usize; 3], k: usize, per: usize) -> [[usize; 4]; 3] {
    let low = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
    let (a, b, c) = (t[low], t[(low + 1) % 3], t[(low + 2) % 3]);
    let top = |v: usize| v * per + k;
    let bottom = |v: usize| v * per + k + 1;
    let first = [top(a), bottom(a), bottom(b), bottom(c)];
    if b < c {
        [first, [top(a), top(b), top(c), bottom(c)], [top(a), top(b), bottom(c), bottom(b)]]
    } else {
        [first, [top(a), top(b), top(c), bottom(b)], [top(a), top(c), bottom(c), bottom(b)]]
    }
}

fn shortest_edge(nodes: &[V3], tets: &[[usize; 4]]) -> f64 {
    tets.par_iter()
        .map(|t| {
            let mut best = f64::INFINITY;
            for i in 0..4 {
                for j in i + 1..4 {
                    best = best.min(norm(sub(nodes[t[i]], nodes[t[j]])));
                }
            }
            best
        })
        .reduce(|| f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbouring_prisms_cut_their_shared_face_alike() {
        // Two prisms on triangles (0, 1, 2) and (2, 1, 3) share face 1-2.
        let per = 2;
        let diagonal = |tets: [[usize; 4]; 3]| {
            let on_face = |n: usize| n / per == 1 || n / per == 2;
            let mut edges = Vec::new();
            for t in tets {
                for i in 0..4 {
                    for j in i + 1..4 {
                        let (a, b) = (t[i], t[j]);
                        if on_face(a) && on_face(b) && a / per != b / per && a % per != b % per {
                            edges.push((a.min(b), a.max(b)));
                        }
                    }
                }
            }
            edges.sort_unstable();
            edges.dedup();
            edges
        };
        let left = diagonal(split_prism([0, 1, 2], 0, per));
        let right = diagonal(split_prism([2, 1, 3], 0, per));
        assert_eq!(left.len(), 1, "one diagonal on the shared face: {left:?}");
        assert_eq!(left, right);
    }
}
