//! Steps 1–2 of the layered mesher (module `shell`): which triangles face
//! each other across a thin wall, and which of the skins they form carries
//! the prisms.
//!
//! 1. **Pairs.** From each triangle's centroid a ray along −n: the triangle
//!    is paired when the ray leaves the solid, within [`MAX_WALL_FRACTION`]
//!    of the diagonal, through an opposite-facing triangle (`n·n' < −½`).
//! 2. **Skins.** Paired triangles joined by manifold edges. Skins that face
//!    each other must fall on two sides (outer ↔ inner), each sending
//!    [`MIN_PARTNER_SHARE`] of its rays to the other side; one side of each
//!    group must be a single skin (the master), and each group one closed
//!    surface ([`master_sides`]). A skin that faces itself (a handle's tube)
//!    means the body is no shell. Paired triangles must hold
//!    [`MIN_PAIRED_AREA`] of the area (the rest are rims).
//!
//! On a smoothed scan (`noisy`), a few triangles whose rays the leftover
//! noise turned away stay unpaired inside a skin: a hole in the master
//! skin is a hole in the layers, and its rim, pulled to a speck by the
//! smoothing, gives flat tets. There, a patch of unpaired triangles smaller
//! than a disc of one wall's radius that borders a single skin joins it
//! ([`close_holes`]) before the skins are formed.

use std::collections::BTreeMap;

use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::geom::{add, area_vector, dot, norm, scale, sub, unit, V3};
use crate::shell::NotLayered;
use crate::stuff::{edge, edge_triangles, EdgeTriangles};

/// Walls up to this fraction of the bounding-box diagonal can pair.
pub const MAX_WALL_FRACTION: f64 = 0.1;

/// Paired skins must hold at least this fraction of the surface area.
pub const MIN_PAIRED_AREA: f64 = 0.8;

/// Each skin must send at least this fraction (by area) of its rays to the other side.
pub const MIN_PARTNER_SHARE: f64 = 0.8;

/// The paired skins of a shell: every triangle's pairing, the master
/// side's triangles (prisms hang from them) and the other side's.
pub(crate) struct Skins {
    pairs: Vec<Pair>,
    /// Triangles of the master side.
    pub master: Vec<usize>,
    /// Paired triangles of the other side.
    pub opposite: Vec<usize>,
}

impl Skins {
    /// Steps 1–2 of the module doc on the closed, outward surface
    /// (`bvh` over the same triangles) of `bodies` closed solids, with
    /// the small holes of a `noisy` surface closed.
    pub fn pair(
        vertices: &[V3],
        triangles: &[[usize; 3]],
        bvh: &Bvh,
        diagonal: f64,
        bodies: usize,
        noisy: bool,
    ) -> Result<Skins, NotLayered> {
        let mut pairs = pair_triangles(vertices, triangles, bvh, diagonal);
        let by_edge = edge_triangles(triangles);
        if noisy {
            let wall = median_wall(&pairs);
            close_holes(triangles, &by_edge, &mut pairs, std::f64::consts::PI * wall * wall);
        }
        let total_area: f64 = pairs.iter().map(|p| p.area).sum();
        let paired_area: f64 = pairs.iter().filter(|p| p.partner.is_some()).map(|p| p.area).sum();
        let paired_fraction = if total_area > 0.0 { paired_area / total_area } else { 0.0 };
        if paired_fraction < MIN_PAIRED_AREA {
            return Err(NotLayered::Unpaired { paired_fraction });
        }
        let (master, opposite) = master_triangles(triangles, &by_edge, &pairs, bodies)?;
        Ok(Skins { pairs, master, opposite })
    }

    /// Area-weighted median thickness of the paired triangles [m].
    pub fn median_wall(&self) -> f64 {
        median_wall(&self.pairs)
    }

    /// Thickest wall of the paired triangles [m].
    pub fn max_wall(&self) -> f64 {
        self.pairs.iter().filter(|p| p.partner.is_some()).map(|p| p.thickness).fold(0.0, f64::max)
    }

