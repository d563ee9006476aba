#!/usr/bin/env python3
"""Independent reference for `modal radiation`: per-mode radiated pressure of a
mode bank by a Galerkin boundary-element solve with bempp-cl.

Packages (pip, in a virtualenv OUTSIDE the repository):
    python3 -m venv /work/venvs/bempp
    /work/venvs/bempp/bin/pip install bempp-cl==0.4.2 numba==0.68.1 safetensors==0.8.0
(numpy 2.4.6 and scipy 1.17.1 come with them). Run with that interpreter.

What it solves (time convention e^{-i omega t}, G = e^{ikr}/(4 pi r)):
mode i of the bank vibrating at its undamped frequency f_i with unit modal
velocity amplitude has surface velocity phi_i(x) [m/s] (mass-normalized
shape) and normal velocity v_n = phi_i . n, so dp/dn = i omega rho0 v_n on
the surface. The exterior Neumann problem is solved with the Burton-Miller
equation (no fictitious interior resonances), alpha = i/k:

    (1/2 I - K + alpha W) p = -(V + alpha (1/2 I + K')) dp/dn

(V, K, K', W: bempp's single, double, adjoint double layer and hypersingular
operators), and the pressure in the air is p(x) = (DL p)(x) - (SL dp/dn)(x).

How it differs from modal's own solver (crates/modal-radiation), so that the
two are independent:
- Galerkin with continuous piecewise-linear pressure (bempp P1) and
  piecewise-linear, per-triangle (discontinuous, DP1) normal velocity, against
  modal's collocation with constant pressure on clusters of flat panels;
- bempp's numerical singular quadrature against modal's own kernels;
- the surface: each quadratic (6-node) surface triangle of the bank is
  sampled on a lattice of (2R+1)(2R+2)/2 points of its own quadratic map
  (R = --refine; R = 1 gives exactly the bank's corner and mid-edge nodes) and
  split into (2R)^2 flat triangles; the velocity there is the quadratic
  interpolation of the shape and the normal is the quadratic triangle's own
  normal (d x/d xi cross d x/d eta) at that point, no averaging between
  triangles. With --velocity l2 each flat triangle's DP1 velocity is instead
  the L2 projection of that quadratic field over it (so it carries the
  field's exact flux; nodal sampling does not: a quadratic triangle's corner
  shape functions integrate to zero). A linear bank uses its flat triangles (split R^2 times).
  R = 0: the corner triangles only (velocity and normal at the corners, linear
  in between): 16x fewer element pairs, for low frequencies.

Usage:
    rad_ref.py BANK --point X,Y,Z [--point ...] [--sphere-points N,FACTOR]
               [--mode I ...] [--refine R] [--velocity nodes|l2]
               [--air-density 1.21] [--sound-speed 343] [-o OUT.json]
        prints (or writes) {"modes": [{"index", "frequency_hz",
        "pressure_pa": [[re, im], ...]}], ...}: the same layout as
        `modal radiation BANK --point ... --json`.
    rad_ref.py BANK --mode I [--mode ...] --trim OUT.bank
        writes a copy of BANK holding only the given modes (in ascending
        order), with its checksum recomputed (docs/bank-format.md), so that
        a committed test bank stays small.
    rad_ref.py --merge OUT.json IN.json [IN.json ...]
        one reference from several runs at the same points (each mode keeps
        the refine and quadrature it was solved with), modes in index order.
    rad_ref.py --self-test
        pulsating and oscillating spheres (and ka = pi) against closed forms.
    rad_ref.py --compare REF.json MODAL.json [--within-db 40]
        per mode and point the level error 20 log10(|p_modal| / |p_ref|) [dB];
        median and max over the modes within --within-db of the loudest, at
        their points within --within-db of the mode's loudest point.
"""

import argparse
import json
import math
import sys
import time

import numpy as np


