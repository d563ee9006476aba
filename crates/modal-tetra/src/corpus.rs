//! A corpus of real-world-like surface assets, generated here (deterministic,
//! no downloads), for testing the pipeline on the kinds of meshes users
//! actually have rather than on textbook solids.
//!
//! Every asset is scaled to a bounding-box diagonal of [`DIAGONAL_M`]
//! (20 cm, the size at which issue #14 measured real models) and kept small
//! (a few thousand triangles). [`ASSETS`] lists them with what each one
//! exercises:
//! - `teapot`: four intersecting *open* shells (a body open at the top, a lid
//!   dome, a spout tube and a handle tube without end caps), like the classic
//!   multi-part teapot model.
//! - `vessel`: a closed cup with a thin handle and a spout, three overlapping
//!   closed parts.
//! - `holed_sphere`: a sphere with two holes cut out (open boundary).
//! - `nonmanifold`: two boxes touching along one edge (a non-manifold edge)
//!   and a dangling fin triangle on the first box.
//! - `animal`: a four-legged animal-like body made of overlapping closed
//!   parts (torso, legs, neck, head, ears, tail).
//! - `bracket`: a CAD-like L-bracket with a gusset: sharp edges and corners.
//! - `thin_shell`: a bell with a wall 1.2 % of its height.
//! - `sheet` (odd input): one flat open square, no volume at all.
//! - `soup` (odd input): a box as a triangle soup with duplicate vertices,
//!   flipped and zero-area triangles.

use std::f64::consts::PI;

use crate::geom::{add, cross, norm, scale, sub, V3};
use crate::shapes::{bell, cuboid, icosphere, revolve};
use crate::TriSurface;

/// Bounding-box diagonal every corpus asset is scaled to (m).
pub const DIAGONAL_M: f64 = 0.2;

/// One corpus entry: name (also the file stem) and what it exercises.
#[derive(Clone, Copy, Debug)]
pub struct AssetInfo {
    /// Short name, e.g. `teapot`.
    pub name: &'static str,
    /// One line saying what is odd about it.
    pub description: &'static str,
    /// True for inputs that are expected to be refused with a clear error
    /// (no volume at all) rather than to give a bank.
    pub odd: bool,
}

/// The corpus, in a fixed order.
pub const ASSETS: [AssetInfo; 9] = [
    AssetInfo {
        name: "teapot",
        description: "four intersecting open shells: body, lid, spout, handle",
        odd: false,
    },
    AssetInfo {
        name: "vessel",
        description: "closed cup with a thin handle and a spout (overlapping parts)",
        odd: false,
    },
    AssetInfo { name: "holed_sphere", description: "sphere with two holes (open boundary)", odd: false },
    AssetInfo {
        name: "nonmanifold",
        description: "two boxes sharing an edge, plus a dangling fin triangle",
        odd: false,
    },
    AssetInfo {
        name: "animal",
        description: "four-legged animal-like body of overlapping closed parts",
        odd: false,
    },
    AssetInfo {
        name: "bracket",
        description: "CAD L-bracket with a gusset: sharp edges and corners",
        odd: false,
    },
    AssetInfo { name: "thin_shell", description: "bell with a wall 1.2 % of its height", odd: false },
    AssetInfo { name: "sheet", description: "a single flat open square: no volume", odd: true },
    AssetInfo {
        name: "soup",
        description: "box as a triangle soup: duplicate vertices, flipped and zero-area triangles",
        odd: true,
    },
];

/// The asset called `name`, scaled to [`DIAGONAL_M`]; `None` for an unknown name.
pub fn asset(name: &str) -> Option<TriSurface> {
    let mut s = match name {
        "teapot" => teapot(),
        "vessel" => vessel(),
        "holed_sphere" => holed_sphere(),
        "nonmanifold" => nonmanifold(),
        "animal" => animal(),
        "bracket" => bracket(),
        "thin_shell" => bell(0.16, 0.07, 0.002, 48),
        "sheet" => sheet(),
        "soup" => soup(),
        _ => return None,
    };
    let d = s.diagonal();
    if d > 0.0 {
        s.scale(DIAGONAL_M / d);
    }
    Some(s)
}

/// Appends `part` to `out` under `name` (its own vertices, its own part range).
fn append(out: &mut TriSurface, part: TriSurface, name: &str) {
    let offset = out.vertices.len();
    let first = out.triangles.len();
    out.vertices.extend(part.vertices);
    out.triangles.extend(part.triangles.iter().map(|t| t.map(|v| v + offset)));
    out.parts.push((name.to_string(), first..out.triangles.len()));
}

