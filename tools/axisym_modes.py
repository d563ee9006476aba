#!/usr/bin/env python3
"""Independent reference frequencies of a free solid of revolution, by an axisymmetric FEM
with one Fourier harmonic at a time: the converged reference for bells and bowls that a
3-D tet mesh cannot afford (BENCHMARKS.md, "The corpus bell's crown").

For harmonic n the displacement is u_r = U(r,z) cos nθ, u_θ = V(r,z) sin nθ,
u_z = W(r,z) cos nθ, and the strains (engineering shear) are
  ε_rr = U_r,  ε_θθ = (U + nV)/r,  ε_zz = W_z,  γ_rz = U_z + W_r,
  γ_rθ = V_r − (V + nU)/r,  γ_θz = V_z − nW/r,
so K = ∫ Bᵀ D B r dr dz and M = ρ ∫ Nᵀ N r dr dz over the meridian section (the θ integral is
a common factor of K and M). n ≥ 1 modes come in degenerate pairs in 3-D (cos ↔ sin); n = 0
holds the axisymmetric (U, W) and the torsional (V) families. On the axis: U = V = 0 (n = 0),
U + V = 0 and W = 0 (n = 1), U = V = W = 0 (n ≥ 2). Six-node triangles from Gmsh (2-D),
7-point Gauss rule; shift-invert Lanczos (scipy). Rigid modes (below 1 Hz) are dropped.

The section is read from a revolved OBJ (`modal mesh corpus`'s thin_shell, or any surface
made by revolving a closed (r, z) profile about z): the vertices in the half-plane y = 0,
x ≥ 0, in the order of the first ring's profile. A faceted OBJ of N segments lies between
the circles through its vertices and through its facets' midlines (radius × cos(π/N));
`--radius-scale cos(pi/N)` solves the inner bound.

Element size SIZE, and at each profile vertex at most its local thickness / ACROSS (the
distance to the nearest segment across the section), graded by Gmsh: a neck or a knife edge is
resolved without refining the whole section.

usage: axisym_modes.py SURFACE.obj --h SIZE --harmonics 0,1,2,3 --modes K
       --E PA --nu NU --rho KG_M3 [--radius-scale S] [--across A]
Needs: pip install gmsh numpy scipy
"""
import argparse
import json
import math
import time

import gmsh
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla


def profile_from_obj(path, tol=1e-12):
    """(r, z) of the vertices in the half-plane y = 0, x ≥ 0, in file order, duplicates dropped."""
    pts = []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                x, y, z = (float(t) for t in line.split()[1:4])
                if abs(y) <= tol and x >= -tol:
                    p = (max(x, 0.0), z)
                    if not pts or math.dist(p, pts[-1]) > 1e-12:
                        pts.append(p)
    if len(pts) > 1 and math.dist(pts[0], pts[-1]) <= 1e-12:
        pts.pop()
    return pts