def quadratic_shape(xi, eta):
    """Shape functions of the 6-node triangle (corners 0-2, mid-edge nodes of
    edges 01, 12, 20) and their xi, eta derivatives at arrays xi, eta."""
    l0 = 1.0 - xi - eta
    n = np.stack([l0 * (2 * l0 - 1), xi * (2 * xi - 1), eta * (2 * eta - 1),
                  4 * l0 * xi, 4 * xi * eta, 4 * eta * l0])
    dxi = np.stack([-(4 * l0 - 1), 4 * xi - 1, 0 * xi, 4 * (l0 - xi), 4 * eta, -4 * eta])
    deta = np.stack([-(4 * l0 - 1), 0 * xi, 4 * eta - 1, -4 * xi, 4 * xi, 4 * (l0 - eta)])
    return n, dxi, deta


def linear_shape(xi, eta):
    n = np.stack([1.0 - xi - eta, xi, eta])
    dxi = np.stack([-1.0 + 0 * xi, 1.0 + 0 * xi, 0 * xi])
    deta = np.stack([-1.0 + 0 * xi, 0 * xi, 1.0 + 0 * xi])
    return n, dxi, deta


def lattice(r):
    """Points (xi, eta) of the reference triangle's lattice with r intervals per
    edge, and its r^2 sub-triangles (counter-clockwise, like the parent)."""
    idx = {}
    pts = []
    for j in range(r + 1):
        for i in range(r + 1 - j):
            idx[(i, j)] = len(pts)
            pts.append((i / r, j / r))
    tris = []
    for j in range(r):
        for i in range(r - j):
            tris.append((idx[(i, j)], idx[(i + 1, j)], idx[(i, j + 1)]))
            if i + j + 2 <= r:
                tris.append((idx[(i + 1, j)], idx[(i + 1, j + 1)], idx[(i, j + 1)]))
    p = np.array(pts)
    return p[:, 0], p[:, 1], np.array(tris)


def load_bank(path):
    from safetensors.numpy import load_file
    b = load_file(path)
    return {
        "positions": b["surface_positions"].astype(np.float64),
        "triangles": b["surface_triangles"].astype(np.int64),
        "edges": b.get("surface_triangle_edge_nodes"),
        "shapes": b["shapes"].astype(np.float64),
        "frequencies_hz": b["frequencies_hz"],
        "centre": b["center_of_mass_m"],
    }


