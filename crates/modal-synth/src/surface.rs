//! Nearest surface point of a query point, and mode shapes there.
//!
//! The nearest point on each corner triangle is found exactly (Ericson,
//! *Real-Time Collision Detection*, §5.1.5: Voronoi regions of vertices, edges
//! and face), pruned by a bounding-volume hierarchy of axis-aligned boxes
//! (median split on the longest centroid axis, ≤ 4 triangles per leaf), so a
//! query costs O(log n) triangle tests on typical meshes.
//!
//! Shapes at a point with barycentric coordinates (λ₀, λ₁, λ₂):
//! - linear banks: `φ(p) = Σ λ_k φ_k` over the 3 corners;
//! - quadratic banks (mid-edge nodes present): 6-node triangle shape functions
//!   `N_k = λ_k (2λ_k − 1)` at corners and `4 λ_a λ_b` at the mid-edge node of
//!   edge (a, b), edges ordered (0,1), (1,2), (2,0).
//!
//! Geometry: the flat corner triangle of a linear bank. On a quadratic bank
//! the corner triangle found is refined to the nearest of its 4 flat
//! sub-triangles through the mid-edge nodes, which lie on the curved
//! surface: on a curved body the corner triangle's chord lies inside it (on
//! a quadratic 5 cm sphere a point snapped up to 2.55 mm in, 0.74 mm through
//! the sub-triangles). The normal is the 6-node map's own where all three
//! edges bow out of their chords (on that sphere ≤ 2.9° off, against 17.9°
//! for the chord's), else the corner triangle's (`evenly_curved`). The barycentric coordinates stay those
//! of the parent triangle's parametrization, as the shape functions need.

use modal_mesh::{closest_point_on_triangle, Surface};

/// A point on the surface, as located by [`SurfaceLocator::nearest`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Triangle index into `Surface::triangles`.
    pub triangle: usize,
    /// Barycentric coordinates w.r.t. the triangle's corners (sum 1, each ≥ 0).
    pub bary: [f64; 3],
    /// The surface point \[m\].
    pub position: [f64; 3],
    /// Outward unit normal of the triangle (zero for a degenerate triangle).
    pub normal: [f64; 3],
    /// Distance from the query point to `position` \[m\].
    pub distance: f64,
}

/// Shape-function weights of a surface point: up to 6 (node, weight) pairs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeWeights {
    /// Local surface-node indices.
    pub nodes: [usize; 6],
    /// Shape-function values at the point.
    pub weights: [f64; 6],
    /// Number of used entries (3 linear, 6 quadratic).
    pub len: usize,
}

/// Shape-function weights of `p` on `surface` (linear or quadratic, see module doc).
pub fn node_weights(surface: &Surface, p: &SurfacePoint) -> NodeWeights {
    let tri = surface.triangles[p.triangle];
    let [l0, l1, l2] = p.bary;
    match &surface.triangle_edge_nodes {
        Some(edges) => {
            let e = edges[p.triangle];
            NodeWeights {
                nodes: [tri[0], tri[1], tri[2], e[0], e[1], e[2]],
                weights: [
                    l0 * (2.0 * l0 - 1.0),
                    l1 * (2.0 * l1 - 1.0),
                    l2 * (2.0 * l2 - 1.0),
                    4.0 * l0 * l1,
                    4.0 * l1 * l2,
                    4.0 * l2 * l0,
                ],
                len: 6,
            }
        }
        None => NodeWeights {
            nodes: [tri[0], tri[1], tri[2], 0, 0, 0],
            weights: [l0, l1, l2, 0.0, 0.0, 0.0],
            len: 3,
        },
    }
}

