//! Isosurface stuffing (Labelle & Shewchuk, "Isosurface Stuffing: Fast
//! Tetrahedral Meshes with Good Dihedral Angles", SIGGRAPH 2007).
//!
//! 1. Sign every BCC lattice point: inside when the generalized winding
//!    number w ≥ ½ (the implicit function is f = w − ½).
//! 2. Cut points: on every lattice edge whose ends have opposite signs, the
//!    crossing with the input surface (exact segment–triangle intersection;
//!    bisection on w where the edge passes through a hole).
//! 3. Warp: a lattice point closer to a cut point on one of its edges than
//!    α × the edge length (α_long = 0.24969 on black edges, α_short = 0.41189
//!    on red edges, the paper's values) is snapped onto the nearest such cut
//!    point and becomes a surface point (sign 0); cut points on its other
//!    edges disappear.
//! 4. Stencils: each lattice tet is kept whole, dropped, or clipped to the
//!    inside by the cut points (1, 2 or 3 tets). Quadrilaterals on lattice
//!    faces are split by a rule that depends only on the face, so neighbour
//!    tets agree: the diagonal starts at the positive lattice point with the
//!    smaller index (this also makes every prism split without Steiner points).
//!
//! Every output vertex is either an unmoved lattice point or lies on the
//! surface; the output volume approximates the solid without a lattice cover.

use std::collections::HashMap;

use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::geom::{dihedral_angles_deg, lerp, norm, orient6, sub, V3};
use crate::graded::{is_black, Refiner};
use crate::lattice::Lattice;

/// Warp threshold on black (long) edges, as a fraction of the edge length.
pub const ALPHA_LONG: f64 = 0.24969;
/// Warp threshold on red (short) edges, as a fraction of the edge length.
pub const ALPHA_SHORT: f64 = 0.41189;
const BISECTIONS: usize = 30;
/// All-surface tets with a smaller dihedral angle are dropped as slivers.
const SLIVER_DEG: f64 = 10.0;

/// Result of stuffing: nodes and positively oriented tets.
#[derive(Clone, Debug)]
pub(crate) struct Stuffed {
    pub nodes: Vec<V3>,
    pub tets: Vec<[usize; 4]>,
    /// Tets of (numerically) zero volume that were dropped.
    pub dropped: usize,
    /// Shortest background edge (m).
    pub min_cell: f64,
}

impl Stuffed {
    /// Keeps the tets `keep` accepts and the nodes they use (renumbered in
    /// order of first use); returns how many tets were removed.
    pub fn retain_tets(&mut self, mut keep: impl FnMut(&[usize; 4]) -> bool) -> usize {
        let before = self.tets.len();
        self.tets.retain(|t| keep(t));
        let mut index = vec![usize::MAX; self.nodes.len()];
        let mut nodes = Vec::new();
        for t in &mut self.tets {
            for v in t.iter_mut() {
                if index[*v] == usize::MAX {
                    index[*v] = nodes.len();
                    nodes.push(self.nodes[*v]);
                }
                *v = index[*v];
            }
        }
        self.nodes = nodes;
        before - self.tets.len()
    }
}

type Edge = (usize, usize);

/// The triangles on each edge ([`edge_triangles`]).
pub(crate) type EdgeTriangles = HashMap<Edge, Vec<usize>>;

/// An edge as its sorted pair of vertices (the key both its faces share).
pub(crate) fn edge(a: usize, b: usize) -> Edge {
    (a.min(b), a.max(b))
}

/// The triangles on each edge of `triangles` (by [`edge`] key), in triangle order.
pub(crate) fn edge_triangles(triangles: &[[usize; 3]]) -> EdgeTriangles {
    let mut by_edge = EdgeTriangles::new();
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            by_edge.entry(edge(tri[k], tri[(k + 1) % 3])).or_default().push(t);
        }
    }
    by_edge
}

/// A vertex of an output tet: a lattice point, or the cut point of an edge.
#[derive(Clone, Copy)]
enum Vx {
    Lattice(usize),
    Cut(usize, usize),
}

struct Builder<'a> {
    pos: &'a [V3],
    cuts: &'a HashMap<Edge, V3>,
    lattice_out: Vec<usize>,
    cut_out: HashMap<Edge, usize>,
    nodes: Vec<V3>,
    tets: Vec<[usize; 4]>,
    dropped: usize,
    tiny: f64,
}

