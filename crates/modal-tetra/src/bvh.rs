//! Bounding-volume hierarchy over the repaired surface triangles, with three
//! queries: generalized winding number, closest distance, segment crossings.
//!
//! Winding number (Jacobson, Kavan & Sorkine-Hornung 2013):
//! `w(q) = (1/4π) Σ_t Ω_t(q)`, Ω_t the signed solid angle of triangle t
//! seen from q. It is 1 inside and 0 outside a closed, outward-oriented
//! surface, and degrades gracefully (≈ ½ across holes) on open or
//! self-intersecting ones. Far from a node (distance > [`FAR_FIELD`] × node
//! radius) the node's triangles are replaced by their dipole (Barill et al.
//! 2018, first order): `Ω ≈ N · (p̄ − q) / |p̄ − q|³` with N the sum of the
//! triangles' area vectors and p̄ their area-weighted centroid.

use crate::geom::{
    add, area_vector, closest_on_triangle, dot, norm, scale, segment_triangle, solid_angle, sub, V3,
};

/// A node is summarized by its dipole when the query point is farther than
/// this many node radii from its centre.
pub const FAR_FIELD: f64 = 2.5;
const LEAF: usize = 4;

#[derive(Clone, Debug)]
struct Node {
    lo: V3,
    hi: V3,
    center: V3,
    area: V3,
    radius: f64,
    /// Leaf: triangles `order[first..first + count]`; inner: children at
    /// `first` and `first + 1`-th slot in `children`.
    first: usize,
    count: usize,
    children: [usize; 2],
}

/// BVH over a triangle set (positions copied in, triangles oriented).
#[derive(Clone, Debug)]
pub struct Bvh {
    tris: Vec<[V3; 3]>,
    /// Index (in the input order) of each stored triangle.
    index: Vec<usize>,
    nodes: Vec<Node>,
}

impl Bvh {
    /// Builds the hierarchy; `tris` are the triangles' corner positions.
    pub fn new(tris: Vec<[V3; 3]>) -> Self {
        let mut order: Vec<usize> = (0..tris.len()).collect();
        let centroids: Vec<V3> = tris.iter().map(|t| scale(add(add(t[0], t[1]), t[2]), 1.0 / 3.0)).collect();
        let mut nodes = Vec::with_capacity(2 * tris.len() / LEAF + 1);
        if !tris.is_empty() {
            build(&tris, &centroids, &mut order, 0, &mut nodes);
        }
        let tris = order.iter().map(|&i| tris[i]).collect();
        Bvh { tris, index: order, nodes }
    }

    /// Generalized winding number at `q` (≈1 inside, ≈0 outside).
    pub fn winding(&self, q: V3) -> f64 {
        if self.nodes.is_empty() {
            return 0.0;
        }
        let mut stack = vec![0usize];
        let mut omega = 0.0;
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            let d = sub(node.center, q);
            let dist = norm(d);
            if dist > FAR_FIELD * node.radius {
                omega += dot(node.area, d) / (dist * dist * dist);
            } else if node.count > 0 {
                for t in &self.tris[node.first..node.first + node.count] {
                    omega += solid_angle(q, t[0], t[1], t[2]);
                }
            } else {
                stack.extend(node.children);
            }
        }
        omega / (4.0 * std::f64::consts::PI)
    }

    /// Distance from `q` to the nearest triangle (m) (∞ when empty).
    pub fn distance(&self, q: V3) -> f64 {
        self.closest(q).map_or(f64::INFINITY, |p| norm(sub(q, p)))
    }

    /// The point of the surface nearest to `q` (`None` when empty).
    pub fn closest(&self, q: V3) -> Option<V3> {
        let mut best = f64::INFINITY;
        let mut point = None;
        if self.nodes.is_empty() {
            return None;
        }
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if box_distance(q, node.lo, node.hi) >= best {
                continue;
            }
            if node.count > 0 {
                for t in &self.tris[node.first..node.first + node.count] {
                    let p = closest_on_triangle(q, t[0], t[1], t[2]);
                    let d = norm(sub(q, p));
                    if d < best {
                        best = d;
                        point = Some(p);
                    }
                }
            } else {
                stack.extend(node.children);
            }
        }
        point
    }

    /// Whether some triangle lies within `radius` of `q`: [`Bvh::distance`]
    /// `≤ radius`, visiting only the nodes that close (a sag test of a
    /// point near the surface reads a few leaves, not a search from ∞).
    pub fn is_within(&self, q: V3, radius: f64) -> bool {
        let mut stack = if self.nodes.is_empty() { Vec::new() } else { vec![0usize] };
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if box_distance(q, node.lo, node.hi) > radius {
                continue;
            }
            if node.count > 0 {
                let tris = &self.tris[node.first..node.first + node.count];
                if tris.iter().any(|t| norm(sub(q, closest_on_triangle(q, t[0], t[1], t[2]))) <= radius) {
                    return true;
                }
            } else {
                stack.extend(node.children);
            }
        }
        false
    }

    /// Input indices of the triangles whose bounding boxes meet the box [lo, hi].
    pub fn in_box(&self, lo: V3, hi: V3) -> Vec<usize> {
        let mut out = Vec::new();
        let mut stack = if self.nodes.is_empty() { Vec::new() } else { vec![0usize] };
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if (0..3).any(|c| node.hi[c] < lo[c] || node.lo[c] > hi[c]) {
                continue;
            }
            if node.count > 0 {
                for k in node.first..node.first + node.count {
                    let t = &self.tris[k];
                    if (0..3).all(|c| {
                        let (a, b) = (t[0][c].min(t[1][c]).min(t[2][c]), t[0][c].max(t[1][c]).max(t[2][c]));
                        a <= hi[c] && b >= lo[c]
                    }) {
                        out.push(self.index[k]);
                    }
                }
            } else {
                stack.extend(node.children);
            }
        }
        out
    }

    /// Parameters t ∈ [0, 1] (sorted) where segment p→q crosses a triangle.
    pub fn crossings(&self, p: V3, q: V3) -> Vec<f64> {
        let mut hits: Vec<f64> = self.crossings_with_index(p, q).into_iter().map(|(t, _)| t).collect();
        hits.sort_by(f64::total_cmp);
        hits
    }

    /// The first crossing of segment p→q: its parameter t ∈ [0, 1] and the
    /// input index of the triangle crossed (the lower index on a tie).
    pub fn first_crossing(&self, p: V3, q: V3) -> Option<(f64, usize)> {
        self.crossings_with_index(p, q).into_iter().min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
    }

    /// Every crossing of segment p→q with the input index of its triangle, unsorted.
    fn crossings_with_index(&self, p: V3, q: V3) -> Vec<(f64, usize)> {
        let mut hits = Vec::new();
        if self.nodes.is_empty() {
            return hits;
        }
        let lo: V3 = std::array::from_fn(|c| p[c].min(q[c]));
        let hi: V3 = std::array::from_fn(|c| p[c].max(q[c]));
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if (0..3).any(|c| node.hi[c] < lo[c] || node.lo[c] > hi[c]) {
                continue;
            }
            if node.count > 0 {
                for k in node.first..node.first + node.count {
                    let t = &self.tris[k];
                    hits.extend(segment_triangle(p, q, t[0], t[1], t[2]).map(|s| (s, self.index[k])));
                }
            } else {
                stack.extend(node.children);
            }
        }
        hits
    }
}

