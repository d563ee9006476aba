//! Closest point of a triangle to a point (Ericson, *Real-Time Collision Detection*,
//! §5.1.5: classify `p` into the Voronoi regions of the vertices, edges and face).
//! Shared by the surface locator of the synthesizer and the tetrahedralizer's BVH.

type V3 = [f64; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn axpy(a: V3, k: f64, d: V3) -> V3 {
    [a[0] + k * d[0], a[1] + k * d[1], a[2] + k * d[2]]
}
fn ratio(n: f64, d: f64) -> f64 {
    if d != 0.0 {
        (n / d).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Closest point of triangle `(a, b, c)` to `p`: `(point, barycentrics)`; degenerate
/// triangles give a finite point (never NaN).
pub fn closest_point_on_triangle(p: V3, a: V3, b: V3, c: V3) -> (V3, V3) {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = ratio(d1, d1 - d3);
        return (axpy(a, v, ab), [1.0 - v, v, 0.0]);
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = ratio(d2, d2 - d6);
        return (axpy(a, w, ac), [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = ratio(d4 - d3, (d4 - d3) + (d5 - d6));
        return (axpy(b, w, sub(c, b)), [0.0, 1.0 - w, w]);
    }
    let sum = va + vb + vc;
    if sum == 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let v = vb / sum;
    let w = vc / sum;
    (axpy(axpy(a, v, ab), w, ac), [1.0 - v - w, v, w])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_point_regions() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        // Face interior, above the plane.
        let (q, w) = closest_point_on_triangle([0.25, 0.25, 2.0], a, b, c);
        assert_eq!(q, [0.25, 0.25, 0.0]);
        assert!((w[0] - 0.5).abs() < 1e-15 && (w[1] - 0.25).abs() < 1e-15);
        // Vertex region of a, edge region of bc.
        assert_eq!(closest_point_on_triangle([-1.0, -1.0, 0.0], a, b, c).1, [1.0, 0.0, 0.0]);
        let (q, w) = closest_point_on_triangle([1.0, 1.0, 0.0], a, b, c);
        assert!((q[0] - 0.5).abs() < 1e-15 && (q[1] - 0.5).abs() < 1e-15);
        assert!((w[1] - 0.5).abs() < 1e-15 && (w[2] - 0.5).abs() < 1e-15);
        // Degenerate triangle: no NaN.
        let (q, _) = closest_point_on_triangle([0.3, 0.2, 0.0], a, a, a);
        assert!(q.iter().all(|x| x.is_finite()));
    }
}
