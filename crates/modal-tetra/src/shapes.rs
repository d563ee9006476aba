//! Closed, outward-oriented triangle surfaces for tests, examples and
//! benchmarks: icosphere, box, torus, and solids of revolution (bowl, bell).

use std::f64::consts::PI;

use crate::TriSurface;

fn single(vertices: Vec<[f64; 3]>, triangles: Vec<[usize; 3]>, name: &str) -> TriSurface {
    let n = triangles.len();
    TriSurface { vertices, triangles, parts: vec![(name.to_string(), 0..n)] }
}

/// Icosphere of `radius` (m) centred at the origin: 20·4^`subdivisions`
/// triangles (3: 1280, 5: 20 480, 7: 327 680).
pub fn icosphere(radius: f64, subdivisions: u32) -> TriSurface {
    let (v, f) = modal_mesh::icosphere(subdivisions);
    single(v.into_iter().map(|p| p.map(|c| c * radius)).collect(), f, "sphere")
}

/// Axis-aligned box [0, lx] × [0, ly] × [0, lz] (m), 12 triangles.
pub fn cuboid(lx: f64, ly: f64, lz: f64) -> TriSurface {
    let v = (0..8)
        .map(|i| [(i & 1) as f64 * lx, ((i >> 1) & 1) as f64 * ly, ((i >> 2) & 1) as f64 * lz])
        .collect();
    let f = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    single(v, f, "box")
}