type V3 = [f64; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
#[derive(Clone, Copy, Debug)]
struct Aabb {
    min: V3,
    max: V3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb { min: [f64::INFINITY; 3], max: [f64::NEG_INFINITY; 3] };

    fn grow(&mut self, p: V3) {
        for (k, x) in p.into_iter().enumerate() {
            self.min[k] = self.min[k].min(x);
            self.max[k] = self.max[k].max(x);
        }
    }

    fn merge(&mut self, o: &Aabb) {
        self.grow(o.min);
        self.grow(o.max);
    }

    fn distance2(&self, p: V3) -> f64 {
        (0..3)
            .map(|k| {
                let d = (self.min[k] - p[k]).max(p[k] - self.max[k]).max(0.0);
                d * d
            })
            .sum()
    }
}

/// Centre of a box.
fn centroid(b: &Aabb) -> V3 {
    [(b.min[0] + b.max[0]) * 0.5, (b.min[1] + b.max[1]) * 0.5, (b.min[2] + b.max[2]) * 0.5]
}

#[derive(Clone, Debug)]
struct Node {
    bounds: Aabb,
    /// Leaf: `start..start + count` in `order`; inner: `count == 0`, children `start`, `start + 1`.
    start: usize,
    count: usize,
}

const LEAF_SIZE: usize = 4;

/// Bounding-volume hierarchy over the corner triangles of a [`Surface`].
#[derive(Clone, Debug)]
pub struct SurfaceLocator {
    nodes: Vec<Node>,
    order: Vec<usize>,
    tri_bounds: Vec<Aabb>,
    bbox_diagonal: f64,
}

impl SurfaceLocator {
    /// Builds the hierarchy. Triangles with out-of-range node indices are skipped.
    pub fn new(surface: &Surface) -> SurfaceLocator {
        let n_pos = surface.positions.len();
        let mut tri_bounds = Vec::with_capacity(surface.triangles.len());
        let mut order = Vec::with_capacity(surface.triangles.len());
        let mut all = Aabb::EMPTY;
        for (t, tri) in surface.triangles.iter().enumerate() {
            let mut b = Aabb::EMPTY;
            if tri.iter().all(|&k| k < n_pos) {
                for &k in tri {
                    b.grow(surface.positions[k]);
                }
                order.push(t);
            }
            all.merge(&b);
            tri_bounds.push(b);
        }
        let bbox_diagonal =
            if order.is_empty() { 0.0 } else { dot(sub(all.max, all.min), sub(all.max, all.min)).sqrt() };
        let mut locator = SurfaceLocator { nodes: Vec::new(), order, tri_bounds, bbox_diagonal };
        if !locator.order.is_empty() {
            locator.nodes.push(Node { bounds: all, start: 0, count: locator.order.len() });
            locator.split(0);
        }
        locator
    }

    /// Diagonal of the surface's bounding box \[m\].
    pub fn bbox_diagonal(&self) -> f64 {
        self.bbox_diagonal
    }

    /// True when there is no valid triangle.
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    fn split(&mut self, root: usize) {
        // Box centres once, not per comparison of the median selection.
        let centroids: Vec<V3> = self.tri_bounds.iter().map(centroid).collect();
        let mut stack = vec![root];
        while let Some(ni) = stack.pop() {
            let Node { start, count, .. } = self.nodes[ni];
            if count <= LEAF_SIZE {
                continue;
            }
            let mut cb = Aabb::EMPTY;
            for &t in &self.order[start..start + count] {
                cb.grow(centroids[t]);
            }
            let ext = sub(cb.max, cb.min);
            let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
                0
            } else if ext[1] >= ext[2] {
                1
            } else {
                2
            };
            let mid = count / 2;
            self.order[start..start + count].select_nth_unstable_by(mid, |&a, &b| {
                centroids[a][axis].total_cmp(&centroids[b][axis]).then(a.cmp(&b))
            });
            let child = self.nodes.len();
            for (s, c) in [(start, mid), (start + mid, count - mid)] {
                let mut b = Aabb::EMPTY;
                for &t in &self.order[s..s + c] {
                    b.merge(&self.tri_bounds[t]);
                }
                self.nodes.push(Node { bounds: b, start: s, count: c });
            }
            self.nodes[ni].start = child;
            self.nodes[ni].count = 0;
            stack.push(child);
            stack.push(child + 1);
        }
    }

    /// Nearest surface point to `p` (exact), or `None` for an empty surface or a
    /// non-finite query. Ties go to the lowest triangle index.
    pub fn nearest(&self, surface: &Surface, p: V3) -> Option<SurfacePoint> {
        if self.nodes.is_empty() || !p.iter().all(|x| x.is_finite()) {
            return None;
        }
        let mut best: Option<(f64, usize, V3, V3)> = None;
        let mut stack = vec![0usize];
        while let Some(ni) = stack.pop() {
            let node = &self.nodes[ni];
            let bound = node.bounds.distance2(p);
            if best.is_some_and(|b| bound > b.0) {
                continue;
            }
            if node.count == 0 {
                let (a, b) = (node.start, node.start + 1);
                let (da, db) = (self.nodes[a].bounds.distance2(p), self.nodes[b].bounds.distance2(p));
                // Visit the nearer child first (pushed last).
                if da <= db {
                    stack.push(b);
                    stack.push(a);
                } else {
                    stack.push(a);
                    stack.push(b);
                }
                continue;
            }
            for &t in &self.order[node.start..node.start + node.count] {
                let [i, j, k] = surface.triangles[t];
                let (q, bary) = closest_point_on_triangle(
                    p,
                    surface.positions[i],
                    surface.positions[j],
                    surface.positions[k],
                );
                let d = sub(p, q);
                let d2 = dot(d, d);
                let better = match best {
                    None => true,
                    Some((bd, bt, _, _)) => d2 < bd || (d2 == bd && t < bt),
                };
                if better {
                    best = Some((d2, t, q, bary));
                }
            }
        }
        best.map(|(d2, t, q, bary)| {
            let [i, j, k] = surface.triangles[t];
            let (a, b, c) = (surface.positions[i], surface.positions[j], surface.positions[k]);
            let flat = SurfacePoint {
                triangle: t,
                bary,
                position: q,
                normal: unit_normal(a, b, c),
                distance: d2.sqrt(),
            };
            match &surface.triangle_edge_nodes {
                Some(edges) => on_sub_triangles(surface, edges[t], flat, p),
                None => flat,
            }
        })
    }
}

