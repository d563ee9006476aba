//! A lower bound on the body's lowest interior resonance: below it the
//! conventional boundary integral equation is uniquely solvable
//! ([`crate::bem::Formulation::Automatic`]).
//!
//! The conventional equation fails at the interior Dirichlet resonances of
//! the solid `Ω` the surface encloses: `−Δu = k²u` in `Ω`, `u = 0` on its
//! surface. Three rigorous lower bounds on the first, `k₁`, each from a
//! classical inequality on the first eigenvalue `λ₁ = k₁²`:
//!
//! - **Faber–Krahn**: no domain of volume `V` has a lower `λ₁` than the ball
//!   of that volume, so `k₁ ≥ π/R_V`, `R_V = (3V/4π)^⅓`. Exact for a sphere
//!   (`ka = π`); the best bound for round solid bodies.
//! - **Domain monotonicity**: `Ω ⊂ B` implies `λ₁(Ω) ≥ λ₁(B)`, and a box
//!   `a × b × c` has `λ₁ = π²(1/a² + 1/b² + 1/c²)`. Any box holding every
//!   vertex holds the solid; tried in the bank's axes and in the principal
//!   axes of the vertices. Exact for a box (a bar: 16.7 kHz for the demo's,
//!   where Faber–Krahn gives 6.6 kHz); a plate `t` thick is bounded by
//!   `π/t` (a 2 mm disc: 86 kHz).
//! - **A spherical shell** `r₁ ≤ |x − c| ≤ r₂` holding the solid (domain
//!   monotonicity again): its first eigenfunction is radial, `sin(π(r −
//!   r₁)/t)/r`, so `λ₁ = (π/t)²`, `t = r₂ − r₁`. `c` is the centre of the
//!   sphere fitted to the vertices (least squares), `r₁` the nearest
//!   panel's distance, `r₂` the farthest vertex's. The shell holds the solid
//!   when `c` is outside it: the ball `|x − c| < r₁` meets no panel, so it
//!   is all inside or all outside, and with `c` outside it is outside; so
//!   is everything beyond `r₂`, which reaches infinity. Sharp for
//!   bowls, cups, domes and hollow balls (the demo's 4 mm glass bowl:
//!   `π/t` with `t` its wall plus how far its profile strays from a sphere),
//!   none for a solid body (`c` inside).
//!
//! The bound is the largest of the three; several bodies: each holds for
//! the union (the box and the shell hold them all; each body's ball bound
//! exceeds that of their summed volume).

use faer::linalg::solvers::SolveLstsq;
use faer::{Mat, Side};

use crate::geometry::{dot, norm, sub, BoundaryMesh};

/// A lower bound [1/m] on the wavenumber of the lowest interior Dirichlet
/// resonance of the solid `mesh` encloses (module doc). 0 when the
/// surface encloses no volume (inward or open: then nothing is below it).
pub fn interior_wavenumber_bound(mesh: &BoundaryMesh) -> f64 {
    let volume = mesh.enclosed_volume();
    if !(volume.is_finite() && volume > 0.0) {
        return 0.0;
    }
    let ball = std::f64::consts::PI / (3.0 * volume / (4.0 * std::f64::consts::PI)).cbrt();
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let frames = std::iter::once(identity).chain(principal_axes(&mesh.vertices));
    let boxes = frames.map(|axes| box_bound(&mesh.vertices, axes)).fold(ball, f64::max);
    boxes.max(spherical_shell_bound(mesh).unwrap_or(0.0))
}

/// `π/t` of the spherical shell about the vertices' fitted sphere that
/// holds the solid (module doc), or `None` when there is none (the centre
/// inside the solid or on the surface, or no sphere fits).
fn spherical_shell_bound(mesh: &BoundaryMesh) -> Option<f64> {
    let centre = fitted_sphere_centre(&mesh.vertices)?;
    let inner = (0..mesh.len()).map(|j| mesh.panel_distance(j, centre)).fold(f64::INFINITY, f64::min);
    let outer = mesh.vertices.iter().map(|v| norm(sub(*v, centre))).fold(0.0, f64::max);
    let thickness = outer - inner;
    let holds = inner > 0.0 && thickness > 0.0 && !mesh.contains(centre);
    holds.then(|| std::f64::consts::PI / thickness)
}

/// The centre of the sphere `|x|² = 2c·x + d` fitted to `points` by least
/// squares (QR), if finite.
fn fitted_sphere_centre(points: &[[f64; 3]]) -> Option<[f64; 3]> {
    let a = Mat::from_fn(points.len(), 4, |i, j| if j < 3 { 2.0 * points[i][j] } else { 1.0 });
    let b = Mat::from_fn(points.len(), 1, |i, _| dot(points[i], points[i]));
    let x = a.qr().solve_lstsq(&b);
    let c = [x[(0, 0)], x[(1, 0)], x[(2, 0)]];
    c.iter().all(|v| v.is_finite()).then_some(c)
}