    /// Area of the master side [m²].
    pub fn master_area(&self) -> f64 {
        self.master.iter().map(|&t| self.pairs[t].area).sum()
    }
}

/// A triangle's pairing: its area, its wall thickness and the triangle its ray reached.
#[derive(Clone, Copy, Debug)]
struct Pair {
    area: f64,
    thickness: f64,
    partner: Option<usize>,
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

/// Step 2 of the module doc: the master triangles (the master side of each group of facing
/// skins, [`master_sides`]) and the others of the paired skins, or why there are none.
fn master_triangles(
    triangles: &[[usize; 3]],
    by_edge: &EdgeTriangles,
    pairs: &[Pair],
    bodies: usize,
) -> Result<(Vec<usize>, Vec<usize>), NotLayered> {
    let skin_of = paired_components(triangles, by_edge, pairs);
    let skins = skin_of.iter().flatten().map(|&s| s + 1).max().unwrap_or(0);
    // Area of each skin and, per skin, the area its rays send to each other skin.
    let mut area = vec![0.0; skins];
    let mut sent: Vec<BTreeMap<usize, f64>> = vec![BTreeMap::new(); skins];
    for (t, p) in pairs.iter().enumerate() {
        let (Some(s), Some(j)) = (skin_of[t], p.partner) else { continue };
        area[s] += p.area;
        if let Some(r) = skin_of[j] {
            *sent[s].entry(r).or_default() += p.area;
        }
    }
    let is_master = master_sides(&area, &sent, bodies)?;
    let paired = (0..triangles.len()).filter(|&t| skin_of[t].is_some());
    Ok(paired.partition(|&t| skin_of[t].is_some_and(|s| is_master[s])))
}

/// Which skins are masters. Skins that face each other (one sends at least a tenth of its
/// area's rays to the other) must take two sides, like a wall's outer and inner skins;
/// each skin must send [`MIN_PARTNER_SHARE`] of its area to the other side. Of each group
/// of facing skins the master side is the one made of a single skin (the larger if both
/// are): prisms hang from it, and a side split by an unpaired band (a bowl's foot and wall,
/// outside) would hang its pieces apart. Every group must be one of the surface's
/// `bodies` (closed solids; a hollow one has an outer and an inner wall): two groups in one
/// body would be two bodies.
fn master_sides(area: &[f64], sent: &[BTreeMap<usize, f64>], bodies: usize) -> Result<Vec<bool>, NotLayered> {
    let skins = area.len();
    let mut facing: Vec<Vec<usize>> = vec![Vec::new(); skins];
    for s in 0..skins {
        for (&r, &a) in &sent[s] {
            if a >= 0.1 * area[s] {
                facing[s].push(r);
                facing[r].push(s);
            }
        }
    }
    let mut side: Vec<Option<(usize, bool)>> = vec![None; skins];
    let mut groups = 0;
    for start in 0..skins {
        if side[start].is_some() {
            continue;
        }
        side[start] = Some((groups, false));
        let mut stack = vec![start];
        while let Some(s) = stack.pop() {
            let (g, here) = side[s].ok_or(NotLayered::Skins)?;
            for &r in &facing[s] {
                match side[r] {
                    None => {
                        side[r] = Some((g, !here));
                        stack.push(r);
                    }
                    Some((_, there)) if there == here => return Err(NotLayered::Skins),
                    Some(_) => {}
                }
            }
        }
        groups += 1;
    }
    if groups != bodies {
        return Err(NotLayered::Skins);
    }
    let side: Vec<(usize, bool)> =
        side.into_iter().map(|x| x.ok_or(NotLayered::Skins)).collect::<Result<_, _>>()?;
    for s in 0..skins {
        let opposite: f64 = sent[s].iter().filter(|(&r, _)| side[r].1 != side[s].1).map(|(_, &a)| a).sum();
        if opposite < MIN_PARTNER_SHARE * area[s] {
            return Err(NotLayered::Skins);
        }
    }
    // Per group and side: skin count and area.
    let mut count = vec![[0usize; 2]; groups];
    let mut total = vec![[0.0f64; 2]; groups];
    for s in 0..skins {
        let (g, b) = side[s];
        count[g][b as usize] += 1;
        total[g][b as usize] += area[s];
    }
    let master_side: Vec<bool> = (0..groups)
        .map(|g| match count[g] {
            [1, 1] => Ok(total[g][1] > total[g][0]),
            [1, _] => Ok(false),
            [_, 1] => Ok(true),
            _ => Err(NotLayered::Skins),
        })
        .collect::<Result<_, _>>()?;
    Ok(side.iter().map(|&(g, b)| b == master_side[g]).collect())
}

/// Each connected patch of unpaired triangles of less than `max_area` [m²]
/// whose paired neighbours all lie in one skin joins that skin: its
/// triangles take the wall and partner of the lowest-numbered of those
/// neighbours. A rim band borders two skins and stays unpaired.
fn close_holes(triangles: &[[usize; 3]], by_edge: &EdgeTriangles, pairs: &mut [Pair], max_area: f64) {
    let skin_of = paired_components(triangles, by_edge, pairs);
    let mut seen = vec![false; triangles.len()];
    for start in 0..triangles.len() {
        if pairs[start].partner.is_some() || seen[start] {
            continue;
        }
        seen[start] = true;
        let (mut patch, mut stack, mut border) = (vec![start], vec![start], Vec::new());
        while let Some(t) = stack.pop() {
            for u in manifold_neighbours(triangles, by_edge, t) {
                if pairs[u].partner.is_some() {
                    border.push(u);
                } else if !seen[u] {
                    seen[u] = true;
                    patch.push(u);
                    stack.push(u);
                }
            }
        }
        let area: f64 = patch.iter().map(|&t| pairs[t].area).sum();
        let Some(&first) = border.iter().min() else { continue };
        if area < max_area && border.iter().all(|&u| skin_of[u] == skin_of[first]) {
            let (thickness, partner) = (pairs[first].thickness, pairs[first].partner);
            for t in patch {
                pairs[t].thickness = thickness;
                pairs[t].partner = partner;
            }
        }
    }
}

/// Connected components of the paired triangles over manifold edges.
fn paired_components(
    triangles: &[[usize; 3]],
    by_edge: &EdgeTriangles,
    pairs: &[Pair],
) -> Vec<Option<usize>> {
    let mut skin_of: Vec<Option<usize>> = vec![None; triangles.len()];
    let mut next = 0;
    for start in 0..triangles.len() {
        if pairs[start].partner.is_none() || skin_of[start].is_some() {
            continue;
        }
        skin_of[start] = Some(next);
        let mut stack = vec![start];
        while let Some(t) = stack.pop() {
            for u in manifold_neighbours(triangles, by_edge, t) {
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

/// The triangles across the manifold edges (two triangles each) of triangle `t`.
fn manifold_neighbours<'a>(
    triangles: &'a [[usize; 3]],
    by_edge: &'a EdgeTriangles,
    t: usize,
) -> impl Iterator<Item = usize> + 'a {
    (0..3).filter_map(move |k| {
        let shared = &by_edge[&edge(triangles[t][k], triangles[t][(k + 1) % 3])];
        (shared.len() == 2).then(|| if shared[0] == t { shared[1] } else { shared[0] })
    })
}

/// Area-weighted median thickness of the paired triangles.
fn median_wall(pairs: &[Pair]) -> f64 {
    let mut walls: Vec<(f64, f64)> =
        pairs.iter().filter(|p| p.partner.is_some()).map(|p| (p.thickness, p.area)).collect();
    modal_mesh::weighted_median(&mut walls)
}