fn assemble(parts: Vec<(TriSurface, &str)>) -> TriSurface {
    let mut out = TriSurface::default();
    for (part, name) in parts {
        append(&mut out, part, name);
    }
    out
}

/// Applies `f` to every vertex.
fn map(mut s: TriSurface, f: impl Fn(V3) -> V3) -> TriSurface {
    s.vertices.iter_mut().for_each(|p| *p = f(*p));
    s
}

/// A tube of radius `radius(i)` along `path` (points with tangents ⟂ y, as
/// all paths here lie in planes parallel to x–z); with `caps` the ends are
/// closed by fans, giving a closed outward surface, else it is open.
fn tube(path: &[V3], radius: impl Fn(usize) -> f64, sides: usize, caps: bool) -> TriSurface {
    let y = [0.0, 1.0, 0.0];
    let n = path.len();
    let mut v = Vec::with_capacity(n * sides + 2);
    for i in 0..n {
        let t = sub(path[(i + 1).min(n - 1)], path[i.saturating_sub(1)]);
        let t = scale(t, 1.0 / norm(t));
        let w = cross(t, y);
        for j in 0..sides {
            let a = 2.0 * PI * j as f64 / sides as f64;
            v.push(add(path[i], scale(add(scale(y, a.cos()), scale(w, a.sin())), radius(i))));
        }
    }
    let id = |i: usize, j: usize| i * sides + j % sides;
    let mut f = Vec::new();
    for i in 0..n - 1 {
        for j in 0..sides {
            // (y, t × y, t) is right-handed: with the ring angle increasing
            // counter-clockwise about t, this order gives outward normals.
            f.push([id(i, j), id(i + 1, j + 1), id(i + 1, j)]);
            f.push([id(i, j), id(i, j + 1), id(i + 1, j + 1)]);
        }
    }
    if caps {
        v.push(path[0]);
        let c0 = v.len() - 1;
        v.push(path[n - 1]);
        let c1 = v.len() - 1;
        for j in 0..sides {
            f.push([c0, id(0, j + 1), id(0, j)]);
            f.push([c1, id(n - 1, j), id(n - 1, j + 1)]);
        }
    }
    TriSurface { vertices: v, triangles: f, parts: Vec::new() }
}

/// Points on a circular arc in the x–z plane: centre, radius, angles (rad).
fn arc(centre: V3, r: f64, from: f64, to: f64, steps: usize) -> Vec<V3> {
    (0..=steps)
        .map(|k| {
            let a = from + (to - from) * k as f64 / steps as f64;
            [centre[0] + r * a.cos(), centre[1], centre[2] + r * a.sin()]
        })
        .collect()
}

fn ellipsoid(centre: V3, radii: V3, subdivisions: u32) -> TriSurface {
    map(icosphere(1.0, subdivisions), |p| std::array::from_fn(|c| centre[c] + radii[c] * p[c]))
}

/// Utah-teapot-like: four open shells that intersect.
fn teapot() -> TriSurface {
    // Body: open at the top (the profile ends on the rim, not on the axis).
    let body: Vec<(f64, f64)> = (0..=20)
        .map(|k| {
            let s = k as f64 / 20.0;
            let z = 0.09 * s;
            let r = if k == 0 { 0.0 } else { 0.045 + 0.03 * (PI * (0.15 + 0.8 * s)).sin() - 0.012 * s };
            (r, z)
        })
        .collect();
    let rim = body[20].0;
    // Lid: a dome whose rim reaches past the body's rim and below it.
    let lid: Vec<(f64, f64)> = (0..=12)
        .map(|k| {
            let a = 0.5 * PI * k as f64 / 12.0;
            ((rim + 0.004) * a.sin(), 0.086 + 0.018 * a.cos())
        })
        .collect();
    let spout_path: Vec<V3> = (0..=12)
        .map(|k| {
            let s = k as f64 / 12.0;
            [0.04 + 0.07 * s, 0.0, 0.025 + 0.065 * s * s]
        })
        .collect();
    let handle_path = arc([-0.068, 0.0, 0.045], 0.028, 0.3 * PI, 1.7 * PI, 20);
    assemble(vec![
        (revolve(&body, 40, "body"), "body"),
        (revolve(&lid, 40, "lid"), "lid"),
        (tube(&spout_path, |i| 0.012 - 0.006 * i as f64 / 12.0, 16, false), "spout"),
        (tube(&handle_path, |_| 0.006, 12, false), "handle"),
    ])
}

