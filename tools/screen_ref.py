#!/usr/bin/env python3
"""Independent reference for modal's thin-wall (open screen) solver and for its
closed-surface solver on a thin flat body: a rigid disc of radius 0.1 m
translating broadside at 1 m/s, solved by bempp-cl.

Packages (pip, in a virtualenv OUTSIDE the repository), as for rad_ref.py:
    /work/venvs/bempp/bin/pip install bempp-cl==0.4.2 numba==0.68.1

Usage: screen_ref.py FREQ_HZ THICKNESS_M RINGS
Prints |p| [Pa] at 0.4 m from the centre, at 0, 0.6 and 1.2 rad from the axis:
- "closed": the disc THICKNESS_M thick (faces and a rim band), Burton-Miller
  with continuous piecewise-linear pressure (P1) and piecewise-constant
  velocity (DP0), Galerkin;
- "screen": the disc of no thickness, the hypersingular equation
  W mu = -dp/dn for the pressure jump mu (P1 without the free edge's nodes,
  so mu vanishes there), Galerkin; p = DL mu.
Both meshes are the ones of modal's `examples/screen.rs` (`flat_disc`,
`closed_disc`: RINGS rings of 6 RINGS nodes about a centre node), so the
numbers compare discretization for discretization.

Time convention e^{-i omega t}, G = e^{ikr}/(4 pi r), rho0 = 1.21 kg/m3,
c = 343 m/s.
"""
import sys

import numpy as np
import scipy.linalg


def face(v, tris, z, up, a, rings, segments):
    centre = len(v)
    v.append([0.0, 0.0, z])

    def at(r, s):
        return centre + 1 + (r - 1) * segments + s % segments

    for r in range(1, rings + 1):
        rho = a * r / rings
        for s in range(segments):
            phi = 2 * np.pi * (s + 0.5 * (r % 2)) / segments
            v.append([rho * np.cos(phi), rho * np.sin(phi), z])

    def push(p, q, w):
        tris.append([p, q, w] if up else [p, w, q])

    for s in range(segments):
        push(centre, at(1, s), at(1, s + 1))
    for r in range(1, rings):
        for s in range(segments):
            push(at(r, s), at(r + 1, s), at(r + 1, s + 1))
            push(at(r, s), at(r + 1, s + 1), at(r, s + 1))
    return [at(rings, s) for s in range(segments)]


def closed_disc(a, t, rings):
    segments = 6 * rings
    v, tris = [], []
    top = face(v, tris, 0.5 * t, True, a, rings, segments)
    bottom = face(v, tris, -0.5 * t, False, a, rings, segments)
    for s in range(segments):
        a0, a1, b0, b1 = top[s], top[(s + 1) % segments], bottom[s], bottom[(s + 1) % segments]
        tris.append([b0, a1, a0])
        tris.append([b0, b1, a1])
    return np.array(v, float), np.array(tris)


def flat_disc(a, rings):
    v, tris = [], []
    face(v, tris, 0.0, True, a, rings, 6 * rings)
    return np.array(v, float), np.array(tris)


def main():
    import bempp_cl.api as bempp
    from bempp_cl.api.operators.boundary import helmholtz, sparse
    from bempp_cl.api.operators.potential import helmholtz as potential

    bempp.DEFAULT_DEVICE_INTERFACE = "numba"
    f, t, rings = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
    c, rho, a = 343.0, 1.21, 0.1
    k = 2 * np.pi * f / c
    iwr = 1j * 2 * np.pi * f * rho
    pts = np.array([[0.4 * np.sin(th), 0.0, 0.4 * np.cos(th)] for th in (0.0, 0.6, 1.2)]).T.copy()

    v, tr = closed_disc(a, t, rings)
    grid = bempp.Grid(v.T.copy(), tr.T.copy())
    p1 = bempp.function_space(grid, "P", 1)
    dp0 = bempp.function_space(grid, "DP", 0)
    alpha = 1j / k
    lhs = (0.5 * sparse.identity(p1, p1, p1) - helmholtz.double_layer(p1, p1, p1, k)
           + alpha * helmholtz.hypersingular(p1, p1, p1, k))
    rhs_op = -(helmholtz.single_layer(dp0, p1, p1, k)
               + alpha * (0.5 * sparse.identity(dp0, p1, p1) + helmholtz.adjoint_double_layer(dp0, p1, p1, k)))
    g = iwr * grid.normals[:, 2]
    u = scipy.linalg.solve(lhs.weak_form().A, rhs_op.weak_form() @ g)
    p = (potential.double_layer(p1, pts, k) * bempp.GridFunction(p1, coefficients=u)
         - potential.single_layer(dp0, pts, k) * bempp.GridFunction(dp0, coefficients=g))
    print("closed", t, np.abs(p.reshape(-1)))

    v, tr = flat_disc(a, rings)
    grid = bempp.Grid(v.T.copy(), tr.T.copy())
    p1 = bempp.function_space(grid, "P", 1, include_boundary_dofs=False)
    dp0 = bempp.function_space(grid, "DP", 0)
    w = helmholtz.hypersingular(p1, p1, p1, k).weak_form().A
    q = iwr * np.ones(dp0.global_dof_count)
    mu = scipy.linalg.solve(w, -(sparse.identity(dp0, p1, p1).weak_form() @ q))
    p = potential.double_layer(p1, pts, k) * bempp.GridFunction(p1, coefficients=mu)
    print("screen", np.abs(p.reshape(-1)))


if __name__ == "__main__":
    main()