impl Builder<'_> {
    fn point(&self, v: Vx) -> V3 {
        match v {
            Vx::Lattice(i) => self.pos[i],
            Vx::Cut(a, b) => self.cuts[&edge(a, b)],
        }
    }

    fn id(&mut self, v: Vx) -> usize {
        match v {
            Vx::Lattice(i) => {
                if self.lattice_out[i] == usize::MAX {
                    self.lattice_out[i] = self.nodes.len();
                    self.nodes.push(self.pos[i]);
                }
                self.lattice_out[i]
            }
            Vx::Cut(a, b) => {
                let p = self.cuts[&edge(a, b)];
                let next = self.nodes.len();
                let id = *self.cut_out.entry(edge(a, b)).or_insert(next);
                if id == next {
                    self.nodes.push(p);
                }
                id
            }
        }
    }

    fn emit(&mut self, t: [Vx; 4]) {
        let p = t.map(|v| self.point(v));
        let o = orient6(p[0], p[1], p[2], p[3]);
        if o.abs() <= self.tiny {
            self.dropped += 1;
            return;
        }
        let mut ids = t.map(|v| self.id(v));
        if o < 0.0 {
            ids.swap(2, 3);
        }
        self.tets.push(ids);
    }

    fn min_angle(&self, t: [Vx; 4]) -> f64 {
        dihedral_angles_deg(t.map(|v| self.point(v))).into_iter().fold(180.0, f64::min)
    }

    /// Clips lattice tet `t` (signs `s`) to the inside and emits the pieces.
    fn stencil(&mut self, t: [usize; 4], s: [i8; 4]) {
        let mut pos: Vec<usize> = (0..4).filter(|&k| s[k] > 0).map(|k| t[k]).collect();
        let zer: Vec<usize> = (0..4).filter(|&k| s[k] == 0).map(|k| t[k]).collect();
        let neg: Vec<usize> = (0..4).filter(|&k| s[k] < 0).map(|k| t[k]).collect();
        pos.sort_unstable();
        let l = Vx::Lattice;
        let c = Vx::Cut;
        match (pos.len(), zer.len(), neg.len()) {
            (_, _, 0) => self.emit(t.map(l)),
            (1, 0, 3) => {
                let a = pos[0];
                self.emit([l(a), c(a, neg[0]), c(a, neg[1]), c(a, neg[2])]);
            }
            (1, 1, 2) => {
                let a = pos[0];
                self.emit([l(a), l(zer[0]), c(a, neg[0]), c(a, neg[1])]);
            }
            (1, 2, 1) => {
                let a = pos[0];
                self.emit([l(a), l(zer[0]), l(zer[1]), c(a, neg[0])]);
            }
            (2, 1, 1) => {
                // Pyramid: apex z, base quad (a, b, b|d, a|d) on face abd.
                let (a, b, z, d) = (pos[0], pos[1], zer[0], neg[0]);
                self.emit([l(z), l(a), l(b), c(b, d)]);
                self.emit([l(z), l(a), c(b, d), c(a, d)]);
            }
            (2, 0, 2) => {
                // Prism (a, a|c, a|d)–(b, b|c, b|d); lattice faces split from a.
                let (a, b, cc, d) = (pos[0], pos[1], neg[0], neg[1]);
                self.emit([l(a), l(b), c(b, cc), c(b, d)]);
                let one = [[l(a), c(a, cc), c(b, cc), c(b, d)], [l(a), c(a, cc), c(b, d), c(a, d)]];
                let two = [[l(a), c(a, cc), c(b, cc), c(a, d)], [l(a), c(a, d), c(b, cc), c(b, d)]];
                let q1 = self.min_angle(one[0]).min(self.min_angle(one[1]));
                let q2 = self.min_angle(two[0]).min(self.min_angle(two[1]));
                for tet in if q1 >= q2 { one } else { two } {
                    self.emit(tet);
                }
            }
            (3, 0, 1) => {
                // Prism (m0, m1, m2)–(cuts to d); diagonals from the smaller index.
                let (m0, m1, m2, d) = (pos[0], pos[1], pos[2], neg[0]);
                self.emit([l(m0), l(m1), l(m2), c(m2, d)]);
                self.emit([l(m0), l(m1), c(m1, d), c(m2, d)]);
                self.emit([l(m0), c(m0, d), c(m1, d), c(m2, d)]);
            }
            _ => {} // no positive corner: outside
        }
    }
}

