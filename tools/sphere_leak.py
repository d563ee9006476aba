#!/usr/bin/env python3
"""How much a sphere bank's torsional modes radiate, without a boundary
solve: the normal velocity v_n = phi . n over the bank's curved (quadratic)
surface is projected on spherical harmonics, and each degree radiates as on
an exact sphere of radius a (e^{-i omega t}):

    P = rho0 c sum_lm |c_lm|^2 / (2 k^2 |h_l'(ka)|^2),   v_n = sum_lm c_lm Y_l^m.

Three normals are compared: the quadratic map's own normal at each
quadrature point, the exact radial normal, and the node-averaged quadratic
normal (modal-radiation's normal before 2026-11-26; it now fits the node
normals to the local surface, crates/modal-radiation/src/normals.rs, whose
leak the Rust test `exactly_tangential_fields_…` measures through the
solver) interpolated quadratically.
With --analytic, the bank's modes are replaced by exactly tangential fields
x cross grad q (torsional) and grad q (spheroidal), q = xy, xyz, unit RMS
at the nodes, at 1600 and 2400 Hz (the fields of the test
`exactly_tangential_fields_on_the_fem_sphere_radiate_far_below_spheroidal_ones`).

Packages: those of tools/rad_ref.py (numpy, scipy, safetensors).
Usage: sphere_leak.py BANK [--radius 0.05] [--analytic] [--panels]
Prints, per mode, its power in dB relative to the quietest spheroidal mode
(modes with normal-velocity power within 30 dB of the loudest count as
spheroidal).
"""

import argparse
import os
import sys

import numpy as np
from scipy.special import spherical_jn, spherical_yn, sph_harm_y

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rad_ref  # noqa: E402

# Degree-4 six-point triangle rule (Strang-Fix), weights summing to 1/2.
GP = np.array([[0.445948490915965, 0.445948490915965], [0.445948490915965, 0.10810301816807],
               [0.10810301816807, 0.445948490915965], [0.091576213509771, 0.091576213509771],
               [0.091576213509771, 0.816847572980459], [0.816847572980459, 0.091576213509771]])
