//! Taubin's λ|μ smoothing of a triangle surface (G. Taubin, "A signal
//! processing approach to fair surface design", SIGGRAPH 1995): each pass
//! moves every vertex by the umbrella operator
//!
//! `Δx_i = (1/|N_i|) Σ_{j∈N_i} (x_j − x_i)`  (N_i: the edge neighbours of i),
//!
//! first `x ← x + λΔx` (shrinks, like Laplacian smoothing), then
//! `x ← x + μΔx` with `μ < −λ` (grows back). The pair is a low-pass filter
//! of the surface's "frequencies" (eigenvalues k of the umbrella operator):
//! `f(k) = (1 − λk)(1 − μk)`, 1 at `k = 0`, above 1 up to the pass-band
//! `k_PB = 1/λ + 1/μ`, and damped beyond. With λ = 0.5, μ = −0.53,
//! `k_PB` ≈ 0.11: `f(1)` = 0.77, `f(1.5)` = 0.45, `f(2)` = 0, so ten
//! passes leave at most 7 % of a scan's vertex-to-vertex noise (`k ≥ 1`),
//! while a shape many edges across (`k` ≪ 0.11, `f` ≈ 1) is kept and the
//! volume hardly shrinks.
//!
//! Creases are kept: an edge whose faces' normals differ by more than the
//! crease angle is a crease. The normals are the caller's: on a scan they
//! must be averaged over a neighbourhood (noise tilts single facets by tens
//! of degrees, a wall's rim turns by 90° whatever the averaging). A vertex
//! on two crease edges is smoothed along them only (its neighbours are the
//! two crease ends), a vertex on three or more (a corner) stays, and any
//! other vertex (on one crease edge: noise, or a crease's end) takes all
//! its edge neighbours. Rounding a thin wall's rim would bend the wall's
//! last cells towards it, where the layers then fold.
//!
//! Written here: the surface crates we considered smooth with plain
//! Laplacian or cotangent flow (shrinking), or remesh, which would lose
//! the input's vertices the layered mesher reads.

use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::geom::{add, area_vector, dot, scale, sub, unit, V3};
use crate::stuff::edge_triangles;

/// λ of the shrinking step.
pub const LAMBDA: f64 = 0.5;

/// μ of the growing step (`k_PB = 1/λ + 1/μ ≈ 0.11`).
pub const MU: f64 = -0.53;

/// `vertices` after `passes` λ|μ passes over the edges of `triangles`,
/// edges whose faces' unit `normals` differ by more than `crease_deg`
/// kept as creases (module doc). A vertex on no triangle stays where it is.
pub(crate) fn taubin(
    vertices: &[V3],
    triangles: &[[usize; 3]],
    normals: &[V3],
    crease_deg: f64,
    passes: usize,
) -> Vec<V3> {
    let neighbours = smoothing_neighbours(vertices.len(), triangles, normals, crease_deg);
    let mut x = vertices.to_vec();
    for _ in 0..passes {
        for factor in [LAMBDA, MU] {
            x = umbrella_step(&x, &neighbours, factor);
        }
    }
    x
}

/// `x + factor · Δx` for every vertex.
fn umbrella_step(x: &[V3], neighbours: &[Vec<usize>], factor: f64) -> Vec<V3> {
    x.iter()
        .zip(neighbours)
        .map(|(&xi, n)| {
            if n.is_empty() {
                return xi;
            }
            let sum = n.iter().fold([0.0; 3], |acc, &j| add(acc, sub(x[j], xi)));
            add(xi, scale(sum, factor / n.len() as f64))
        })
        .collect()
}

/// Each triangle's normal averaged (by area) over the triangles whose
/// bounding boxes meet the cube of half-side `radius` about its centroid
/// and whose own normals lie within 60° of its own: a scan's noise
/// averages out, while the other skin of a thin wall and a rim at right
/// angles stay out. `bvh` is over the same triangles.
pub(crate) fn averaged_normals(vertices: &[V3], triangles: &[[usize; 3]], bvh: &Bvh, radius: f64) -> Vec<V3> {
    let areas: Vec<V3> =
        triangles.iter().map(|t| area_vector(vertices[t[0]], vertices[t[1]], vertices[t[2]])).collect();
    let facets: Vec<V3> = areas.iter().map(|&a| unit(a)).collect();
    (0..triangles.len())
        .into_par_iter()
        .map(|i| {
            let t = triangles[i];
            let c = scale(add(add(vertices[t[0]], vertices[t[1]]), vertices[t[2]]), 1.0 / 3.0);
            let near = bvh.in_box(sub(c, [radius; 3]), add(c, [radius; 3]));
            let same_side = near.into_iter().filter(|&j| dot(facets[i], facets[j]) >= 0.5);
            unit(same_side.fold([0.0; 3], |acc, j| add(acc, areas[j])))
        })
        .collect()
}

