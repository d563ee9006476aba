#!/usr/bin/env python3
"""Reference frequencies of the steel cantilever used by `modal bench accuracy`.

Bar 0.3 x 0.02 x 0.01 m (E = 200 GPa, nu = 0.3, rho = 7850 kg/m^3), every node of the
face x = 0 clamped. Independent of modal: scikit-fem P2 tets on structured tensor meshes
(n x n/15 x n/30 boxes, each split into tets by scikit-fem), scipy ARPACK shift-invert,
then Richardson extrapolation of the two finest levels with the P2 eigenvalue rate h^4.
With --free the clamp is dropped (check against the 3D-converged free-free table).

usage: /work/.venv-ref/bin/python cantilever_reference.py [--free] [--levels 90 120] [--modes 24]
Prints JSON: per level the DOFs and frequencies (Hz), and the extrapolated frequencies.
"""
import argparse, json, time
import numpy as np, scipy.sparse.linalg as sla
from skfem import MeshTet, ElementVector, ElementTetP2, Basis, asm, BilinearForm, condense
from skfem.models.elasticity import linear_elasticity, lame_parameters
from skfem.helpers import dot

ap = argparse.ArgumentParser()
ap.add_argument("--free", action="store_true")
ap.add_argument("--levels", type=int, nargs="+", default=[90, 120])
ap.add_argument("--modes", type=int, default=24)
a = ap.parse_args()
E, NU, RHO, L, B, H = 200e9, 0.3, 7850.0, 0.3, 0.02, 0.01


@BilinearForm
def mass(u, v, w):
    return RHO * dot(u, v)


def level(n):
    mesh = MeshTet.init_tensor(np.linspace(0, L, n + 1), np.linspace(0, B, n // 15 + 1),
                               np.linspace(0, H, n // 30 + 1))
    basis = Basis(mesh, ElementVector(ElementTetP2()), intorder=4)
    K = asm(linear_elasticity(*lame_parameters(E, NU)), basis)
    M = asm(mass, basis)
    extra = 6 if a.free else 0
    sigma = -(2 * np.pi * 10.0) ** 2
    t0 = time.time()
    if a.free:
        Kc, Mc = K, M
    else:
        D = basis.get_dofs(lambda x: x[0] < 1e-12).all()
        Kc, Mc = condense(K, M, D=D, expand=False)[:2]
    vals = sla.eigsh(Kc.tocsc(), k=a.modes + extra, M=Mc.tocsc(), sigma=sigma, which="LM",
                     return_eigenvectors=False)
    f = np.sort(np.sqrt(np.abs(vals)) / (2 * np.pi))[extra:]
    return {"n": n, "dofs": int(Kc.shape[0]), "eigsh_s": round(time.time() - t0, 2),
            "frequencies_hz": [round(float(x), 4) for x in f]}


levels = [level(n) for n in a.levels]
f1 = np.array(levels[-2]["frequencies_hz"]); f2 = np.array(levels[-1]["frequencies_hz"])
r = (a.levels[-1] / a.levels[-2]) ** 4
extrap = f2 + (f2 - f1) / (r - 1)
print(json.dumps({"free": a.free, "levels": levels,
                  "extrapolated_hz": [round(float(x), 3) for x in extrap]}, indent=1))