def local_thickness(profile):
    """For each vertex, the distance to the nearest segment across the section from it: the
    local thickness there (small at a neck). A segment counts only when the way to it along
    the outline is more than twice as long as the straight way, so the neighbours on a finely
    drawn curve, and the other face at a knife edge's tip, are not mistaken for thickness."""
    p = np.asarray(profile, dtype=float)
    a, b = p, np.roll(p, -1, axis=0)
    seg = np.linalg.norm(b - a, axis=1)
    along = np.concatenate([[0.0], np.cumsum(seg)])  # outline length to each vertex
    total = along[-1]
    ab = b - a
    out = []
    for i, q in enumerate(p):
        t = np.clip(np.einsum("ij,ij->i", q - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0.0, 1.0)
        d = np.linalg.norm(a + t[:, None] * ab - q, axis=1)
        # Outline length from vertex i to the nearer end of each segment, either way round.
        ends = np.stack([along[:-1], along[1:]], axis=1) - along[i]
        way = np.min(np.minimum(np.abs(ends), total - np.abs(ends)), axis=1)
        across = way > 2.0 * d
        out.append(float(d[across].min()) if across.any() else math.inf)
    return out


def mesh_section(profile, h, across):
    """Six-node triangles of the closed polygon `profile`, size `h`, and at least `across`
    elements across the local thickness at each vertex: (nodes (n, 2), triangles (m, 6))."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("section")
    geo = gmsh.model.geo
    sizes = [min(h, t / across) for t in local_thickness(profile)]
    pts = [geo.addPoint(r, z, 0.0, s) for (r, z), s in zip(profile, sizes)]
    lines = [geo.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
    geo.addPlaneSurface([geo.addCurveLoop(lines)])
    geo.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 1)
    gmsh.option.setNumber("Mesh.ElementOrder", 2)
    gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)
    gmsh.model.mesh.generate(2)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    index = {t: i for i, t in enumerate(tags)}
    nodes = coords.reshape(-1, 3)[:, :2]
    _, elem = gmsh.model.mesh.getElementsByType(9)  # 6-node triangles
    tri = np.array([index[t] for t in elem], dtype=np.int64).reshape(-1, 6)
    gmsh.finalize()
    return nodes, tri


# 7-point, degree-5 rule on the reference triangle (area 1/2).
_A, _B = 0.0597158717, 0.4701420641
_C, _D = 0.7974269853, 0.1012865073
GAUSS = [
    (1 / 3, 1 / 3, 0.225 / 2),
    (_A, _B, 0.1323941527 / 2), (_B, _A, 0.1323941527 / 2), (_B, _B, 0.1323941527 / 2),
    (_C, _D, 0.1259391805 / 2), (_D, _C, 0.1259391805 / 2), (_D, _D, 0.1259391805 / 2),
]


def shape(xi, eta):
    """Six-node triangle (Gmsh order: corners 0-2, mid-edges 01, 12, 20): N and dN/d(xi, eta)."""
    l0 = 1 - xi - eta
    n = np.array([l0 * (2 * l0 - 1), xi * (2 * xi - 1), eta * (2 * eta - 1), 4 * l0 * xi, 4 * xi * eta, 4 * eta * l0])
    dxi = np.array([-(4 * l0 - 1), 4 * xi - 1, 0.0, 4 * (l0 - xi), 4 * eta, -4 * eta])
    deta = np.array([-(4 * l0 - 1), 0.0, 4 * eta - 1, -4 * xi, 4 * xi, 4 * (l0 - eta)])
    return n, np.vstack([dxi, deta])


def assemble(nodes, tri, n, E, nu, rho):
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[range(3), range(3)] += 2 * mu
    D[range(3, 6), range(3, 6)] = mu
    rows, cols, kv, mv = [], [], [], []
    rules = [(shape(x, e), w) for (x, e, w) in GAUSS]
    for t in tri:
        xy = nodes[t]
        ke, me = np.zeros((18, 18)), np.zeros((18, 18))
        for (N, dN), w in rules:
            J = dN @ xy
            detJ = abs(np.linalg.det(J))
            dr, dz = np.linalg.solve(J, dN)  # dN/dr, dN/dz
            r = N @ xy[:, 0]
            B = np.zeros((6, 18))
            U, V, W = slice(0, 18, 3), slice(1, 18, 3), slice(2, 18, 3)
            B[0, U] = dr
            B[1, U], B[1, V] = N / r, n * N / r
            B[2, W] = dz
            B[3, U], B[3, W] = dz, dr
            B[4, V], B[4, U] = dr - N / r, -n * N / r
            B[5, V], B[5, W] = dz, -n * N / r
            Nm = np.zeros((3, 18))
            Nm[0, U], Nm[1, V], Nm[2, W] = N, N, N
            f = w * detJ * r
            ke += f * B.T @ D @ B
            me += f * rho * Nm.T @ Nm
        dofs = (3 * t[:, None] + np.arange(3)).ravel()
        rows.append(np.repeat(dofs, 18))
        cols.append(np.tile(dofs, 18))
        kv.append(ke.ravel())
        mv.append(me.ravel())
    size = 3 * len(nodes)
    K = sp.csr_matrix((np.concatenate(kv), (np.concatenate(rows), np.concatenate(cols))), shape=(size, size))
    M = sp.csr_matrix((np.concatenate(mv), (np.concatenate(rows), np.concatenate(cols))), shape=(size, size))
    return K, M


def axis_constraints(nodes, n):
    """T with u = T q: the axis conditions of harmonic n (see the module doc)."""
    size = 3 * len(nodes)
    on_axis = np.abs(nodes[:, 0]) < 1e-12 * max(1.0, np.abs(nodes).max())
    cols, free = {}, []
    rows, cs, vals = [], [], []
    for i in range(len(nodes)):
        for c in range(3):
            d = 3 * i + c
            if on_axis[i]:
                if n == 0 and c in (0, 1):
                    continue
                if n == 1 and c == 2:
                    continue
                if n >= 2:
                    continue
                if n == 1 and c == 1:  # V = −U on the axis
                    rows.append(d)
                    cs.append(cols[3 * i])
                    vals.append(-1.0)
                    continue
            cols[d] = len(free)
            free.append(d)
            rows.append(d)
            cs.append(cols[d])
            vals.append(1.0)
    return sp.csr_matrix((vals, (rows, cs)), shape=(size, len(free)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("obj")
    ap.add_argument("--h", type=float, required=True)
    ap.add_argument("--harmonics", default="0,1,2,3")
    ap.add_argument("--modes", type=int, default=6)
    ap.add_argument("--E", type=float, required=True)
    ap.add_argument("--nu", type=float, required=True)
    ap.add_argument("--rho", type=float, required=True)
    ap.add_argument("--radius-scale", type=float, default=1.0)
    ap.add_argument("--across", type=float, default=4.0,
                    help="elements across the local thickness at each profile vertex (a neck or knife edge)")
    a = ap.parse_args()
    profile = [(r * a.radius_scale, z) for (r, z) in profile_from_obj(a.obj)]
    t0 = time.time()
    nodes, tri = mesh_section(profile, a.h, a.across)
    out = {"h_m": a.h, "across": a.across, "min_thickness_m": min(local_thickness(profile)), "radius_scale": a.radius_scale, "section_nodes": len(nodes), "harmonics": {}}
    for n in (int(x) for x in a.harmonics.split(",")):
        K, M = assemble(nodes, tri, n, a.E, a.nu, a.rho)
        T = axis_constraints(nodes, n)
        Kr, Mr = (T.T @ K @ T).tocsc(), (T.T @ M @ T).tocsc()
        sigma = -(2 * math.pi * 10.0) ** 2
        w2 = sla.eigsh(Kr, k=a.modes + 4, M=Mr, sigma=sigma, which="LM", return_eigenvectors=False)
        hz = sorted(math.sqrt(max(x, 0.0)) / (2 * math.pi) for x in w2)
        out["harmonics"][n] = [f for f in hz if f > 1.0][: a.modes]
    out["seconds"] = time.time() - t0
    print(json.dumps(out))


if __name__ == "__main__":
    main()
