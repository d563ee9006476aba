//! Coarsening a finely tessellated skin by half-edge collapses.
//!
//! A layered shell hangs its prisms from the master skin, so without this
//! the tets follow the input's triangles wherever they are finer than the
//! wall rule asks: the demo bowl tessellated with 43 k triangles instead of
//! 2.7 k took 59 k tets and 100 s instead of 7.7 k tets and 7 s, for the
//! same shape; at 174 k triangles its tiny prisms folded and it was stuffed.
//! Here the skin is brought up to the wall rule's size first.
//!
//! Each collapse removes one vertex `u` into a neighbour `v`
//! (Hoppe 1996's half-edge collapse; shortest edge first, like the
//! collapse step of Botsch & Kobbelt 2004's isotropic remeshing), so every
//! remaining vertex is an input vertex and lies on the input surface. A
//! collapse is made only when all of these hold ([`Collapse`]):
//! - the mesh stays a manifold of the same topology (the link condition:
//!   `u` and `v` share no neighbour but the third corners of their edge's
//!   triangles; Dey et al. 1999);
//! - a rim vertex moves only along a straight rim: it is within the sag
//!   tolerance of the chord of its two rim neighbours, which survive;
//! - every new edge is one the wall rule's refinement keeps (`fits`; on a
//!   chime's axis that is longer than across it), so it has nothing to undo;
//! - no new triangle turns by more than [`MAX_TURN_DEG`] against the one
//!   it replaces, or gets a shape quality `q = 4√3 A / Σ ℓ²` below the
//!   lower of [`MIN_QUALITY`] and [`INPUT_QUALITY_SHARE`] of the worst
//!   input triangle at either end (a chime's long strips are slivers of
//!   `q ≈ 0.17`, and every collapse across them makes one a little thinner);
//! - every new triangle's centroid and every new edge's midpoint lies
//!   within the sag tolerance of the input skin (a triangle spanning a
//!   crease or a bead sags off it).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::bvh::Bvh;
use crate::geom::{add, area_vector, dot, norm, scale, sub, V3};

/// No triangle of a collapse's new fan turns by more than this against the
/// triangle it replaces (degrees).
pub const MAX_TURN_DEG: f64 = 30.0;

/// A new triangle keeps at least this shape quality, or
/// [`INPUT_QUALITY_SHARE`] of the worst input triangle at the edge's ends
/// when that is lower (an input sliver is not a reason to stop, nor made
/// much worse: the floor is the input's, so it does not sink collapse
/// after collapse).
pub const MIN_QUALITY: f64 = 0.3;

/// See [`MIN_QUALITY`].
pub const INPUT_QUALITY_SHARE: f64 = 0.9;

/// What a coarsened skin must keep.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Targets {
    /// Edges shorter than this are collapsed where the module doc allows [m].
    pub short_m: f64,
    /// How far new triangles and edges may sag off the input skin [m].
    pub sag_m: f64,
}

/// The coarsened mesh of `vertices` and `triangles` (oriented, manifold
/// with rims), vertices renumbered in their input order; `surface` is the
/// input skin itself, `fits(a, b)` whether an edge between input vertices
/// `a` and `b` is short enough. Returns the input unchanged when no edge is
/// a candidate or no collapse is allowed.
pub(crate) fn coarsen(
    vertices: &[V3],
    triangles: &[[usize; 3]],
    surface: &Bvh,
    targets: Targets,
    fits: &(dyn Fn(usize, usize) -> bool + Sync),
) -> (Vec<V3>, Vec<[usize; 3]>) {
    let mut mesh = Collapse::new(vertices, triangles, (surface, targets), fits);
    for _ in 0..ROUNDS {
        let collapsed = mesh.collapse_short_edges();
        let flipped = mesh.flip_to_better_shapes();
        if collapsed == 0 && flipped == 0 {
            break;
        }
    }
    mesh.compacted()
}

/// Collapse passes, each followed by flips (a collapse leaves its fan's
/// triangles stretched; a flip lets the next pass collapse there again).
const ROUNDS: usize = 4;