def refined_surface(bank, refine, modes, velocity="nodes"):
    """Flat triangles sampled on each bank triangle's own (quadratic or linear)
    map. Returns vertices (N, 3), triangles (M, 3) and, per triangle corner,
    the normal velocity of each mode (len(modes), M, 3)."""
    pos, tri, edges = bank["positions"], bank["triangles"], bank["edges"]
    quadratic = edges is not None
    r = (2 * refine if refine > 0 else 1) if quadratic else max(refine, 1)
    xi, eta, sub = lattice(r)
    n, dxi, deta = (quadratic_shape if quadratic else linear_shape)(xi, eta)
    nodes = np.concatenate([tri, edges], axis=1) if quadratic else tri  # (t, 6 or 3)
    x = pos[nodes]  # (t, q, 3)
    pts = np.einsum("qp,tqc->tpc", n, x)  # (t, P, 3)
    a = np.einsum("qp,tqc->tpc", dxi, x)
    b = np.einsum("qp,tqc->tpc", deta, x)
    normal = np.cross(a, b)
    normal /= np.linalg.norm(normal, axis=2, keepdims=True)
    phi = bank["shapes"][modes][:, nodes]  # (m, t, q, 3)
    vel = np.einsum("qp,mtqc->mtpc", n, phi)
    vn = np.einsum("mtpc,tpc->mtp", vel, normal)  # (m, t, P)
    # Merge lattice points shared by neighbouring triangles (same coordinates
    # up to round-off: an edge's points depend only on that edge's nodes).
    flat = pts.reshape(-1, 3)
    scale = np.abs(flat).max()
    key = np.round(flat / scale * 2**36).astype(np.int64)
    uniq, inverse = np.unique(key, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    verts = np.zeros((len(uniq), 3))
    verts[inverse] = flat
    t = len(tri)
    p_count = len(xi)
    glob = inverse.reshape(t, p_count)
    elements = glob[:, sub].reshape(-1, 3)  # (t * s, 3)
    if velocity == "l2":
        vn_corner = l2_corner_values(bank, nodes, xi, eta, sub, modes, quadratic).reshape(len(modes), -1, 3)
    else:
        vn_corner = vn[:, np.arange(t)[:, None, None], sub[None, :, :]].reshape(len(modes), -1, 3)
    return verts, elements, vn_corner


# Dunavant's 6-point rule on a triangle (barycentric points, weights summing
# to 1): exact for polynomials of degree 4.
_D4_A, _D4_B = 0.445948490915965, 0.091576213509771
DUNAVANT4_POINTS = np.array([[_D4_A, _D4_A, 1 - 2 * _D4_A], [_D4_A, 1 - 2 * _D4_A, _D4_A],
                             [1 - 2 * _D4_A, _D4_A, _D4_A], [_D4_B, _D4_B, 1 - 2 * _D4_B],
                             [_D4_B, 1 - 2 * _D4_B, _D4_B], [1 - 2 * _D4_B, _D4_B, _D4_B]])
DUNAVANT4_WEIGHTS = np.array([0.223381589678011] * 3 + [0.109951743655322] * 3)


def l2_corner_values(bank, nodes, xi, eta, sub, modes, quadratic):
    """DP1 corner values per (mode, triangle, sub-triangle, corner): the L2
    projection onto linear functions of v_n = phi . n (the triangle's own
    quadratic interpolant and normal) over each flat sub-triangle, so that
    each carries the interpolant's exact flux (a quadratic triangle's corner
    shape functions integrate to zero; nodal sampling does not keep that).
    On a flat sub-triangle with mass matrix (A/12)(I + J), the coefficients
    are c_i = 12 b_i - 3 sum(b), b_i = mean over the triangle of lambda_i f."""
    shape = quadratic_shape if quadratic else linear_shape
    pos, phi_all = bank["positions"], bank["shapes"]
    x = pos[nodes]  # (t, q, 3)
    corners = np.stack([xi[sub], eta[sub]], axis=-1)  # (s, 3, 2): each sub-triangle's corners in (xi, eta)
    qp = np.einsum("gc,scd->sgd", DUNAVANT4_POINTS, corners)  # (s, g, 2)
    n, dxi, deta = shape(qp[..., 0].reshape(-1), qp[..., 1].reshape(-1))  # (q, s*g)
    a = np.einsum("qp,tqc->tpc", dxi, x)
    b = np.einsum("qp,tqc->tpc", deta, x)
    normal = np.cross(a, b)
    normal /= np.linalg.norm(normal, axis=2, keepdims=True)
    phi = phi_all[modes][:, nodes]  # (m, t, q, 3)
    f = np.einsum("qp,mtqc,tpc->mtp", n, phi, normal)  # (m, t, s*g)
    f = f.reshape(len(modes), len(nodes), sub.shape[0], len(DUNAVANT4_WEIGHTS))
    bary = np.einsum("g,gi,mtsg->mtsi", DUNAVANT4_WEIGHTS, DUNAVANT4_POINTS, f)  # (m, t, s, 3)
    return 12 * bary - 3 * bary.sum(axis=-1, keepdims=True)


class Solver:
    """Burton-Miller Galerkin solve on one flat triangle grid."""

    def __init__(self, verts, elements):
        import bempp_cl.api as bempp
        bempp.DEFAULT_DEVICE_INTERFACE = "numba"  # bempp's OpenCL path is not used
        self.bempp = bempp
        self.grid = bempp.Grid(verts.T.copy(), elements.T.copy())
        self.p1 = bempp.function_space(self.grid, "P", 1)
        self.dp1 = bempp.function_space(self.grid, "DP", 1)
        self.elements = elements

    def dp1_coefficients(self, corner_values):
        """DP1 coefficients from values per (our triangle, our corner)."""
        grid_el = self.grid.elements  # (3, M): vertex ids per element, as bempp stores them
        l2g = self.dp1.local2global  # (M, 3)
        coeffs = np.zeros(self.dp1.global_dof_count, dtype=np.complex128)
        for j in range(3):
            vid = grid_el[j]
            # Position of that vertex among our triangle's corners.
            match = self.elements == vid[:, None]
            assert match.any(axis=1).all(), "bempp reordered the elements"
            coeffs[l2g[:, j]] = corner_values[match.argmax(axis=1) + 3 * np.arange(len(vid))]
        return coeffs

    def solve(self, k, omega_rho, corner_values_list, points):
        """Pressures (modes, points) for normal velocities per triangle corner."""
        from bempp_cl.api.operators.boundary import helmholtz, sparse
        from bempp_cl.api.operators.potential import helmholtz as potential
        import scipy.linalg
        p1, dp1 = self.p1, self.dp1
        alpha = 1j / k
        lhs = (0.5 * sparse.identity(p1, p1, p1) - helmholtz.double_layer(p1, p1, p1, k)
               + alpha * helmholtz.hypersingular(p1, p1, p1, k))
        rhs_op = -(helmholtz.single_layer(dp1, p1, p1, k)
                   + alpha * (0.5 * sparse.identity(dp1, p1, p1)
                              + helmholtz.adjoint_double_layer(dp1, p1, p1, k)))
        a = lhs.weak_form().A
        rhs_mat = rhs_op.weak_form()
        g = np.stack([omega_rho * 1j * self.dp1_coefficients(v.reshape(-1)) for v in corner_values_list], axis=1)
        b = np.stack([rhs_mat @ g[:, j] for j in range(g.shape[1])], axis=1)
        u = scipy.linalg.solve(a, b)
        pts = np.asarray(points, dtype=np.float64).T.copy()
        dl = potential.double_layer(p1, pts, k)
        sl = potential.single_layer(dp1, pts, k)
        out = []
        for j in range(g.shape[1]):
            pu = self.bempp.GridFunction(p1, coefficients=u[:, j])
            pg = self.bempp.GridFunction(dp1, coefficients=g[:, j])
            out.append((dl * pu - sl * pg).reshape(-1))
        return np.array(out)


def sphere_points(bank, count, factor):
    """`count` points spread evenly (Fibonacci spiral) on the sphere of radius
    `factor` bounding radii about the centre of mass (bounding radius: the
    farthest surface node from the centre)."""
    c = np.asarray(bank["centre"], dtype=np.float64)
    radius = factor * np.linalg.norm(bank["positions"] - c, axis=1).max()
    golden = math.pi * (3 - 5**0.5)
    out = []
    for i in range(count):
        z = 1 - 2 * (i + 0.5) / count
        s = (1 - z * z) ** 0.5
        out.append([float(c[0] + radius * s * math.cos(golden * i)),
                    float(c[1] + radius * s * math.sin(golden * i)), float(c[2] + radius * z)])
    return out


def reference(args):
    bank = load_bank(args.bank)
    n = len(bank["frequencies_hz"])
    modes = args.mode if args.mode else list(range(n))
    for m in modes:
        if not 0 <= m < n:
            sys.exit(f"mode {m} does not exist (the bank has {n} modes)")
    if args.sphere_points:
        count, factor = args.sphere_points
        args.point += sphere_points(bank, int(count), factor)
    if not args.point:
        sys.exit("give at least one --point X,Y,Z (or --sphere-points N,FACTOR)")
    import bempp_cl.api as bempp
    bempp.GLOBAL_PARAMETERS.quadrature.regular = args.quadrature
    t0 = time.time()
    verts, elements, vn = refined_surface(bank, args.refine, modes, args.velocity)
    solver = Solver(verts, elements)
    print(f"rad_ref: {len(modes)} mode(s), {len(elements)} triangles, {solver.p1.global_dof_count} P1 "
          f"and {solver.dp1.global_dof_count} DP1 unknowns", file=sys.stderr)
    results = []
    for mi, m in enumerate(modes):
        f = float(bank["frequencies_hz"][m])
        omega = 2 * math.pi * f
        k = omega / args.sound_speed
        t1 = time.time()
        p = solver.solve(k, omega * args.air_density, [vn[mi]], args.point)[0]
        print(f"rad_ref: mode {m} at {f:.1f} Hz (k = {k:.2f} 1/m) solved in {time.time() - t1:.1f} s",
              file=sys.stderr)
        results.append({"index": m, "frequency_hz": f, "refine": args.refine, "quadrature": args.quadrature,
                        "velocity": args.velocity,
                        "seconds": time.time() - t1, "pressure_pa": [[z.real, z.imag] for z in p]})
    report = {
        "generator": "tools/rad_ref.py (bempp-cl Galerkin P1/DP1 Burton-Miller)",
        "bank": args.bank,
        "refine": args.refine,
        "quadrature": args.quadrature,
        "triangles": int(len(elements)),
        "air_density_kg_m3": args.air_density,
        "sound_speed_m_s": args.sound_speed,
        "points": [list(p) for p in args.point],
        "modes": results,
        "seconds": time.time() - t0,
    }
    text = json.dumps(report, indent=1)
    if args.out:
        with open(args.out + ".tmp", "w") as fh:
            fh.write(text + "\n")
        import os
        os.replace(args.out + ".tmp", args.out)
    else:
        print(text)


# Tensors with one entry per mode (docs/bank-format.md); the rest describe the
# surface and the body and are copied as they are.
PER_MODE = ["frequencies_hz", "damping_ratios", "decay_rates", "residuals", "shapes"]


def bank_checksum(tensors, meta):
    """The bank checksum of docs/bank-format.md: SHA-256 over the tag, each
    tensor (sorted by name) and each metadata entry but `checksum`."""
    import hashlib
    import struct
    dt = {"float64": "F64", "float32": "F32", "int64": "I64"}
    h = hashlib.sha256()

    def s(b):
        h.update(struct.pack("<Q", len(b)))
        h.update(b)
    s(b"modal-bank-checksum-v1")
    for name in sorted(tensors, key=lambda n: n.encode()):
        a = tensors[name]  # (np.ascontiguousarray would make a scalar 1-D)
        s(name.encode())
        s(dt[a.dtype.name].encode())
        h.update(struct.pack("<Q", a.ndim))
        h.update(struct.pack(f"<{a.ndim}Q", *a.shape))
        s(a.astype(a.dtype.newbyteorder("<")).tobytes())
    for k in sorted((k for k in meta if k != "checksum"), key=str.encode):
        s(k.encode())
        s(meta[k].encode())
    return h.hexdigest()


def trim(path, modes, out):
    """Copy of the bank at `path` with only `modes` (sorted), checksum redone."""
    from safetensors import safe_open
    from safetensors.numpy import load_file, save_file
    tensors = load_file(path)
    with safe_open(path, "np") as f:
        meta = dict(f.metadata())
    if bank_checksum(tensors, meta) != meta.get("checksum"):
        sys.exit(f"{path}: checksum mismatch (not a modal bank, or damaged)")
    n = len(tensors["frequencies_hz"])
    keep = sorted(set(modes))
    if not keep or not all(0 <= m < n for m in keep):
        sys.exit(f"--trim needs --mode indices in 0..{n - 1}")
    extra = [k for k, v in tensors.items() if k not in PER_MODE and v.ndim and v.shape[0] == n
             and not k.startswith("surface_")]
    if extra:
        sys.exit(f"{path}: per-mode tensors this script does not know how to trim: {extra}")
    for k in PER_MODE:
        tensors[k] = tensors[k][keep]  # fancy indexing copies, C-contiguous
    info = json.loads(meta["solve_info"])
    if info.get("error_estimate_pct") is not None:
        info["error_estimate_pct"] = [info["error_estimate_pct"][m] for m in keep]
        meta["solve_info"] = json.dumps(info, separators=(",", ":"))
    meta["checksum"] = bank_checksum(tensors, meta)
    save_file(tensors, out, metadata=meta)
    print(f"rad_ref: wrote {out} with modes {keep} of {n}", file=sys.stderr)


def icosphere(subdiv):
    t = (1 + 5**0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    v = [np.array(p, float) / np.linalg.norm(p) for p in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
         (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
         (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdiv):
        mid = {}

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = v[a] + v[b]
                v.append(p / np.linalg.norm(p))
                mid[key] = len(v) - 1
            return mid[key]
        f = [g for (a, b, c) in f for g in ((a, m(a, b), m(c, a)), (b, m(b, c), m(a, b)),
                                             (c, m(c, a), m(b, c)), (m(a, b), m(b, c), m(c, a)))]
    return np.array(v), np.array(f)


def self_test():
    """Pulsating (l = 0) and oscillating rigid (l = 1) sphere of radius a:
    p = i rho0 c h_l(kr) / h_l'(ka) * v_l(direction), e^{-i omega t}."""
    from scipy.special import spherical_jn, spherical_yn
    a, rho, c = 0.1, 1.21, 343.0
    v, f = icosphere(3)
    verts = a * v
    solver = Solver(verts, f)
    pts = []
    for i in range(7):
        th, ph = 0.2 + 0.4 * i, 0.7 * i
        pts.append([0.25 * np.sin(th) * np.cos(ph), 0.25 * np.sin(th) * np.sin(ph), 0.25 * np.cos(th)])
    pts = np.array(pts)
    worst = 0.0
    for ka in [0.3, 1.0, math.pi, 4.0]:
        k = ka / a
        omega = k * c
        corner_n = verts[f] / a  # exact radial normal at each corner
        fields = [np.ones(f.shape), corner_n[:, :, 2]]
        p = solver.solve(k, omega * rho, fields, pts)
        r = np.linalg.norm(pts, axis=1)
        for l, got in enumerate(p):
            h = spherical_jn(l, k * r) + 1j * spherical_yn(l, k * r)
            hp = spherical_jn(l, ka, derivative=True) + 1j * spherical_yn(l, ka, derivative=True)
            ang = 1.0 if l == 0 else pts[:, 2] / r
            want = 1j * rho * c * h / hp * ang
            db = np.abs(20 * np.log10(np.abs(got) / np.abs(want)))
            ph_err = np.abs(np.angle(got / want))
            worst = max(worst, db.max())
            print(f"self-test l={l} ka={ka:.3f}: max {db.max():.4f} dB, max phase {ph_err.max():.4f} rad")
    ok = worst < 0.1
    print("self-test", "passed" if ok else "FAILED", f"(worst {worst:.4f} dB; limit 0.1 dB)")
    sys.exit(0 if ok else 1)


def compare(ref_path, modal_path, within_db):
    """Level errors of MODAL against REF. Counted: the modes within
    `within_db` of the loudest (mean square pressure over the points) and, of
    each, the points within `within_db` of its loudest point (nodal
    directions say nothing about a level)."""
    ref = json.load(open(ref_path))
    got = json.load(open(modal_path))
    by_index = {m["index"]: m for m in got["modes"]}
    rows = []
    for m in ref["modes"]:
        g = by_index.get(m["index"])
        if g is None:
            continue
        pr = np.array([complex(*z) for z in m["pressure_pa"]])
        pg = np.array([complex(*z) for z in g["pressure_pa"]])
        rows.append((m["index"], m["frequency_hz"], pr, 20 * np.log10(np.abs(pg) / np.abs(pr))))
    loudest = max(np.mean(np.abs(r[2]) ** 2) for r in rows)
    kept, every = [], []
    print(f"{'mode':>5} {'Hz':>9} {'level dB':>9} {'points':>6} {'median':>7} {'max':>7} {'max all':>8}")
    for i, f, pr, err in rows:
        rel = 10 * np.log10(np.mean(np.abs(pr) ** 2) / loudest)
        lit = 20 * np.log10(np.abs(pr) / np.abs(pr).max()) >= -within_db
        e = np.abs(err[lit])
        inside = rel >= -within_db
        if inside:
            kept.extend(e)
            every.extend(np.abs(err))
        print(f"{i:>5} {f:>9.1f} {rel:>9.1f} {lit.sum():>6} {np.median(e):>7.3f} {e.max():>7.3f} "
              f"{np.abs(err).max():>8.3f}" + ("" if inside else f"  (> {within_db:g} dB below the loudest)"))
    kept = np.array(kept)
    print(f"counted modes and points: median {np.median(kept):.3f} dB, max {kept.max():.3f} dB over "
          f"{len(kept)} mode-points (max {np.max(every):.3f} dB with the nodal points)")


def merge(out, inputs):
    """One reference file from runs at the same points; a mode solved in
    several runs keeps the last one's."""
    runs = [json.load(open(p)) for p in inputs]
    points = runs[0]["points"]
    if any(r["points"] != points for r in runs):
        sys.exit("--merge: the inputs were computed at different points")
    modes = {}
    for r in runs:
        for m in r["modes"]:
            m.setdefault("refine", r["refine"])
            m.setdefault("quadrature", r["quadrature"])
            modes[m["index"]] = m
    report = {k: runs[0][k] for k in ["generator", "bank", "air_density_kg_m3", "sound_speed_m_s", "points"]}
    report["merged_from"] = [{"refine": r["refine"], "quadrature": r["quadrature"], "triangles": r["triangles"],
                              "modes": [m["index"] for m in r["modes"]], "seconds": r["seconds"]} for r in runs]
    report["modes"] = [modes[i] for i in sorted(modes)]
    with open(out + ".tmp", "w") as fh:
        fh.write(json.dumps(report, indent=1) + "\n")
    import os
    os.replace(out + ".tmp", out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("bank", nargs="?")
    ap.add_argument("--point", action="append", default=[],
                    type=lambda s: [float(x) for x in s.split(",")])
    ap.add_argument("--mode", action="append", type=int, default=[])
    ap.add_argument("--sphere-points", type=lambda s: [float(x) for x in s.split(",")],
                    metavar="N,FACTOR", help="also N points at FACTOR bounding radii about the centre of mass")
    ap.add_argument("--refine", type=int, default=1)
    ap.add_argument("--quadrature", type=int, default=4,
                    help="order of bempp's regular (non-adjacent) quadrature (bempp default 4)")
    ap.add_argument("--velocity", choices=["nodes", "l2"], default="nodes",
                    help="DP1 normal velocity: sampled at each flat triangle's corners (nodes), or the L2 "
                         "projection of the quadratic interpolant onto each flat triangle (l2: keeps its flux)")
    ap.add_argument("--air-density", type=float, default=1.21)
    ap.add_argument("--sound-speed", type=float, default=343.0)
    ap.add_argument("-o", "--out")
    ap.add_argument("--self-test", action="store_true")
    ap.add_argument("--compare", nargs=2, metavar=("REF", "MODAL"))
    ap.add_argument("--within-db", type=float, default=40.0)
    ap.add_argument("--merge", nargs="+", metavar=("OUT", "IN"))
    ap.add_argument("--trim", metavar="OUT.bank", help="write BANK with only the --mode modes")
    args = ap.parse_args()
    if args.self_test:
        self_test()
    elif args.merge:
        merge(args.merge[0], args.merge[1:])
    elif args.compare:
        compare(*args.compare, args.within_db)
    elif args.bank and args.trim:
        trim(args.bank, args.mode, args.trim)
    elif args.bank:
        for p in args.point:
            if len(p) != 3:
                sys.exit("--point takes X,Y,Z")
        reference(args)
    else:
        ap.error("give a BANK, --self-test or --compare")


if __name__ == "__main__":
    main()