/// The background mesh to stuff: vertices with their side, tets, edges.
pub(crate) struct Background {
    /// Vertex positions (m): the lattice points first, in lattice order.
    pub pos: Vec<V3>,
    /// Inside (+1) / outside (−1) of every vertex.
    pub sign: Vec<i8>,
    /// Tets (vertex indices, any orientation).
    pub tets: Vec<[usize; 4]>,
    /// Unique edges (a < b) and whether each is black (axis-aligned: the
    /// long edges of BCC tets, warped with [`ALPHA_LONG`]).
    pub edges: Vec<(usize, usize, bool)>,
    /// Shortest edge (m), for the zero-volume tolerance.
    pub h_min: f64,
}

/// The background mesh on `lattice`: its tets (minus those far outside the
/// solid), refined by longest-edge bisection (module `graded`) wherever a
/// tet's longest edge exceeds `size_at` at its centroid or a corner, when
/// a sizing is given. `Err(live tets)` when refinement exceeds `limit` tets.
pub(crate) fn background(
    lattice: &Lattice,
    bvh: &Bvh,
    size_at: Option<&(dyn Fn(V3) -> f64 + Sync)>,
    limit: usize,
) -> Result<Background, usize> {
    let count = lattice.point_count();
    let lattice_pos: Vec<V3> = (0..count).map(|i| lattice.position(lattice.coord(i))).collect();
    let far_sign = signs(lattice, bvh, &lattice_pos);
    // A tet whose corners all lie in blocks decided to be far outside holds
    // no surface: it is dropped before any refinement.
    let mut tets = Vec::new();
    lattice.for_each_tet(|t| {
        if !t.iter().all(|&v| far_sign[v] == -2) {
            tets.push(t);
        }
    });
    let mut sign: Vec<i8> = far_sign.iter().map(|s| s.signum()).collect();
    let (pos, tets, coords) = match size_at {
        None => (lattice_pos, tets, None),
        Some(size_at) => {
            let mut r = Refiner::new(lattice, tets);
            // Refine while the longest edge exceeds the wanted size at the
            // centroid or a corner.
            r.refine(
                |r, t| {
                    let s = r.size(t);
                    s > size_at(r.centroid(t)) || r.corners(t).iter().any(|&p| s > size_at(p))
                },
                limit,
            )?;
            let (pos, tets, coords) = r.finish();
            let extra: Vec<i8> =
                pos[count..].par_iter().map(|&p| if bvh.winding(p) >= 0.5 { 1 } else { -1 }).collect();
            sign.extend(extra);
            (pos, tets, Some(coords))
        }
    };
    let mut edges: Vec<(usize, usize)> =
        tets.iter().flat_map(|t| TET_EDGES.map(|(a, b)| (t[a].min(t[b]), t[a].max(t[b])))).collect();
    edges.par_sort_unstable();
    edges.dedup();
    let edges: Vec<(usize, usize, bool)> = edges
        .into_iter()
        .map(|(a, b)| {
            let black = match &coords {
                Some(c) => is_black(c[a], c[b]),
                None => is_black(lattice.coord(a), lattice.coord(b)),
            };
            (a, b, black)
        })
        .collect();
    let h_min = edges.iter().map(|&(a, b, _)| norm(sub(pos[a], pos[b]))).fold(lattice.h, f64::min);
    Ok(Background { pos, sign, tets, edges, h_min })
}