/// A closed cup with a thin handle and a spout.
fn vessel() -> TriSurface {
    let (r, h, wall) = (0.045, 0.11, 0.004);
    let profile = [(0.0, 0.0), (r, 0.0), (r, h), (r - wall, h), (r - wall, wall), (0.0, wall)];
    let cup = revolve(&profile, 48, "cup");
    let handle = tube(&arc([-r + 0.002, 0.0, 0.055], 0.032, 0.5 * PI, 1.5 * PI, 20), |_| 0.0035, 10, true);
    let spout_path: Vec<V3> =
        (0..=8).map(|k| [r - 0.003 + 0.035 * k as f64 / 8.0, 0.0, 0.08 + 0.02 * k as f64 / 8.0]).collect();
    let spout = tube(&spout_path, |i| 0.007 - 0.003 * i as f64 / 8.0, 12, true);
    assemble(vec![(cup, "cup"), (handle, "handle"), (spout, "spout")])
}

/// A sphere with a cap and a side patch removed.
fn holed_sphere() -> TriSurface {
    let mut s = icosphere(0.1, 3);
    let v = s.vertices.clone();
    s.triangles.retain(|t| {
        let c: V3 = std::array::from_fn(|a| (v[t[0]][a] + v[t[1]][a] + v[t[2]][a]) / 3.0);
        c[2] < 0.085 && c[0] < 0.092
    });
    let n = s.triangles.len();
    s.parts = vec![("holed_sphere".into(), 0..n)];
    s
}

/// Two boxes sharing an edge, and a fin triangle on the first box's top diagonal.
fn nonmanifold() -> TriSurface {
    let a = cuboid(0.08, 0.08, 0.05);
    let b = map(cuboid(0.06, 0.06, 0.05), |p| [p[0] + 0.08, p[1] + 0.08, p[2]]);
    let mut out = assemble(vec![(a, "box_a"), (b, "box_b")]);
    // Corners 5 = (lx, 0, lz) and 6 = (0, ly, lz) of box a: its top face's diagonal.
    let apex = [0.04, 0.04, 0.09];
    out.vertices.push(apex);
    let first = out.triangles.len();
    out.triangles.push([5, 6, out.vertices.len() - 1]);
    out.parts.push(("fin".into(), first..first + 1));
    out
}

/// Torso, four legs, neck, head, ears and tail: overlapping closed parts.
fn animal() -> TriSurface {
    let mut parts = vec![(ellipsoid([0.0, 0.0, 0.09], [0.08, 0.035, 0.03], 3), "torso")];
    for (k, (x, y)) in
        [(0.055, 0.02), (0.055, -0.02), (-0.055, 0.02), (-0.055, -0.02)].into_iter().enumerate()
    {
        let leg: Vec<V3> = (0..=6).map(|i| [x, y, 0.1 - 0.1 * i as f64 / 6.0]).collect();
        let name = ["leg_fl", "leg_fr", "leg_bl", "leg_br"][k];
        parts.push((tube(&leg, |i| 0.011 - 0.004 * i as f64 / 6.0, 12, true), name));
    }
    let neck: Vec<V3> =
        (0..=6).map(|i| [0.07 + 0.03 * i as f64 / 6.0, 0.0, 0.1 + 0.04 * i as f64 / 6.0]).collect();
    parts.push((tube(&neck, |_| 0.014, 12, true), "neck"));
    parts.push((ellipsoid([0.11, 0.0, 0.15], [0.03, 0.018, 0.018], 2), "head"));
    parts.push((ellipsoid([0.1, 0.012, 0.172], [0.006, 0.003, 0.012], 1), "ear_l"));
    parts.push((ellipsoid([0.1, -0.012, 0.172], [0.006, 0.003, 0.012], 1), "ear_r"));
    let tail = arc([-0.11, 0.0, 0.08], 0.035, 0.05 * PI, -0.45 * PI, 8);
    parts.push((tube(&tail, |_| 0.004, 8, true), "tail"));
    assemble(parts)
}

