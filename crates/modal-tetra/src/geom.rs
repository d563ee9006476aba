//! Small 3-vector helpers and exact-formula geometric predicates in f64.

/// 3-vector.
pub type V3 = [f64; 3];

/// a − b.
#[inline]
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// a + b.
#[inline]
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
/// s a.
#[inline]
pub fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
/// a · b.
#[inline]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
/// a × b.
#[inline]
pub fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
/// |a|.
#[inline]
pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}
/// a + t (b − a).
#[inline]
pub fn lerp(a: V3, b: V3, t: f64) -> V3 {
    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])]
}

/// Six times the signed volume of tet (a, b, c, d): (b−a)×(c−a)·(d−a).
#[inline]
pub fn orient6(a: V3, b: V3, c: V3, d: V3) -> f64 {
    dot(cross(sub(b, a), sub(c, a)), sub(d, a))
}

/// `v / |v|`, or `v` itself when it is zero.
#[inline]
pub fn unit(v: V3) -> V3 {
    let n = norm(v);
    if n > 0.0 {
        scale(v, 1.0 / n)
    } else {
        v
    }
}

/// The bounding box (lower corner, upper corner) of points; (+∞, −∞) when
/// there are none.
pub use modal_mesh::bounding_box as bounds;

/// Area vector ½ (b−a)×(c−a) of a triangle (outward for counter-clockwise).
#[inline]
pub fn area_vector(a: V3, b: V3, c: V3) -> V3 {
    scale(cross(sub(b, a), sub(c, a)), 0.5)
}

/// The six dihedral angles of a tet (degrees), one per edge.
pub fn dihedral_angles_deg(p: [V3; 4]) -> [f64; 6] {
    // Face normals (outward up to a common sign) of faces opposite each vertex.
    const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
    let n: [V3; 4] = std::array::from_fn(|i| {
        let [a, b, c] = FACES[i];
        cross(sub(p[b], p[a]), sub(p[c], p[a]))
    });
    // Edge (i, j) is shared by the faces opposite the other two vertices k, l.
    const PAIRS: [[usize; 2]; 6] = [[2, 3], [1, 3], [1, 2], [0, 3], [0, 2], [0, 1]];
    std::array::from_fn(|e| {
        let [k, l] = PAIRS[e];
        let c = dot(n[k], n[l]) / (norm(n[k]) * norm(n[l]));
        // Interior dihedral angle = π − angle between outward normals.
        180.0 - c.clamp(-1.0, 1.0).acos().to_degrees()
    })
}

/// Closest point on triangle (a, b, c) to p ([`modal_mesh::closest_point_on_triangle`]).
pub fn closest_on_triangle(p: V3, a: V3, b: V3, c: V3) -> V3 {
    modal_mesh::closest_point_on_triangle(p, a, b, c).0
}

/// Parameter t ∈ [0, 1] where segment p→q crosses triangle (a, b, c), if it
/// does (Möller–Trumbore, two-sided).
pub fn segment_triangle(p: V3, q: V3, a: V3, b: V3, c: V3) -> Option<f64> {
    let d = sub(q, p);
    let e1 = sub(b, a);
    let e2 = sub(c, a);
    let h = cross(d, e2);
    let det = dot(e1, h);
    let scale_ref = norm(e1) * norm(e2) * norm(d);
    if det.abs() <= 1e-14 * scale_ref {
        return None;
    }
    let inv = 1.0 / det;
    let s = sub(p, a);
    let u = dot(s, h) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = cross(s, e1);
    let v = dot(d, qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = dot(e2, qv) * inv;
    (0.0..=1.0).contains(&t).then_some(t)
}

/// Solid angle (sr) of triangle (a, b, c) seen from q, signed positive when
/// q is on the back (inner) side of a counter-clockwise triangle
/// (Van Oosterom & Strackee 1983).
#[inline]
pub fn solid_angle(q: V3, a: V3, b: V3, c: V3) -> f64 {
    let a = sub(a, q);
    let b = sub(b, q);
    let c = sub(c, q);
    let (la, lb, lc) = (norm(a), norm(b), norm(c));
    let num = dot(a, cross(b, c));
    let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    2.0 * num.atan2(den)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_tet_dihedral_is_70_53() {
        let p = [[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]];
        for a in dihedral_angles_deg(p) {
            assert!((a - 70.528_779).abs() < 1e-5, "{a}");
        }
    }

    #[test]
    fn corner_tet_has_three_right_angles() {
        let p = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let mut a = dihedral_angles_deg(p);
        a.sort_by(f64::total_cmp);
        assert!((a[3] - 90.0).abs() < 1e-9 && (a[5] - 90.0).abs() < 1e-9);
        assert!((a[0] - 54.735_610).abs() < 1e-5);
    }

    #[test]
    fn solid_angle_of_octant_face() {
        // Triangle of the unit axis points seen from the origin: 4π/8.
        let w = solid_angle([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        assert!((w - std::f64::consts::PI / 2.0).abs() < 1e-12);
    }
}