const TET_EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// Stuffs the solid {w ≥ ½} of `bvh` on the background mesh.
pub(crate) fn stuff(bg: Background, bvh: &Bvh) -> Stuffed {
    let Background { mut pos, mut sign, tets, edges, h_min } = bg;
    let count = pos.len();
    let crossing: Vec<(usize, usize, bool)> =
        edges.iter().filter(|&&(v, w, _)| sign[v] != sign[w]).copied().collect();
    let mut cuts: HashMap<Edge, V3> =
        crossing.par_iter().map(|&(v, w, _)| ((v, w), cut_point(bvh, pos[v], pos[w], sign[v]))).collect();
    warp(&mut pos, &mut sign, &mut cuts, &crossing, &tets);

    let h = h_min;
    let mut b = Builder {
        pos: &pos,
        cuts: &cuts,
        lattice_out: vec![usize::MAX; count],
        cut_out: HashMap::new(),
        nodes: Vec::new(),
        tets: Vec::new(),
        dropped: 0,
        tiny: 1e-12 * h * h * h,
    };
    for &t in &tets {
        let s = t.map(|i| sign[i]);
        if s.iter().all(|&x| x < 0) {
            continue;
        }
        if s.iter().all(|&x| x == 0) {
            let centroid: V3 = std::array::from_fn(|a| t.iter().map(|&i| pos[i][a]).sum::<f64>() / 4.0);
            // All four corners on the surface: keep it when it is inside and
            // not a sliver flattened onto the surface (dropping one leaves a
            // conforming mesh with a dent thinner than the sliver).
            let whole = t.map(Vx::Lattice);
            if bvh.winding(centroid) >= 0.5 && b.min_angle(whole) >= SLIVER_DEG {
                b.emit(whole);
            }
            continue;
        }
        b.stencil(t, s);
    }
    Stuffed { nodes: b.nodes, tets: b.tets, dropped: b.dropped, min_cell: h_min }
}

/// Inside (+) / outside (−) of every lattice point, from the winding number:
/// ±2 for points of blocks decided at once (far from the surface), ±1 else.
///
/// Blocks of cubes far from the surface are classified at once: with the
/// block's centre c at distance d from every triangle and the block within
/// radius ρ < d / [`BLOCK_MARGIN`] of c, w is harmonic on the ball B(c, d).
/// For a closed surface it is then constant there (0 or 1), so one sample
/// decides the block exactly; for open surfaces the block is accepted only
/// when |w(c) − ½| > [`BLOCK_CLEARANCE`] (a heuristic: w varies slowly so far
/// from the triangles). Other blocks are split in two along their longest
/// axis, down to single cubes whose points are evaluated one by one.
fn signs(lattice: &Lattice, bvh: &Bvh, pos: &[V3]) -> Vec<i8> {
    let mut sign = vec![0i8; pos.len()];
    let mut pending = Vec::new();
    let mut blocks = vec![([0usize; 3], lattice.n)];
    while let Some((lo, hi)) = blocks.pop() {
        let extent: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
        let centre = lattice.position(std::array::from_fn(|a| (lo[a] + hi[a]) as i64));
        let radius =
            0.5 * lattice.h * ((extent[0].pow(2) + extent[1].pow(2) + extent[2].pow(2)) as f64).sqrt();
        let mut decided = None;
        if extent.iter().all(|&e| e >= 2) && bvh.distance(centre) > BLOCK_MARGIN * radius {
            let w = bvh.winding(centre);
            if (w - 0.5).abs() > BLOCK_CLEARANCE {
                decided = Some(if w >= 0.5 { 2 } else { -2 });
            }
        }
        if decided.is_none() && extent.iter().any(|&e| e >= 2) {
            let a = (0..3).max_by_key(|&a| extent[a]).unwrap_or(0);
            let mid = lo[a] + extent[a] / 2;
            let (mut h1, mut l2) = (hi, lo);
            h1[a] = mid;
            l2[a] = mid;
            blocks.push((lo, h1));
            blocks.push((l2, hi));
            continue;
        }
        for_block_points(lattice, lo, hi, |v| match decided {
            Some(s) => sign[v] = s,
            None => pending.push(v),
        });
    }
    let evaluated: Vec<i8> =
        pending.par_iter().map(|&v| if bvh.winding(pos[v]) >= 0.5 { 1 } else { -1 }).collect();
    for (&v, s) in pending.iter().zip(evaluated) {
        sign[v] = s;
    }
    sign
}

/// Block acceptance: distance to the surface over block radius.
const BLOCK_MARGIN: f64 = 1.5;
/// Block acceptance for open surfaces: minimum |w − ½| at the block centre.
const BLOCK_CLEARANCE: f64 = 0.3;

