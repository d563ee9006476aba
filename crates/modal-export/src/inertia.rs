//! Principal axes of an inertia tensor, as glTF physics extensions store it.
//!
//! A symmetric tensor `I` is diagonalized as `I = R diag(λ) Rᵀ` by cyclic
//! Jacobi rotations (Golub & Van Loan §8.5: each rotation zeroes one
//! off-diagonal entry; the sweep converges quadratically). The columns of
//! `R` are the principal axes; `R` is made a proper rotation (det +1) and
//! stored as the unit quaternion `(x, y, z, w)` that rotates the principal
//! axes into the body frame, so `I = R(q) diag(λ) R(q)ᵀ` (Shepperd's method
//! for the matrix → quaternion step: pick the largest of `w², x², y², z²`
//! to divide by, for accuracy).

/// A 3×3 matrix, row-major.
pub type Mat3 = [[f64; 3]; 3];

/// Principal moments `λ` and the quaternion `(x, y, z, w)` of the axes.
pub fn principal(inertia: &Mat3) -> ([f64; 3], [f64; 4]) {
    let mut a = *inertia;
    let mut v: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..50 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        let diag = a[0][0].powi(2) + a[1][1].powi(2) + a[2][2].powi(2);
        if off <= f64::EPSILON * f64::EPSILON * diag || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            // tan 2θ = 2 a_pq / (a_qq − a_pp); the smaller root t = tan θ.
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let sign = if theta >= 0.0 { 1.0 } else { -1.0 };
            let t = sign / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ A J with J the rotation in the (p, q) plane.
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (row_p, row_q) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * row_p[k] - s * row_q[k];
                a[q][k] = s * row_p[k] + c * row_q[k];
            }
            for row in v.iter_mut() {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    if det(&v) < 0.0 {
        for row in v.iter_mut() {
            row[2] = -row[2];
        }
    }
    ([a[0][0], a[1][1], a[2][2]], quaternion(&v))
}

/// The tensor `R(q) diag(λ) R(q)ᵀ` of principal moments `λ` and axes `q`.
pub fn tensor(moments: [f64; 3], q: [f64; 4]) -> Mat3 {
    let r = rotation(q);
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = (0..3).map(|k| r[i][k] * moments[k] * r[j][k]).sum();
        }
    }
    out
}

fn det(m: &Mat3) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Rotation matrix of the unit quaternion `(x, y, z, w)` (normalized first).
pub fn rotation(q: [f64; 4]) -> Mat3 {
    let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    let [x, y, z, w] = if n > 0.0 { q.map(|c| c / n) } else { [0.0, 0.0, 0.0, 1.0] };
    [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
        [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
        [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
    ]
}

/// Unit quaternion `(x, y, z, w)` of a proper rotation matrix (Shepperd).
fn quaternion(m: &Mat3) -> [f64; 4] {
    let trace = m[0][0] + m[1][1] + m[2][2];
    let q = if trace >= m[0][0].max(m[1][1]).max(m[2][2]) {
        let w = 0.5 * (1.0 + trace).max(0.0).sqrt();
        [(m[2][1] - m[1][2]) / (4.0 * w), (m[0][2] - m[2][0]) / (4.0 * w), (m[1][0] - m[0][1]) / (4.0 * w), w]
    } else if m[0][0] >= m[1][1] && m[0][0] >= m[2][2] {
        let x = 0.5 * (1.0 + m[0][0] - m[1][1] - m[2][2]).max(0.0).sqrt();
        [x, (m[0][1] + m[1][0]) / (4.0 * x), (m[0][2] + m[2][0]) / (4.0 * x), (m[2][1] - m[1][2]) / (4.0 * x)]
    } else if m[1][1] >= m[2][2] {
        let y = 0.5 * (1.0 - m[0][0] + m[1][1] - m[2][2]).max(0.0).sqrt();
        [(m[0][1] + m[1][0]) / (4.0 * y), y, (m[1][2] + m[2][1]) / (4.0 * y), (m[0][2] - m[2][0]) / (4.0 * y)]
    } else {
        let z = 0.5 * (1.0 - m[0][0] - m[1][1] + m[2][2]).max(0.0).sqrt();
        [(m[0][2] + m[2][0]) / (4.0 * z), (m[1][2] + m[2][1]) / (4.0 * z), z, (m[1][0] - m[0][1]) / (4.0 * z)]
    };
    let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    q.map(|c| c / n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &Mat3, b: &Mat3, tol: f64) -> bool {
        (0..3).all(|i| (0..3).all(|j| (a[i][j] - b[i][j]).abs() <= tol))
    }

    #[test]
    fn diagonal_tensors_keep_identity_axes() {
        let (m, q) = principal(&[[2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 5.0]]);
        assert_eq!(m, [2.0, 3.0, 5.0]);
        assert_eq!(q, [0.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn a_rotated_tensor_is_recovered() {
        // Independent reference: a known rotation (30° about z, then 40° about x) of diag(1, 2, 7).
        let (c1, s1) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let (c2, s2) = (40f64.to_radians().cos(), 40f64.to_radians().sin());
        let rz = [[c1, -s1, 0.0], [s1, c1, 0.0], [0.0, 0.0, 1.0]];
        let rx = [[1.0, 0.0, 0.0], [0.0, c2, -s2], [0.0, s2, c2]];
        let mut r = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                r[i][j] = (0..3).map(|k| rx[i][k] * rz[k][j]).sum();
            }
        }
        let d = [1.0, 2.0, 7.0];
        let mut inertia = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                inertia[i][j] = (0..3).map(|k| r[i][k] * d[k] * r[j][k]).sum();
            }
        }
        let (moments, q) = principal(&inertia);
        let mut sorted = moments;
        sorted.sort_by(f64::total_cmp);
        for (a, b) in sorted.iter().zip(d) {
            assert!((a - b).abs() < 1e-12, "{moments:?}");
        }
        assert!((q.iter().map(|c| c * c).sum::<f64>() - 1.0).abs() < 1e-12);
        assert!(close(&tensor(moments, q), &inertia, 1e-12));
    }

    #[test]
    fn repeated_moments_and_proper_rotations() {
        let inertia = [[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 3.0]];
        let (m, q) = principal(&inertia);
        assert!(close(&tensor(m, q), &inertia, 1e-12));
        assert!((det(&rotation(q)) - 1.0).abs() < 1e-12);
    }
}