/// `π √(Σ 1/L²)` of the box with edges along `axes` (orthonormal) that
/// holds every point.
fn box_bound(points: &[[f64; 3]], axes: [[f64; 3]; 3]) -> f64 {
    let sum: f64 = axes
        .iter()
        .map(|axis| {
            let (lo, hi) = points
                .iter()
                .map(|p| dot(*p, *axis))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
            let side = hi - lo;
            if side > 0.0 {
                1.0 / (side * side)
            } else {
                0.0
            }
        })
        .sum();
    std::f64::consts::PI * sum.sqrt()
}

/// The eigenvectors of the points' covariance (orthonormal rows), or
/// `None` if the eigensolver fails.
fn principal_axes(points: &[[f64; 3]]) -> Option<[[f64; 3]; 3]> {
    let n = points.len() as f64;
    let mean = [0, 1, 2].map(|k| points.iter().map(|p| p[k]).sum::<f64>() / n);
    let cov = Mat::from_fn(3, 3, |i, j| {
        points.iter().map(|p| (p[i] - mean[i]) * (p[j] - mean[j])).sum::<f64>() / n
    });
    let eig = cov.self_adjoint_eigen(Side::Lower).ok()?;
    let u = eig.U();
    let axes = [0, 1, 2].map(|c| [u[(0, c)], u[(1, c)], u[(2, c)]]);
    axes.iter().flatten().all(|x| x.is_finite()).then_some(axes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::tests::{box_surface, icosphere};

    /// A box `sides` [m] turned about two axes, as 12 outward triangles.
    fn turned_box(sides: [f64; 3]) -> BoundaryMesh {
        let (c, s) = (0.6f64.cos(), 0.6f64.sin());
        let (c2, s2) = (0.3f64.cos(), 0.3f64.sin());
        box_surface(sides, |p| {
            let q = [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]];
            [q[0], c2 * q[1] - s2 * q[2], s2 * q[1] + c2 * q[2]]
        })
    }

    #[test]
    fn a_box_is_bounded_by_its_own_first_resonance() {
        for sides in [[0.3, 0.02, 0.012], [0.08, 0.05, 0.04], [0.2, 0.18, 0.002]] {
            let mesh = turned_box(sides);
            assert!(mesh.enclosed_volume() > 0.0, "outward");
            let want = std::f64::consts::PI * sides.iter().map(|l| 1.0 / (l * l)).sum::<f64>().sqrt();
            let got = interior_wavenumber_bound(&mesh);
            assert!((got / want - 1.0).abs() < 1e-9, "{sides:?}: {got} vs {want}");
        }
    }

    /// A sphere's first resonance is `ka = π`: Faber–Krahn's bound (a box
    /// gives only `π√3/2`, and no spherical shell holds a solid ball), from
    /// just above on the inscribed panels.
    #[test]
    fn a_sphere_is_bounded_by_faber_krahn() {
        let ball = icosphere(0.1, [0.02, -0.01, 0.03], 3);
        assert_eq!(spherical_shell_bound(&ball), None, "the centre is inside");
        let got = interior_wavenumber_bound(&ball) * 0.1;
        assert!(got > std::f64::consts::PI && got < 1.01 * std::f64::consts::PI, "{got}");
    }

    /// A hollow ball (outer surface out, the cavity's surface into the
    /// cavity) is a spherical shell: bounded by `π/t` up to its panels'
    /// sagitta, far above Faber–Krahn and the box.
    #[test]
    fn a_hollow_ball_is_bounded_by_its_wall() {
        let (outer, inner, c) = (0.1, 0.096, [0.01, 0.02, -0.03]);
        let o = icosphere(outer, c, 4);
        let i = icosphere(inner, c, 4);
        let mut vertices = o.vertices.clone();
        let mut tris: Vec<[usize; 3]> = o.panels.iter().map(|p| p.corners).collect();
        let shift = vertices.len();
        vertices.extend(i.vertices.iter().copied());
        tris.extend(
            i.panels.iter().map(|p| [p.corners[0] + shift, p.corners[2] + shift, p.corners[1] + shift]),
        );
        let hollow = BoundaryMesh::new(vertices, &tris).unwrap();
        assert!(hollow.enclosed_volume() > 0.0);
        let got = interior_wavenumber_bound(&hollow);
        // The inscribed panels come closer to the centre than the inner
        // sphere by their sagitta, so the shell is a little thicker.
        let wall = std::f64::consts::PI / (outer - inner);
        assert!(got < wall && got > 0.8 * wall, "{got} vs {wall}");
        let solid_box = std::f64::consts::PI * 3f64.sqrt() / (2.0 * outer);
        assert!(got > 10.0 * solid_box);
    }
}