/// Calls `f` for the lattice points owned by the block of cubes [lo, hi):
/// the centres of its cubes and the corners with index in [lo, hi), plus
/// the upper corners where the block touches the lattice's upper faces.
fn for_block_points(lattice: &Lattice, lo: [usize; 3], hi: [usize; 3], mut f: impl FnMut(usize)) {
    let top: [usize; 3] = std::array::from_fn(|a| if hi[a] == lattice.n[a] { hi[a] + 1 } else { hi[a] });
    for k in lo[2]..top[2] {
        for j in lo[1]..top[1] {
            for i in lo[0]..top[0] {
                let c = [i, j, k].map(|x| 2 * x as i64);
                if let Some(v) = lattice.index(c) {
                    f(v);
                }
                if i < hi[0] && j < hi[1] && k < hi[2] {
                    if let Some(v) = lattice.index(c.map(|x| x + 1)) {
                        f(v);
                    }
                }
            }
        }
    }
}

/// Where the surface crosses segment p→q; `sp` is the sign at p.
fn cut_point(bvh: &Bvh, p: V3, q: V3, sp: i8) -> V3 {
    let hits = bvh.crossings(p, q);
    let inside = |x: V3| if bvh.winding(x) >= 0.5 { 1 } else { -1 };
    match hits.len() {
        0 => {
            // Through a hole: bisect on the winding number.
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if inside(lerp(p, q, mid)) == sp {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lerp(p, q, 0.5 * (lo + hi))
        }
        1 => lerp(p, q, hits[0]),
        n => {
            // The first crossing after which the side differs from p's.
            for k in 0..n - 1 {
                if inside(lerp(p, q, 0.5 * (hits[k] + hits[k + 1]))) != sp {
                    return lerp(p, q, hits[k]);
                }
            }
            lerp(p, q, hits[n - 1])
        }
    }
}

/// Snaps vertices that are too close to a cut point (step 3); `crossing`
/// are the edges with a cut point (a < b, black flag).
///
/// A snap that would turn a background tet around the vertex inside out
/// (orientation sign change or zero) is not made: on the BCC lattice the
/// paper's α values never do that, on bisected (graded) tets they can.
fn warp(
    pos: &mut [V3],
    sign: &mut [i8],
    cuts: &mut HashMap<Edge, V3>,
    crossing: &[(usize, usize, bool)],
    tets: &[[usize; 4]],
) {
    // Tets around each vertex that may move (CSR).
    let mut moving = vec![false; pos.len()];
    for &(a, b, _) in crossing {
        moving[a] = true;
        moving[b] = true;
    }
    let mut star: Vec<(usize, usize)> = tets
        .iter()
        .enumerate()
        .flat_map(|(i, t)| t.iter().filter(|&&v| moving[v]).map(move |&v| (v, i)).collect::<Vec<_>>())
        .collect();
    star.sort_unstable();
    let original: Vec<f64> =
        tets.iter().map(|t| orient6(pos[t[0]], pos[t[1]], pos[t[2]], pos[t[3]])).collect();
    // Incident crossing edges per vertex, with their (unwarped) length.
    let mut incident: Vec<(usize, usize, f64, bool)> = crossing
        .iter()
        .flat_map(|&(a, b, black)| {
            let length = norm(sub(pos[a], pos[b]));
            [(a, b, length, black), (b, a, length, black)]
        })
        .collect();
    incident.sort_unstable_by_key(|x| (x.0, x.1));
    for run in incident.chunk_by(|x, y| x.0 == y.0) {
        let v = run[0].0;
        let mut best: Option<(f64, V3)> = None;
        for &(_, w, length, black) in run {
            let Some(&cp) = cuts.get(&edge(v, w)) else { continue };
            let alpha = if black { ALPHA_LONG } else { ALPHA_SHORT };
            let dist = norm(sub(cp, pos[v]));
            if dist < alpha * length && best.is_none_or(|(d, _)| dist < d) {
                best = Some((dist, cp));
            }
        }
        if let Some((_, cp)) = best {
            let first = star.partition_point(|&(w, _)| w < v);
            let keeps_orientation = star[first..].iter().take_while(|&&(w, _)| w == v).all(|&(_, i)| {
                let p = tets[i].map(|k| if k == v { cp } else { pos[k] });
                orient6(p[0], p[1], p[2], p[3]) * original[i] > 0.0
            });
            if !keeps_orientation {
                continue;
            }
            pos[v] = cp;
            sign[v] = 0;
            for &(_, w, _, _) in run {
                cuts.remove(&edge(v, w));
            }
        }
    }
}