/// Torus around the z axis (major radius `major`, tube radius `minor`) (m).
pub fn torus(major: f64, minor: f64, segments: usize, sides: usize) -> TriSurface {
    let (n, m) = (segments.max(3), sides.max(3));
    let mut v = Vec::with_capacity(n * m);
    for i in 0..n {
        let u = 2.0 * PI * i as f64 / n as f64;
        for j in 0..m {
            let w = 2.0 * PI * j as f64 / m as f64;
            let r = major + minor * w.cos();
            v.push([r * u.cos(), r * u.sin(), minor * w.sin()]);
        }
    }
    let id = |i: usize, j: usize| (i % n) * m + (j % m);
    let mut f = Vec::with_capacity(2 * n * m);
    for i in 0..n {
        for j in 0..m {
            f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    single(v, f, "torus")
}

/// Closed solid of revolution about the z axis. `profile` is a closed
/// polyline (r, z) going counter-clockwise in the (r, z) half-plane; its
/// first and last points must lie on the axis (r = 0), or be the same point
/// off the axis (an annulus, like [`tube`]: that ring is then written twice,
/// and the repair of `tetrahedralize` or of a reader welds it).
pub fn revolve(profile: &[(f64, f64)], segments: usize, name: &str) -> TriSurface {
    let n = segments.max(3);
    let mut v: Vec<[f64; 3]> = Vec::new();
    let mut ring: Vec<Vec<usize>> = Vec::new();
    for &(r, z) in profile {
        if r <= 0.0 {
            v.push([0.0, 0.0, z]);
            ring.push(vec![v.len() - 1; n]);
        } else {
            let ids = (0..n)
                .map(|i| {
                    let u = 2.0 * PI * i as f64 / n as f64;
                    v.push([r * u.cos(), r * u.sin(), z]);
                    v.len() - 1
                })
                .collect();
            ring.push(ids);
        }
    }
    let mut f = Vec::new();
    for k in 0..profile.len() - 1 {
        let (a, b) = (&ring[k], &ring[k + 1]);
        for i in 0..n {
            let j = (i + 1) % n;
            for t in [[a[i], b[j], b[i]], [a[i], a[j], b[j]]] {
                if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                    f.push(t);
                }
            }
        }
    }
    single(v, f, name)
}

/// A tube (hollow cylinder) along z from 0 to `length`, radii `inner` <
/// `outer` (m), its walls in `rows` rings of quads as a CAD export or a
/// user's OBJ of a chime or pipe gives them (1: single strips the tube's length).
pub fn tube(inner: f64, outer: f64, length: f64, rows: usize, segments: usize) -> TriSurface {
    let z = |i: usize| length * i as f64 / rows as f64;
    let mut profile = vec![(inner, 0.0)];
    profile.extend((0..=rows).map(|i| (outer, z(i))));
    profile.extend((0..=rows).rev().map(|i| (inner, z(i))));
    revolve(&profile, segments, "tube")
}

/// A hemispherical bowl of outer radius `radius` and wall `thickness` (m)
/// with a flat foot, opening upwards.
pub fn bowl(radius: f64, thickness: f64, segments: usize) -> TriSurface {
    let steps = 16;
    let ri = radius - thickness;
    let foot = 0.35 * radius;
    let mut profile = vec![(0.0, -radius + 0.05 * radius)];
    profile.push((foot, -radius + 0.05 * radius));
    // Outer wall from the foot up to the rim.
    let start = (foot / radius).asin();
    for s in 0..=steps {
        let a = start + (PI / 2.0 - start) * s as f64 / steps as f64;
        profile.push((radius * a.sin(), -radius * a.cos()));
    }
    // Inner wall from the rim down to the axis.
    for s in (0..=steps).rev() {
        let a = (PI / 2.0) * s as f64 / steps as f64;
        profile.push((ri * a.sin(), -ri * a.cos()));
    }
    revolve(&profile, segments, "bowl")
}

/// A bell-like shell of revolution: height `height`, mouth radius
/// `mouth` (m), wall thickness `thickness` (m).
pub fn bell(height: f64, mouth: f64, thickness: f64, segments: usize) -> TriSurface {
    let steps = 24;
    let shape = |s: f64| {
        // Radius as a function of height fraction s (0 = mouth, 1 = crown).
        mouth * (0.55 + 0.45 * (1.0 - s).powf(1.8)) * (1.0 - 0.1 * s)
    };
    // Counter-clockwise in (r, z): crown on the axis, inner wall down to the
    // mouth, lip, outer wall back up to the crown.
    let mut profile = vec![(0.0, height)];
    for k in (0..=steps).rev() {
        let s = k as f64 / steps as f64;
        profile.push((shape(s), s * height));
    }
    profile.push((shape(0.0), -0.5 * thickness));
    profile.push((shape(0.0) + thickness, -0.5 * thickness));
    for k in 0..=steps {
        let s = k as f64 / steps as f64;
        profile.push((shape(s) + thickness, s * height));
    }
    profile.push((0.0, height + thickness));
    revolve(&profile, segments, "bell")
}

/// A mug: a cup of revolution (radius, height, wall) plus a torus-segment
/// handle, as two overlapping parts ("cup", "handle").
pub fn mug(radius: f64, height: f64, wall: f64, segments: usize) -> TriSurface {
    let inner = radius - wall;
    let profile = [(0.0, 0.0), (radius, 0.0), (radius, height), (inner, height), (inner, wall), (0.0, wall)];
    let cup = revolve(&profile, segments, "cup");
    let mut handle = torus(0.3 * height, 0.12 * radius, segments / 2, 12);
    // Rotate the handle by 90° about x (into the x–z plane), push it against the wall.
    for p in &mut handle.vertices {
        *p = [p[0] + radius + 0.05 * height, -p[2], p[1] + 0.5 * height];
    }
    let offset = cup.vertices.len();
    let mut out = cup;
    let first = out.triangles.len();
    out.vertices.extend(handle.vertices);
    out.triangles.extend(handle.triangles.iter().map(|t| t.map(|v| v + offset)));
    out.parts.push(("handle".to_string(), first..out.triangles.len()));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose;

    #[test]
    fn generated_shapes_are_closed_and_outward() {
        for s in [
            icosphere(0.05, 2),
            cuboid(0.3, 0.02, 0.01),
            torus(0.05, 0.02, 32, 12),
            bowl(0.1, 0.01, 32),
            bell(0.2, 0.1, 0.01, 32),
        ] {
            let r = diagnose(&s);
            assert!(r.is_clean(), "{:?}: {r:?}", s.parts);
            assert_eq!(r.components, 1);
        }
        let sphere = diagnose(&icosphere(0.05, 4)).enclosed_volume_m3;
        let exact = 4.0 / 3.0 * PI * 0.05f64.powi(3);
        assert!((sphere / exact - 1.0).abs() < 0.005, "{sphere}");
        assert!((diagnose(&cuboid(0.3, 0.02, 0.01)).enclosed_volume_m3 - 6e-5).abs() < 1e-15);
    }

    #[test]
    fn mug_has_two_outward_parts() {
        let r = diagnose(&mug(0.04, 0.1, 0.005, 32));
        assert_eq!(r.parts, ["cup", "handle"]);
        assert_eq!(r.components, 2);
        assert_eq!(r.flipped_faces, 0);
        assert_eq!(r.open_boundary_edges, 0);
    }
}
