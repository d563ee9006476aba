//! A disc's triangulated surface, the test body of thin-wall radiation:
//! `rings` rings of `6·rings` nodes about a centre node on each face, every
//! other ring turned by half a step (no long thin triangles).

/// The surface of a disc of radius `radius` [m] about the origin, axis `z`,
/// outward counter-clockwise triangles: closed (both faces at `±thickness/2`
/// and one band of quads around the rim) for `thickness > 0`, one open face
/// at `z = 0` facing `+z` for `thickness = 0`.
pub fn disc_surface(radius: f64, thickness: f64, rings: usize) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let segments = 6 * rings.max(1);
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    let face = |z: f64, up: bool, v: &mut Vec<[f64; 3]>, tris: &mut Vec<[usize; 3]>| -> Vec<usize> {
        let centre = v.len();
        v.push([0.0, 0.0, z]);
        let at = |r: usize, s: usize| centre + 1 + (r - 1) * segments + s % segments;
        for r in 1..=rings {
            let rho = radius * r as f64 / rings as f64;
            for s in 0..segments {
                let phi = std::f64::consts::TAU * (s as f64 + 0.5 * (r % 2) as f64) / segments as f64;
                v.push([rho * phi.cos(), rho * phi.sin(), z]);
            }
        }
        let mut push = |a: usize, b: usize, c: usize| tris.push(if up { [a, b, c] } else { [a, c, b] });
        for s in 0..segments {
            push(centre, at(1, s), at(1, s + 1));
        }
        for r in 1..rings {
            for s in 0..segments {
                push(at(r, s), at(r + 1, s), at(r + 1, s + 1));
                push(at(r, s), at(r + 1, s + 1), at(r, s + 1));
            }
        }
        (0..segments).map(|s| at(rings, s)).collect()
    };
    if thickness <= 0.0 {
        face(0.0, true, &mut vertices, &mut triangles);
        return (vertices, triangles);
    }
    let top = face(0.5 * thickness, true, &mut vertices, &mut triangles);
    let bottom = face(-0.5 * thickness, false, &mut vertices, &mut triangles);
    for s in 0..segments {
        let (a0, a1, b0, b1) = (top[s], top[(s + 1) % segments], bottom[s], bottom[(s + 1) % segments]);
        triangles.push([b0, a1, a0]);
        triangles.push([b0, b1, a1]);
    }
    (vertices, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Area and (for the closed disc) volume by the divergence theorem.
    #[test]
    fn a_disc_has_its_area_and_volume() {
        let area_volume = |(v, t): (Vec<[f64; 3]>, Vec<[usize; 3]>)| {
            t.iter().fold((0.0, 0.0), |(area, vol), tri| {
                let [a, b, c] = tri.map(|i| v[i]);
                let (u, w) = ([0, 1, 2].map(|k| b[k] - a[k]), [0, 1, 2].map(|k| c[k] - a[k]));
                let n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
                let centroid = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0);
                let twice = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                (
                    area + 0.5 * twice,
                    vol + (centroid[0] * n[0] + centroid[1] * n[1] + centroid[2] * n[2]) / 6.0,
                )
            })
        };
        let pi_a2 = std::f64::consts::PI * 0.01;
        let (area, _) = area_volume(disc_surface(0.1, 0.0, 16));
        assert!((area / pi_a2 - 1.0).abs() < 1e-3, "{area}");
        let (area, volume) = area_volume(disc_surface(0.1, 0.002, 16));
        assert!((area / (2.0 * pi_a2 + std::f64::consts::TAU * 0.1 * 0.002) - 1.0).abs() < 2e-3, "{area}");
        assert!((volume / (pi_a2 * 0.002) - 1.0).abs() < 2e-3, "{volume}");
    }
}