fn box_distance(q: V3, lo: V3, hi: V3) -> f64 {
    let d: V3 = std::array::from_fn(|c| (lo[c] - q[c]).max(0.0).max(q[c] - hi[c]));
    norm(d)
}

/// Builds the subtree over `order[..]` (global offset `first`), returns its index.
fn build(
    tris: &[[V3; 3]],
    centroids: &[V3],
    order: &mut [usize],
    first: usize,
    nodes: &mut Vec<Node>,
) -> usize {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut area = [0.0; 3];
    let mut weighted = [0.0; 3];
    let mut total = 0.0;
    for &t in order.iter() {
        for p in tris[t] {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        let a = area_vector(tris[t][0], tris[t][1], tris[t][2]);
        let w = norm(a);
        area = add(area, a);
        weighted = add(weighted, scale(centroids[t], w));
        total += w;
    }
    let center = if total > 0.0 { scale(weighted, 1.0 / total) } else { scale(add(lo, hi), 0.5) };
    let radius = order.iter().flat_map(|&t| tris[t]).map(|p| norm(sub(p, center))).fold(0.0, f64::max);
    let index = nodes.len();
    nodes.push(Node { lo, hi, center, area, radius, first, count: order.len(), children: [0; 2] });
    if order.len() <= LEAF {
        return index;
    }
    let mut clo = [f64::INFINITY; 3];
    let mut chi = [f64::NEG_INFINITY; 3];
    for &t in order.iter() {
        for c in 0..3 {
            clo[c] = clo[c].min(centroids[t][c]);
            chi[c] = chi[c].max(centroids[t][c]);
        }
    }
    let axis = (0..3).max_by(|&a, &b| (chi[a] - clo[a]).total_cmp(&(chi[b] - clo[b]))).unwrap_or(0);
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| centroids[a][axis].total_cmp(&centroids[b][axis]));
    let (left, right) = order.split_at_mut(mid);
    let l = build(tris, centroids, left, first, nodes);
    let r = build(tris, centroids, right, first + mid, nodes);
    nodes[index].count = 0;
    nodes[index].children = [l, r];
    index
}

#[cfg(test)]
mod tests {
    use super::*;

    fn octahedron() -> Vec<[V3; 3]> {
        let v = [
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let f = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
        f.iter().map(|t| t.map(|i| v[i])).collect()
    }

    #[test]
    fn winding_is_one_inside_zero_outside() {
        let b = Bvh::new(octahedron());
        assert!((b.winding([0.1, 0.05, -0.2]) - 1.0).abs() < 1e-12);
        assert!(b.winding([3.0, 0.0, 0.0]).abs() < 1e-12);
    }

    #[test]
    fn distance_and_crossings() {
        let b = Bvh::new(octahedron());
        assert!((b.distance([0.0; 3]) - 1.0 / 3f64.sqrt()).abs() < 1e-12);
        let hits = b.crossings([-2.0, 0.01, 0.02], [2.0, 0.01, 0.02]);
        assert_eq!(hits.len(), 2);
    }
}