/// Unit normal of the triangle `(a, b, c)` (zero when degenerate).
fn unit_normal(a: V3, b: V3, c: V3) -> V3 {
    normalized(cross(sub(b, a), sub(c, a)))
}

/// `n / |n|`, or zero for a zero or non-finite `n`.
fn normalized(n: V3) -> V3 {
    let len = dot(n, n).sqrt();
    if len > 0.0 && len.is_finite() {
        n.map(|v| v / len)
    } else {
        [0.0; 3]
    }
}

/// The 4 sub-triangles of a quadratic triangle, as its 6 nodes (corners 0–2,
/// mid-edge nodes 3–5 of edges (0,1), (1,2), (2,0)), in the parent's order.
const SUB_TRIANGLES: [[usize; 3]; 4] = [[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]];

/// `flat` (the nearest point of corner triangle `flat.triangle`, mid-edge
/// nodes `edges`) moved to the nearest of its flat sub-triangles (module
/// doc), its barycentric coordinates mapped back to the parent triangle and
/// its normal the curved map's where that is trustworthy.
fn on_sub_triangles(surface: &Surface, edges: [usize; 3], flat: SurfacePoint, p: V3) -> SurfacePoint {
    let [i, j, k] = surface.triangles[flat.triangle];
    let nodes = [i, j, k, edges[0], edges[1], edges[2]];
    // Each node's coordinates in the parent triangle's parametrization.
    let param: [V3; 6] = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.5],
        [0.5, 0.0, 0.5],
    ];
    let mut best = flat;
    best.distance = f64::INFINITY;
    for sub_triangle in SUB_TRIANGLES {
        let [a, b, c] = sub_triangle.map(|n| surface.positions[nodes[n]]);
        let (q, w) = closest_point_on_triangle(p, a, b, c);
        let d = sub(p, q);
        let distance = dot(d, d).sqrt();
        if distance < best.distance {
            let bary = [0, 1, 2].map(|m| (0..3).map(|v| w[v] * param[sub_triangle[v]][m]).sum::<f64>());
            best = SurfacePoint { bary, position: q, distance, ..flat };
        }
    }
    let x = nodes.map(|n| surface.positions[n]);
    // The curved surface's own normal at the point, not a facet's (ξ = λ₁, η = λ₂).
    let curved = if evenly_curved(&x) {
        normalized(modal_mesh::quadratic_triangle_normal(&x, best.bary[1], best.bary[2]))
    } else {
        [0.0; 3]
    };
    best.normal = if curved == [0.0; 3] { flat.normal } else { curved };
    best
}