/// Length-ordered edge queue entry: (length bits, a, b). Positive floats
/// order like their bits, and the vertex pair breaks ties deterministically.
type Entry = Reverse<(u64, usize, usize)>;

/// The skin being coarsened: triangles with a live flag and each vertex's fan.
struct Collapse<'a> {
    vertices: &'a [V3],
    triangles: Vec<[usize; 3]>,
    alive: Vec<bool>,
    /// Live and dead triangles around each vertex (dead ones are skipped).
    fans: Vec<Vec<usize>>,
    removed: Vec<bool>,
    /// The worst shape quality of the input triangles at each vertex.
    input_quality: Vec<f64>,
    surface: &'a Bvh,
    targets: Targets,
    fits: &'a (dyn Fn(usize, usize) -> bool + Sync),
}

impl<'a> Collapse<'a> {
    fn new(
        vertices: &'a [V3],
        triangles: &[[usize; 3]],
        (surface, targets): (&'a Bvh, Targets),
        fits: &'a (dyn Fn(usize, usize) -> bool + Sync),
    ) -> Self {
        let mut fans = vec![Vec::new(); vertices.len()];
        let mut input_quality = vec![1.0f64; vertices.len()];
        for (i, t) in triangles.iter().enumerate() {
            let q = quality(t.map(|v| vertices[v]));
            for &v in t {
                fans[v].push(i);
                input_quality[v] = input_quality[v].min(q);
            }
        }
        Collapse {
            vertices,
            triangles: triangles.to_vec(),
            alive: vec![true; triangles.len()],
            fans,
            removed: vec![false; vertices.len()],
            input_quality,
            surface,
            targets,
            fits,
        }
    }

    /// Collapses edges shorter than `targets.short_m`, shortest first;
    /// returns how many.
    fn collapse_short_edges(&mut self) -> usize {
        let short = self.targets.short_m;
        let entries: Vec<Entry> =
            self.live_edges().into_iter().filter_map(|(a, b)| self.entry_if_short(a, b, short)).collect();
        let mut queue = BinaryHeap::from(entries);
        let mut count = 0;
        while let Some(Reverse((_, a, b))) = queue.pop() {
            if self.removed[a] || self.removed[b] || !self.has_edge(a, b) {
                continue;
            }
            let survivor = if self.try_collapse(a, b) {
                b
            } else if self.try_collapse(b, a) {
                a
            } else {
                continue;
            };
            count += 1;
            for w in self.neighbours(survivor) {
                queue.extend(self.entry_if_short(survivor, w, short));
            }
        }
        count
    }

    /// One sweep of edge flips over the inner edges, in vertex order; returns how many.
    fn flip_to_better_shapes(&mut self) -> usize {
        self.live_edges().into_iter().filter(|&(a, b)| self.try_flip(a, b)).count()
    }

    /// Every edge of the live triangles once, as `(smaller, larger)` vertex, sorted.
    fn live_edges(&self) -> Vec<(usize, usize)> {
        let mut edges: Vec<(usize, usize)> = Vec::new();
        for (t, _) in self.triangles.iter().zip(&self.alive).filter(|(_, &alive)| alive) {
            edges.extend((0..3).map(|k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))));
        }
        edges.sort_unstable();
        edges.dedup();
        edges
    }

    /// Replaces the diagonal `a`–`b` of its two triangles by the other one
    /// when that raises their worst shape quality and the pair is nearly
    /// flat (each new triangle within [`MAX_TURN_DEG`] of both old ones) and
    /// on the surface.
    fn try_flip(&mut self, a: usize, b: usize) -> bool {
        let shared = self.edge_triangles(a, b);
        let [t1, t2] = shared[..] else { return false };
        // Orient so t1 runs a → b → c and t2 runs b → a → d.
        let (a, b) = match self.triangles[t1].iter().position(|&x| x == a) {
            Some(k) if self.triangles[t1][(k + 1) % 3] == b => (a, b),
            _ => (b, a),
        };
        let third = |t: usize| self.triangles[t].into_iter().find(|&x| x != a && x != b);
        let (Some(c), Some(d)) = (third(t1), third(t2)) else { return false };
        if c == d || self.has_edge(c, d) {
            return false;
        }
        let p = |i: usize| self.vertices[i];
        let before = [[a, b, c], [b, a, d]].map(|t| t.map(p));
        let after = [[a, d, c], [d, b, c]];
        let worst = |tris: &[[V3; 3]; 2]| quality(tris[0]).min(quality(tris[1]));
        let min_cos = MAX_TURN_DEG.to_radians().cos();
        let new = after.map(|t| t.map(p));
        let flat = new.iter().all(|n| before.iter().all(|o| turn_cos(*o, *n) >= min_cos));
        let middle = scale(add(p(c), p(d)), 0.5);
        if worst(&new) <= 1.05 * worst(&before) || !flat || !(self.fits)(c, d) || !self.on_surface(middle) {
            return false;
        }
        self.triangles[t1] = after[0];
        self.triangles[t2] = after[1];
        self.fans[a].retain(|&t| t != t2);
        self.fans[b].retain(|&t| t != t1);
        self.fans[c].push(t2);
        self.fans[d].push(t1);
        true
    }

    fn entry_if_short(&self, a: usize, b: usize, short: f64) -> Option<Entry> {
        let length = norm(sub(self.vertices[a], self.vertices[b]));
        (length < short).then_some(Reverse((length.to_bits(), a.min(b), a.max(b))))
    }

    fn fan(&self, v: usize) -> impl Iterator<Item = usize> + '_ {
        self.fans[v].iter().copied().filter(|&t| self.alive[t])
    }

    /// Live triangles with both `a` and `b`.
    fn edge_triangles(&self, a: usize, b: usize) -> Vec<usize> {
        self.fan(a).filter(|&t| self.triangles[t].contains(&b)).collect()
    }

    fn has_edge(&self, a: usize, b: usize) -> bool {
        self.fan(a).any(|t| self.triangles[t].contains(&b))
    }

    /// The vertices joined to `v` by an edge, sorted.
    fn neighbours(&self, v: usize) -> Vec<usize> {
        let mut out: Vec<usize> = self.fan(v).flat_map(|t| self.triangles[t]).filter(|&w| w != v).collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The neighbours of `v` across a rim edge (an edge of one triangle).
    fn rim_neighbours(&self, v: usize) -> Vec<usize> {
        self.neighbours(v).into_iter().filter(|&w| self.edge_triangles(v, w).len() == 1).collect()
    }

    /// Removes `u` into `v` if the module doc's conditions hold.
    fn try_collapse(&mut self, u: usize, v: usize) -> bool {
        let shared = self.edge_triangles(u, v);
        if shared.is_empty() || shared.len() > 2 || !self.keeps_topology(u, v, &shared) {
            return false;
        }
        let rim = self.rim_neighbours(u);
        if !rim.is_empty() && !self.slides_along_rim(u, v, &rim, shared.len()) {
            return false;
        }
        let moved: Vec<usize> = self.fan(u).filter(|t| !shared.contains(t)).collect();
        if !self.fan_is_acceptable(u, v, &moved) {
            return false;
        }
        for &t in &shared {
            self.alive[t] = false;
        }
        for &t in &moved {
            for c in self.triangles[t].iter_mut().filter(|c| **c == u) {
                *c = v;
            }
            self.fans[v].push(t);
        }
        let alive = &self.alive;
        self.fans[v].retain(|&t| alive[t]);
        self.removed[u] = true;
        self.fans[u].clear();
        true
    }

    /// The link condition, and no collapse of a closed piece below a tetrahedron.
    fn keeps_topology(&self, u: usize, v: usize, shared: &[usize]) -> bool {
        let opposite: Vec<usize> =
            shared.iter().flat_map(|&t| self.triangles[t]).filter(|&w| w != u && w != v).collect();
        let (nu, nv) = (self.neighbours(u), self.neighbours(v));
        let common = nu.iter().filter(|w| nv.binary_search(w).is_ok()).count();
        common == opposite.len() && self.fan(u).count() + self.fan(v).count() > 6
    }

    /// A rim vertex `u` may go only along a rim edge to `v`, on a straight stretch of rim.
    fn slides_along_rim(&self, u: usize, v: usize, rim: &[usize], shared: usize) -> bool {
        if shared != 1 || rim.len() != 2 || !rim.contains(&v) {
            return false;
        }
        let w = if rim[0] == v { rim[1] } else { rim[0] };
        distance_to_segment(self.vertices[u], self.vertices[v], self.vertices[w]) <= self.targets.sag_m
    }

    /// The triangles `moved` (around `u`, without its edge to `v`) with `u` replaced by `v`:
    /// short enough, not turned, well shaped, on the surface.
    fn fan_is_acceptable(&self, u: usize, v: usize, moved: &[usize]) -> bool {
        let p = |i: usize| self.vertices[i];
        let worst_now = self.fan(u).map(|t| quality(self.triangles[t].map(p))).fold(1.0, f64::min);
        let worst_input = INPUT_QUALITY_SHARE * self.input_quality[u].min(self.input_quality[v]);
        let min_quality = MIN_QUALITY.min(worst_now).min(worst_input);
        let min_cos = MAX_TURN_DEG.to_radians().cos();
        moved.iter().all(|&t| {
            let before = self.triangles[t].map(p);
            let after = self.triangles[t].map(|c| if c == u { p(v) } else { p(c) });
            let turned = turn_cos(before, after) < min_cos;
            let others = self.triangles[t].into_iter().filter(|&c| c != u);
            !turned
                && quality(after) >= min_quality
                && others.clone().all(|w| (self.fits)(v, w))
                && self.on_surface(scale(add(add(after[0], after[1]), after[2]), 1.0 / 3.0))
                && others.map(|w| scale(add(p(w), p(v)), 0.5)).all(|m| self.on_surface(m))
        })
    }

    fn on_surface(&self, x: V3) -> bool {
        self.surface.is_within(x, self.targets.sag_m)
    }

    /// Live triangles and their vertices, renumbered in input order.
    fn compacted(self) -> (Vec<V3>, Vec<[usize; 3]>) {
        let mut index = vec![usize::MAX; self.vertices.len()];
        let mut vertices = Vec::new();
        for (i, &p) in self.vertices.iter().enumerate() {
            if !self.removed[i] && !self.fans[i].is_empty() {
                index[i] = vertices.len();
                vertices.push(p);
            }
        }
        let triangles = self
            .triangles
            .iter()
            .zip(&self.alive)
            .filter(|(_, &alive)| alive)
            .map(|(t, _)| t.map(|c| index[c]))
            .collect::<Vec<_>>();
        debug_assert!(triangles.iter().flatten().all(|&c| c < vertices.len()));
        (vertices, triangles)
    }
}