/// A closed prism: the polygon `outline` (counter-clockwise in x–y, star-shaped
/// from `kernel`) extruded from z0 to z1.
fn extrude(outline: &[(f64, f64)], kernel: (f64, f64), z0: f64, z1: f64) -> TriSurface {
    let n = outline.len();
    let mut v: Vec<V3> = Vec::with_capacity(2 * n + 2);
    for &z in &[z0, z1] {
        v.extend(outline.iter().map(|&(x, y)| [x, y, z]));
    }
    v.push([kernel.0, kernel.1, z0]);
    v.push([kernel.0, kernel.1, z1]);
    let (c0, c1) = (2 * n, 2 * n + 1);
    let mut f = Vec::new();
    for i in 0..n {
        let j = (i + 1) % n;
        f.push([c0, j, i]);
        f.push([c1, n + i, n + j]);
        f.push([i, j, n + j]);
        f.push([i, n + j, n + i]);
    }
    TriSurface { vertices: v, triangles: f, parts: Vec::new() }
}

/// An L-bracket (two 12 cm arms, 12 mm thick, 50 mm wide) with a gusset.
fn bracket() -> TriSurface {
    let (a, t) = (0.12, 0.012);
    let l = [(0.0, 0.0), (a, 0.0), (a, t), (t, t), (t, a), (0.0, a)];
    let gusset = [(t - 0.002, t - 0.002), (0.06, t - 0.002), (t - 0.002, 0.06)];
    assemble(vec![
        (extrude(&l, (0.5 * t, 0.5 * t), 0.0, 0.05), "bracket"),
        (extrude(&gusset, (0.025, 0.025), 0.019, 0.031), "gusset"),
    ])
}

fn sheet() -> TriSurface {
    let v = vec![[0.0, 0.0, 0.0], [0.14, 0.0, 0.0], [0.14, 0.14, 0.0], [0.0, 0.14, 0.0]];
    TriSurface { vertices: v, triangles: vec![[0, 1, 2], [0, 2, 3]], parts: vec![("sheet".into(), 0..2)] }
}

/// A box as a triangle soup: three fresh vertices per triangle, every other
/// triangle flipped, and two zero-area triangles.
fn soup() -> TriSurface {
    let b = cuboid(0.12, 0.1, 0.11);
    let mut out = TriSurface::default();
    for (k, t) in b.triangles.iter().enumerate() {
        let base = out.vertices.len();
        out.vertices.extend(t.iter().map(|&v| b.vertices[v]));
        out.triangles.push(if k % 2 == 0 { [base, base + 2, base + 1] } else { [base, base + 1, base + 2] });
    }
    let base = out.vertices.len();
    out.vertices.extend([[0.0, 0.0, 0.0], [0.06, 0.0, 0.0], [0.12, 0.0, 0.0]]);
    out.triangles.push([base, base + 1, base + 2]);
    out.triangles.push([base, base, base + 1]);
    let n = out.triangles.len();
    out.parts = vec![("soup".into(), 0..n)];
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose;

    #[test]
    fn every_asset_is_scaled_and_named() {
        for info in ASSETS {
            let s = asset(info.name).expect(info.name);
            assert!((s.diagonal() - DIAGONAL_M).abs() < 1e-12, "{}: {}", info.name, s.diagonal());
            s.validate().expect(info.name);
        }
        assert!(asset("no such asset").is_none());
    }

    #[test]
    fn assets_have_the_defects_they_claim() {
        let r = |n: &str| diagnose(&asset(n).unwrap());
        let teapot = r("teapot");
        assert_eq!(teapot.parts, ["body", "lid", "spout", "handle"]);
        assert_eq!(teapot.components, 4);
        // Body rim, lid rim, two spout ends, two handle ends.
        assert_eq!(teapot.open_boundary_edges, 40 + 40 + 2 * 16 + 2 * 12);
        for closed in ["vessel", "animal", "bracket", "thin_shell"] {
            let rep = r(closed);
            assert_eq!(rep.open_boundary_edges, 0, "{closed}");
            assert_eq!(rep.non_manifold_edges, 0, "{closed}");
            assert_eq!(rep.flipped_faces, 0, "{closed} is built outward");
            assert_eq!(rep.components, asset(closed).unwrap().parts.len(), "{closed}");
        }
        assert!(r("holed_sphere").open_boundary_edges > 0);
        let nm = r("nonmanifold");
        // The shared vertical edge (4 triangles) and the fin's diagonal (3).
        assert_eq!(nm.non_manifold_edges, 2);
        assert_eq!(nm.open_boundary_edges, 2);
        let soup = r("soup");
        assert!(soup.duplicate_vertices > 0 && soup.degenerate_triangles == 2 && soup.flipped_faces > 0);
        assert!(r("sheet").enclosed_volume_m3 == 0.0);
    }

    #[test]
    fn generation_is_deterministic() {
        for info in ASSETS {
            assert_eq!(asset(info.name), asset(info.name), "{}", info.name);
        }
    }
}