/// Whether every edge of the 6-node triangle `x` bows out of its chord, or
/// none does. A triangle with some edges curved and others straight (a mesh
/// curved only where its source surface was: the sweep's torus from an OBJ)
/// has a quadratic map tilted near the curved edge (13° on that torus,
/// against 7.6° for the chord's normal), so its chord's normal is used.
fn evenly_curved(x: &[V3; 6]) -> bool {
    let bows = [(0, 1, 3), (1, 2, 4), (2, 0, 5)].map(|(a, b, m)| {
        let chord = sub(x[b], x[a]);
        let mid = [0, 1, 2].map(|c| 0.5 * (x[a][c] + x[b][c]));
        let off = sub(x[m], mid);
        dot(off, off).sqrt() > 1e-6 * dot(chord, chord).sqrt()
    });
    bows.iter().all(|&b| b) || bows.iter().all(|&b| !b)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(surface: &Surface, p: V3) -> f64 {
        surface
            .triangles
            .iter()
            .map(|t| {
                let (q, _) = closest_point_on_triangle(
                    p,
                    surface.positions[t[0]],
                    surface.positions[t[1]],
                    surface.positions[t[2]],
                );
                dot(sub(p, q), sub(p, q)).sqrt()
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn on_a_curved_quadratic_surface_the_point_and_normal_follow_the_curve() {
        // A quadratic sphere of radius 5 cm (mid-edge nodes on the sphere).
        let mesh = modal_mesh::generate::sphere(0.05, 0.02, 2).expect("sphere");
        let s = modal_mesh::boundary_surface(&mesh);
        let flat = Surface { triangle_edge_nodes: None, ..s.clone() };
        let (loc, loc_flat) = (SurfaceLocator::new(&s), SurfaceLocator::new(&flat));
        let (mut worst_gap, mut worst_gap_flat, mut worst_angle, mut worst_angle_flat) =
            (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for i in 0..200 {
            // Points on the true sphere (a Fibonacci lattice).
            let y = 1.0 - 2.0 * (i as f64 + 0.5) / 200.0;
            let r = (1.0 - y * y).sqrt();
            let phi = 2.399963 * i as f64;
            let radial = [r * phi.cos(), y, r * phi.sin()];
            let p = radial.map(|c| 0.05 * c);
            let angle = |n: V3| dot(n, radial).clamp(-1.0, 1.0).acos().to_degrees();
            let (hit, hit_flat) = (loc.nearest(&s, p).unwrap(), loc_flat.nearest(&flat, p).unwrap());
            worst_gap = worst_gap.max(hit.distance);
            worst_gap_flat = worst_gap_flat.max(hit_flat.distance);
            worst_angle = worst_angle.max(angle(hit.normal));
            worst_angle_flat = worst_angle_flat.max(angle(hit_flat.normal));
            // The parent coordinates still rebuild the shape functions' point.
            assert!(
                (hit.bary.iter().sum::<f64>() - 1.0).abs() < 1e-12 && hit.bary.iter().all(|&b| b >= -1e-12)
            );
        }
        assert!(
            worst_gap < 0.3 * worst_gap_flat,
            "snap {worst_gap} m against {worst_gap_flat} m on the chords"
        );
        assert!(
            worst_angle < 0.3 * worst_angle_flat,
            "normal {worst_angle}° against {worst_angle_flat}° off"
        );
    }

    /// A wavy grid surface of 2·n² triangles.
    fn grid(n: usize) -> Surface {
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                positions.push([x, y, 0.1 * (7.0 * x).sin() * (5.0 * y).cos()]);
            }
        }
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let a = j * (n + 1) + i;
                triangles.push([a, a + 1, a + n + 2]);
                triangles.push([a, a + n + 2, a + n + 1]);
            }
        }
        Surface { node_ids: (0..positions.len()).collect(), positions, triangles, triangle_edge_nodes: None }
    }

    #[test]
    fn bvh_matches_brute_force() {
        let s = grid(40);
        let loc = SurfaceLocator::new(&s);
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..300 {
            let p = [rnd() * 1.4 - 0.2, rnd() * 1.4 - 0.2, rnd() * 0.6 - 0.3];
            let hit = loc.nearest(&s, p).unwrap();
            assert!((hit.distance - brute(&s, p)).abs() < 1e-12, "{p:?}");
            let t = s.triangles[hit.triangle];
            let rebuilt = (0..3).map(|k| {
                hit.bary[0] * s.positions[t[0]][k]
                    + hit.bary[1] * s.positions[t[1]][k]
                    + hit.bary[2] * s.positions[t[2]][k]
            });
            for (k, x) in rebuilt.enumerate() {
                assert!((x - hit.position[k]).abs() < 1e-12);
            }
        }
        assert!(loc.nearest(&s, [f64::NAN, 0.0, 0.0]).is_none());
    }

    #[test]
    fn quadratic_weights_reproduce_quadratics() {
        // One triangle with mid-edge nodes: 6-node shape functions are exact for
        // quadratic fields, e.g. f(x, y) = x² + 3xy − y.
        let positions = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 0.5, 0.0],
            [0.0, 0.5, 0.0],
        ];
        let s = Surface {
            node_ids: (0..6).collect(),
            positions: positions.clone(),
            triangles: vec![[0, 1, 2]],
            triangle_edge_nodes: Some(vec![[3, 4, 5]]),
        };
        let f = |p: V3| p[0] * p[0] + 3.0 * p[0] * p[1] - p[1];
        let loc = SurfaceLocator::new(&s);
        let hit = loc.nearest(&s, [0.7, 0.2, 0.3]).unwrap();
        let w = node_weights(&s, &hit);
        let interp: f64 = (0..w.len).map(|k| w.weights[k] * f(positions[w.nodes[k]])).sum();
        assert!((interp - f(hit.position)).abs() < 1e-12, "{interp} vs {}", f(hit.position));
        assert_eq!(hit.normal, [0.0, 0.0, 1.0]);
    }
}