/// The neighbours each vertex is smoothed towards (module doc): its two
/// crease neighbours, none at a corner, else all its edge neighbours;
/// sorted, once each.
fn smoothing_neighbours(
    count: usize,
    triangles: &[[usize; 3]],
    normals: &[V3],
    crease_deg: f64,
) -> Vec<Vec<usize>> {
    let faces = edge_triangles(triangles);
    let cos_crease = crease_deg.to_radians().cos();
    let mut all: Vec<Vec<usize>> = vec![Vec::new(); count];
    let mut creases: Vec<Vec<usize>> = vec![Vec::new(); count];
    for (&(a, b), f) in &faces {
        all[a].push(b);
        all[b].push(a);
        // A non-manifold or open edge counts as a crease: nothing slides across it.
        let crease = f.len() != 2 || dot(normals[f[0]], normals[f[1]]) < cos_crease;
        if crease {
            creases[a].push(b);
            creases[b].push(a);
        }
    }
    all.into_iter()
        .zip(creases)
        .map(|(mut all, mut crease)| {
            let mut chosen = match crease.len() {
                2 => std::mem::take(&mut crease),
                0 | 1 => std::mem::take(&mut all),
                _ => Vec::new(),
            };
            chosen.sort_unstable();
            chosen.dedup();
            chosen
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use super::*;
    use crate::geom::norm;

    fn facets(v: &[V3], t: &[[usize; 3]]) -> Vec<V3> {
        t.iter().map(|t| unit(area_vector(v[t[0]], v[t[1]], v[t[2]]))).collect()
    }

    #[test]
    fn noise_is_damped_and_the_shape_kept() {
        let (clean, triangles) = modal_mesh::icosphere(4);
        // Deterministic white noise (xorshift): ±1 % of the radius, along the radius.
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let noisy: Vec<V3> = clean
            .iter()
            .map(|&p| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let uniform = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                scale(p, 1.0 + 0.02 * uniform)
            })
            .collect();
        let rms =
            |x: &[V3]| (x.iter().map(|&p| (norm(p) - 1.0).powi(2)).sum::<f64>() / x.len() as f64).sqrt();
        let smoothed = taubin(&noisy, &triangles, &facets(&clean, &triangles), 60.0, 10);
        let (before, after) = (rms(&noisy), rms(&smoothed));
        println!("radial noise rms {before:.2e} -> {after:.2e}");
        // White noise spreads over the whole spectrum of the umbrella
        // operator; what is left is mostly its share below k ≈ 0.5.
        assert!(after < 0.45 * before, "radial noise rms {before:.2e} -> {after:.2e}");
        // The sphere keeps its radius (a plain Laplacian of 20 steps of ½ shrinks it by percents).
        let mean: f64 = smoothed.iter().map(|&p| norm(p)).sum::<f64>() / smoothed.len() as f64;
        assert!((mean - 1.0).abs() < 2e-3, "mean radius {mean}");
    }

    #[test]
    fn a_cube_keeps_its_edges_and_corners() {
        // Each face of the unit cube in 4×4 squares: smoothing moves no vertex
        // off the cube (face vertices are flat, edge vertices slide along
        // straight creases, corners stay).
        let n = 4;
        let mut vertices: Vec<V3> = Vec::new();
        let mut index = HashMap::new();
        let mut triangles = Vec::new();
        let mut id = |p: [i64; 3], vertices: &mut Vec<V3>| {
            *index.entry(p).or_insert_with(|| {
                vertices.push(p.map(|c| c as f64 / n as f64));
                vertices.len() - 1
            })
        };
        for axis in 0..3 {
            for side in [0, n] {
                for i in 0..n {
                    for j in 0..n {
                        let at = |di: i64, dj: i64| {
                            let mut p = [0; 3];
                            p[axis] = side;
                            p[(axis + 1) % 3] = i + di;
                            p[(axis + 2) % 3] = j + dj;
                            p
                        };
                        let q = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)].map(|p| id(p, &mut vertices));
                        triangles.push([q[0], q[1], q[2]]);
                        triangles.push([q[0], q[2], q[3]]);
                    }
                }
            }
        }
        let smoothed = taubin(&vertices, &triangles, &facets(&vertices, &triangles), 60.0, 10);
        for (p, s) in vertices.iter().zip(&smoothed) {
            let off = (0..3).filter(|&c| (p[c] - s[c]).abs() > 1e-12).count();
            let on_faces = (0..3).filter(|&c| p[c] == 0.0 || p[c] == 1.0).count();
            // A face vertex may move in its face (1 boundary coordinate fixed), an edge vertex along its edge.
            assert!(off <= 3 - on_faces, "{p:?} -> {s:?}");
            assert!(s.iter().all(|c| (-1e-12..=1.0 + 1e-12).contains(c)), "{p:?} -> {s:?}");
        }
    }

    #[test]
    fn a_vertex_on_no_triangle_stays() {
        let (mut v, t) = modal_mesh::icosphere(1);
        v.push([5.0, 5.0, 5.0]);
        let s = taubin(&v, &t, &facets(&v, &t), 60.0, 3);
        assert_eq!(s.last(), Some(&[5.0, 5.0, 5.0]));
    }
}