GW = np.array([0.223381589678011] * 3 + [0.109951743655322] * 3) / 2


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bank")
    ap.add_argument("--radius", type=float, default=0.05)
    ap.add_argument("--analytic", action="store_true")
    ap.add_argument("--degree", type=int, default=8)
    ap.add_argument("--panels", action="store_true",
                    help="also the velocity as modal-radiation samples it: constant per flat panel of the "
                         "four-panel split, the mean of its corners' phi . n (node-averaged or exact radial "
                         "node normals), projected with flat-panel solid angles")
    args = ap.parse_args()
    a, c, rho = args.radius, 343.0, 1.21
    b = rad_ref.load_bank(args.bank)
    pos, nodes = b["positions"], np.concatenate([b["triangles"], b["edges"]], 1)
    x = pos[nodes]
    n, dxi, deta = rad_ref.quadratic_shape(GP[:, 0], GP[:, 1])
    X = np.einsum("qp,tqc->tpc", n, x)
    cr = np.cross(np.einsum("qp,tqc->tpc", dxi, x), np.einsum("qp,tqc->tpc", deta, x))
    jac = np.linalg.norm(cr, axis=2)
    n_quad = (cr / jac[..., None]).reshape(-1, 3)
    w = (jac * GW[None, :]).reshape(-1)
    Xf = X.reshape(-1, 3)
    r = np.linalg.norm(Xf, axis=1)
    n_rad = Xf / r[:, None]
    # Node-averaged quadratic normals (sum of d x/d xi cross d x/d eta at the node).
    at = np.array([(0, 0), (1, 0), (0, 1), (.5, 0), (.5, .5), (0, .5)], float)
    _, dxn, den = rad_ref.quadratic_shape(at[:, 0], at[:, 1])
    cn = np.cross(np.einsum("qp,tqc->tpc", dxn, x), np.einsum("qp,tqc->tpc", den, x))
    n_node = np.zeros_like(pos)
    np.add.at(n_node, nodes.reshape(-1), cn.reshape(-1, 3))
    n_node /= np.linalg.norm(n_node, axis=1, keepdims=True)
    th, ph = np.arccos(np.clip(n_rad[:, 2], -1, 1)), np.arctan2(n_rad[:, 1], n_rad[:, 0])
    Y = [(l, sph_harm_y(l, m, th, ph)) for l in range(args.degree + 1) for m in range(-l, l + 1)]
    d_omega = w / r**2

    def multipole_power(harmonics, weights):
        """Radiated power [W] of a normal-velocity field sampled where the spherical
        harmonics `harmonics` are, with solid-angle weights `weights`."""
        def power(vn, f):
            k = 2 * np.pi * f / c
            total = 0.0
            for l, y in harmonics:
                clm = (vn * np.conj(y) * weights).sum()
                hp = spherical_jn(l, k * a, derivative=True) + 1j * spherical_yn(l, k * a, derivative=True)
                total += rho * c * abs(clm) ** 2 / (2 * k * k * abs(hp) ** 2)
            return total
        return power

    power = multipole_power(Y, d_omega)

    if args.analytic:
        P = pos
        g2 = np.stack([P[:, 1], P[:, 0], 0 * P[:, 0]], 1)
        g3 = np.stack([P[:, 1] * P[:, 2], P[:, 0] * P[:, 2], P[:, 0] * P[:, 1]], 1)
        fields = [("T2", np.cross(P, g2)), ("T3", np.cross(P, g3)), ("S2", g2), ("S3", g3)]
        fields = [(nm, (F / np.sqrt((F**2).sum(1).mean())).astype(np.float32).astype(float)) for nm, F in fields]
        modes = [(f"{nm}", f, F) for f in (1600.0, 2400.0) for nm, F in fields]
    else:
        modes = [(str(i), f, b["shapes"][i]) for i, f in enumerate(b["frequencies_hz"])]
    if args.panels:
        sub = [(0, 3, 5), (3, 1, 4), (5, 4, 2), (3, 4, 5)]
        panels = np.concatenate([nodes[:, list(t)] for t in sub])
        corners = pos[panels]
        pc = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        area = np.linalg.norm(pc, axis=1) / 2
        centre = corners.mean(1)
        rc = np.linalg.norm(centre, axis=1)
        dirs = centre / rc[:, None]
        d_omega_p = area * ((pc / (2 * area[:, None])) * dirs).sum(1) / rc**2
        thp, php = np.arccos(np.clip(dirs[:, 2], -1, 1)), np.arctan2(dirs[:, 1], dirs[:, 0])
        Yp = [(l, sph_harm_y(l, m, thp, php)) for l in range(args.degree + 1) for m in range(-l, l + 1)]
        radial = pos / np.linalg.norm(pos, axis=1, keepdims=True)
        corner = np.zeros(len(pos), bool)
        corner[b["triangles"].reshape(-1)] = True
        err = np.degrees(np.arccos(np.clip((n_node * radial).sum(1), -1, 1)))
        print(f"node-averaged normal vs radial: mean {err[corner].mean():.3f} deg at corner nodes, "
              f"{err[~corner].mean():.3f} deg at mid-edge nodes")
        panel_power = multipole_power(Yp, d_omega_p)
        rows_p = []
        for name, f, shape in modes:
            rows_p.append((name, f, [panel_power(((shape * nrm).sum(1))[panels].mean(1), f)
                                     for nrm in (n_node, radial)]))
        for f0 in sorted({f for _, f, _ in rows_p}) if args.analytic else [None]:
            group = [r_ for r_ in rows_p if f0 is None or r_[1] == f0]
            loud = max(r_[2][1] for r_ in group)
            quiet = [min(r_[2][j] for r_ in group if r_[2][1] > 1e-3 * loud) for j in range(2)]
            print(f"{'mode':>5} {'Hz':>8}  panels, dB re the quietest spheroidal: node-averaged, radial node normal")
            for name, f, p in group:
                print(f"{name:>5} {f:8.1f}  " + "  ".join(f"{10 * np.log10(max(p[j], 1e-300) / quiet[j]):7.1f}"
                                                      for j in range(2)))
    rows = []
    for name, f, shape in modes:
        u = np.einsum("qp,tqc->tpc", n, shape[nodes]).reshape(-1, 3)
        v_node = np.einsum("qp,tq->tp", n, (shape * n_node).sum(1)[nodes]).reshape(-1)
        rows.append((name, f, [power((u * n_quad).sum(1), f), power((u * n_rad).sum(1), f), power(v_node, f)]))
    for f0 in sorted({f for _, f, _ in rows}) if args.analytic else [None]:
        group = [r_ for r_ in rows if f0 is None or r_[1] == f0]
        loud = max(r_[2][1] for r_ in group)
        spheroidal = [r_ for r_ in group if r_[2][1] > 1e-3 * loud]
        quiet = [min(r_[2][j] for r_ in spheroidal) for j in range(3)]
        print(f"{'mode':>5} {'Hz':>8}  dB re the quietest spheroidal: quadratic-map, radial, node-averaged normal")
        for name, f, p in group:
            print(f"{name:>5} {f:8.1f}  " + "  ".join(f"{10 * np.log10(p[j] / quiet[j]):7.1f}" for j in range(3)))


if __name__ == "__main__":
    main()