/// Shape quality `4√3 A / (ℓ₁² + ℓ₂² + ℓ₃²)`: 1 equilateral, 0 degenerate.
fn quality([a, b, c]: [V3; 3]) -> f64 {
    let sum = dot(sub(b, a), sub(b, a)) + dot(sub(c, b), sub(c, b)) + dot(sub(a, c), sub(a, c));
    if sum > 0.0 {
        4.0 * 3f64.sqrt() * norm(area_vector(a, b, c)) / sum
    } else {
        0.0
    }
}

/// The cosine of the angle between two triangles' normals (−1 for a degenerate one).
fn turn_cos(a: [V3; 3], b: [V3; 3]) -> f64 {
    let (na, nb) = (area_vector(a[0], a[1], a[2]), area_vector(b[0], b[1], b[2]));
    let scale = norm(na) * norm(nb);
    if scale > 0.0 {
        dot(na, nb) / scale
    } else {
        -1.0
    }
}

fn distance_to_segment(p: V3, a: V3, b: V3) -> f64 {
    let d = sub(b, a);
    let length2 = dot(d, d);
    let s = if length2 > 0.0 { (dot(sub(p, a), d) / length2).clamp(0.0, 1.0) } else { 0.0 };
    norm(sub(p, add(a, scale(d, s))))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat n × n grid of unit squares in the plane z = 0, each cut into two triangles.
    fn grid(n: usize, cell: f64) -> (Vec<V3>, Vec<[usize; 3]>) {
        let id = |i: usize, j: usize| i * (n + 1) + j;
        let vertices =
            (0..=n).flat_map(|i| (0..=n).map(move |j| [i as f64 * cell, j as f64 * cell, 0.0])).collect();
        let mut triangles = Vec::new();
        for i in 0..n {
            for j in 0..n {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (vertices, triangles)
    }

    /// Coarsened with every edge up to `longest` fitting, 10 µm of sag.
    fn coarsened(vertices: &[V3], triangles: &[[usize; 3]], longest: f64) -> (Vec<V3>, Vec<[usize; 3]>) {
        let surface = Bvh::new(triangles.iter().map(|t| t.map(|v| vertices[v])).collect());
        let fits = |a: usize, b: usize| norm(sub(vertices[a], vertices[b])) <= longest;
        coarsen(vertices, triangles, &surface, Targets { short_m: 0.6 * longest, sag_m: 1e-5 }, &fits)
    }

    fn area(vertices: &[V3], triangles: &[[usize; 3]]) -> V3 {
        triangles
            .iter()
            .fold([0.0; 3], |acc, t| add(acc, area_vector(vertices[t[0]], vertices[t[1]], vertices[t[2]])))
    }

    #[test]
    fn a_fine_flat_grid_becomes_coarse_and_keeps_its_area_corners_and_bounds() {
        let (vertices, triangles) = grid(32, 0.001);
        let (v, t) = coarsened(&vertices, &triangles, 0.008);
        assert!(t.len() * 8 < triangles.len(), "{} of {} triangles left", t.len(), triangles.len());
        let (before, after) = (area(&vertices, &triangles), area(&v, &t));
        assert!((after[2] - before[2]).abs() < 1e-12 && after[2] > 0.0, "area {after:?} against {before:?}");
        for corner in [[0.0, 0.0, 0.0], [0.032, 0.0, 0.0], [0.0, 0.032, 0.0], [0.032, 0.032, 0.0]] {
            assert!(v.iter().any(|p| norm(sub(*p, corner)) < 1e-12), "corner {corner:?} kept");
        }
        for tri in &t {
            assert!(quality(tri.map(|c| v[c])) >= MIN_QUALITY, "a new triangle is well shaped");
            for k in 0..3 {
                assert!(norm(sub(v[tri[k]], v[tri[(k + 1) % 3]])) <= 0.008 * (1.0 + 1e-12));
            }
        }
    }

    #[test]
    fn a_grid_already_at_size_is_left_as_it_is() {
        let (vertices, triangles) = grid(4, 0.006);
        let (v, t) = coarsened(&vertices, &triangles, 0.008);
        assert_eq!((v, t), (vertices, triangles));
    }

    #[test]
    fn a_crease_is_not_collapsed_across() {
        // The grid folded by 90° along x = 16 mm: every vertex off the fold keeps its side.
        let (mut vertices, triangles) = grid(32, 0.001);
        for p in &mut vertices {
            if p[0] > 0.016 {
                *p = [0.016, p[1], p[0] - 0.016];
            }
        }
        let (v, t) = coarsened(&vertices, &triangles, 0.008);
        for tri in &t {
            let c = tri.map(|i| v[i]);
            let flat = c.iter().all(|p| p[2].abs() < 1e-12);
            let wall = c.iter().all(|p| (p[0] - 0.016).abs() < 1e-12);
            assert!(flat || wall, "triangle {c:?} spans the crease");
        }
        assert!(t.len() * 4 < triangles.len(), "{} of {} triangles left", t.len(), triangles.len());
    }
}
