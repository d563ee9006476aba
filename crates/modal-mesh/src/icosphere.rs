//! The icosphere: the unit sphere's reference triangulation, shared by the
//! tetrahedralizer's test shapes (`modal-tetra`) and the radiation solver's
//! reference surfaces (`modal-radiation`).
//!
//! The icosahedron's 12 corners `(0, ±1, ±φ)` and cyclic permutations
//! (`φ = (1 + √5)/2`); each subdivision splits every triangle into four
//! through its edge midpoints, each new midpoint projected onto the unit
//! sphere at once (more even triangles than projecting once at the end).

use std::collections::HashMap;

/// Unit icosphere centred at the origin with `20·4^subdivisions` triangles
/// (3: 1 280, 5: 20 480, 7: 327 680), outward (counter-clockwise seen from
/// outside): corner positions and triangles.
pub fn icosphere(subdivisions: u32) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut f: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let unit = |p: [f64; 3]| {
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        p.map(|c| c / r)
    };
    for p in &mut v {
        *p = unit(*p);
    }
    for _ in 0..subdivisions {
        let mut mid: HashMap<(usize, usize), usize> = HashMap::new();
        let mut next = Vec::with_capacity(4 * f.len());
        for tri in &f {
            let m = [0, 1, 2].map(|k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    v.push(unit(std::array::from_fn(|c| v[a][c] + v[b][c])));
                    v.len() - 1
                })
            });
            next.push([tri[0], m[0], m[2]]);
            next.push([tri[1], m[1], m[0]]);
            next.push([tri[2], m[2], m[1]]);
            next.push(m);
        }
        f = next;
    }
    (v, f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_outward_unit_sphere() {
        let (v, f) = icosphere(3);
        assert_eq!(f.len(), 1280);
        assert_eq!(v.len(), 642); // Euler: V = F/2 + 2
        assert!(v.iter().all(|p| ((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 1.0).abs() < 1e-12));
        // Every triangle faces outward: (b − a) × (c − a) · a > 0.
        let mut volume = 0.0;
        for t in &f {
            let [a, b, c] = t.map(|i| v[i]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
            let d = n[0] * a[0] + n[1] * a[1] + n[2] * a[2];
            assert!(d > 0.0);
            volume += d / 6.0;
        }
        // Inscribed polyhedron: just below 4π/3.
        let ball = 4.0 * std::f64::consts::PI / 3.0;
        assert!(volume < ball && volume > 0.99 * ball, "{volume}");
    }
}
