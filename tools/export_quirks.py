#!/usr/bin/env python3
"""Surfaces written the way exporters write them, for the fourth sweep of unseen inputs
(BENCHMARKS.md, "A fourth sweep: how exporters write a surface"). Each is a 10 x 6 x 4 cm box
or a small variation on one, so a run says at once whether the quirk changed the answer:

  box.obj                        the clean box (12 triangles)
  box_twice.obj                  every triangle written twice (a duplicated export)
  box_double_sided.obj           every face once per side, sharing vertices (two-sided material)
  box_double_sided_split.obj     the same with the back side on vertices of its own
  box_inside_out.obj             every triangle facing in
  box_stray_vertices.obj         two unreferenced vertices 1000 km away
  box_t_junction.obj             a top-face corner half-way along an edge the front face keeps whole
  box_solid_header.stl           binary STL whose 80-byte header begins with "solid" (SolidWorks)
  bricks_stacked.obj             two 20 x 10 x 5 cm bricks touching face to face
  l_prism_ngon.obj               an L-shaped prism whose caps are single hexagons (Blender n-gons)
  l_sheet_ngon.obj               an L-shaped sheet as one hexagon (give it --sheet-thickness)
  disc_double_sided.obj          a 10 cm disc sheet written double-sided
  uv_sphere_quads.obj            a 5 cm UV sphere of quads (convex polygons)
  rock_specks.obj                a noisy 10 x 7 x 5 cm rock with 30 floating specks and 10 loose triangles
  scan_327k.obj                  a 327 680-triangle noisy ellipsoid (12 x 12 x 18 cm)
  box_and_plate.obj              the box and, 5 cm from it, a separate 10 x 6 cm plate 2 mm thick
  box_rotated.obj                the box turned 0.5 rad about z, then 0.3 rad about x

Quirks combined (the fifth sweep, BENCHMARKS.md "A fifth sweep: quirks combined"):

  box_double_sided_t_junction.obj   box_t_junction.obj written double-sided
  box_half_double_sided.obj         the box with every other triangle written again, reversed
  box_rotated_6digits.obj           box_rotated.obj written with 6 significant digits
  box_rotated_filler_6digits.obj    the same with its top face split a third of the way along an
                                    edge and the gap filled by a zero-area sliver, as some
                                    exporters fill a split edge (6 digits: the sliver's corner is
                                    off the edge by the rounding)
  box_rotated_soup_ulps.obj         box_rotated.obj as an unwelded soup whose copies of a corner
                                    differ by up to 2e-12 m (per-face transforms), 17 digits

A dense scan (BENCHMARKS.md, "The noise of a dense scan is not a sharp feature"), only with
--scan-1m, since it is a 57 MB file:

  scan_1m.obj                    scan_327k.obj's ellipsoid at 1 310 720 triangles, the same noise

Needs numpy. Usage: python tools/export_quirks.py OUT_DIR [--scan-1m]
"""
import os
import struct
import sys

import numpy as np

out = sys.argv[1]
os.makedirs(out, exist_ok=True)
rng = np.random.default_rng(7)

BOX_V = np.array([[x, y, z] for x in (0, 0.1) for y in (0, 0.06) for z in (0, 0.04)], float)
BOX_F = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
         (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]


def write(name, V, F, header=""):
    with open(f"{out}/{name}", "w") as f:
        f.write(header)
        for v in V:
            f.write("v %.9g %.9g %.9g\n" % tuple(v))
        for t in F:
            f.write("f " + " ".join(str(k + 1) for k in t) + "\n")


def reversed_faces(F):
    return [tuple(reversed(t)) for t in F]


def box(lo, hi):
    V = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])], float)
    return V, BOX_F


def merge(parts):
    V, F, o = [], [], 0
    for v, f in parts:
        V.extend(v)
        F.extend([tuple(k + o for k in t) for t in f])
        o += len(v)
    return np.array(V), F


def icosphere(n):
    t = (1 + 5 ** .5) / 2
    V = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    F = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    V = [np.array(v, float) / np.linalg.norm(v) for v in V]
    for _ in range(n):
        cache, NF = {}, []

        def mid(a, b):
            k = (min(a, b), max(a, b))
            if k not in cache:
                m = V[a] + V[b]
                V.append(m / np.linalg.norm(m))
                cache[k] = len(V) - 1
            return cache[k]
        for a, b, c in F:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            NF += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        F = NF
    return np.array(V), F


write("box.obj", BOX_V, BOX_F)
V2, F2 = merge([(BOX_V, BOX_F), (BOX_V.copy(), BOX_F)])
write("box_twice.obj", V2, F2)
write("box_double_sided.obj", BOX_V, BOX_F + reversed_faces(BOX_F))
V2, F2 = merge([(BOX_V, BOX_F), (BOX_V.copy(), reversed_faces(BOX_F))])
write("box_double_sided_split.obj", V2, F2)
write("box_inside_out.obj", BOX_V, reversed_faces(BOX_F))
with open(f"{out}/box_stray_vertices.obj", "w") as f:
    f.write("v 1e6 1e6 1e6\nv -5e5 0 0\n")
    for v in BOX_V:
        f.write("v %.9g %.9g %.9g\n" % tuple(v))
    for t in BOX_F:
        f.write("f %d %d %d\n" % tuple(k + 3 for k in t))
# The top face (z = 0.04: corners 1, 3, 5, 7) split at (0.05, 0, 0.04) on edge 1-5.
t_v = np.vstack([BOX_V, [[0.05, 0.0, 0.04]]])
t_f = [t for t in BOX_F if t not in [(1, 5, 7), (1, 7, 3)]] + [(1, 8, 3), (8, 7, 3), (8, 5, 7)]
write("box_t_junction.obj", t_v, t_f)
with open(f"{out}/box_solid_header.stl", "wb") as f:
    f.write(b"solid part1 exported by SolidWorks".ljust(80, b" "))
    f.write(struct.pack("<I", len(BOX_F)))
    for t in BOX_F:
        f.write(struct.pack("<3f", 0, 0, 0))
        for i in t:
            f.write(struct.pack("<3f", *BOX_V[i]))
        f.write(struct.pack("<H", 0))
V2, F2 = merge([box((0, 0, 0), (0.2, 0.1, 0.05)), box((0, 0, 0.05), (0.2, 0.1, 0.1))])
write("bricks_stacked.obj", V2, F2)
# L outline; caps listed from corner 1, which does not see the whole L (a fan from it folds).
L = [(0, 0), (0.1, 0), (0.1, 0.03), (0.03, 0.03), (0.03, 0.08), (0, 0.08)]
V = [(x, y, 0) for x, y in L] + [(x, y, 0.02) for x, y in L]
order = [1, 2, 3, 4, 5, 0]
F = [tuple(reversed(order)), tuple(k + 6 for k in order)] + [(i, (i + 1) % 6, (i + 1) % 6 + 6, i + 6) for i in range(6)]
write("l_prism_ngon.obj", V, F)
L2 = [(0, 0), (0.3, 0), (0.3, 0.1), (0.1, 0.1), (0.1, 0.25), (0, 0.25)]
write("l_sheet_ngon.obj", [(x, y, 0) for x, y in L2], [(1, 2, 3, 4, 5, 0)])
n, rings = 48, 8
V = [(0, 0, 0)] + [(0.05 * r / rings * np.cos(2 * np.pi * j / n), 0.05 * r / rings * np.sin(2 * np.pi * j / n), 0)
                   for r in range(1, rings + 1) for j in range(n)]


def ring(r, j):
    return 0 if r == 0 else 1 + (r - 1) * n + (j % n)


F = [(0, ring(1, j), ring(1, j + 1)) for j in range(n)]
for r in range(1, rings):
    for j in range(n):
        a, b, c, d = ring(r, j), ring(r, j + 1), ring(r + 1, j), ring(r + 1, j + 1)
        F += [(a, c, d), (a, d, b)]
write("disc_double_sided.obj", V, F + reversed_faces(F))
n, m, R = 48, 24, 0.05
V = [(0, 0, R)] + [(R * np.sin(np.pi * i / m) * np.cos(2 * np.pi * j / n),
                    R * np.sin(np.pi * i / m) * np.sin(2 * np.pi * j / n), R * np.cos(np.pi * i / m))
                   for i in range(1, m) for j in range(n)] + [(0, 0, -R)]


def uv(i, j):
    return 1 + (i - 1) * n + (j % n)


F = [(0, uv(1, j), uv(1, j + 1)) for j in range(n)]
F += [(uv(i, j), uv(i + 1, j), uv(i + 1, j + 1), uv(i, j + 1)) for i in range(1, m - 1) for j in range(n)]
F += [(uv(m - 1, j), len(V) - 1, uv(m - 1, j + 1)) for j in range(n)]
write("uv_sphere_quads.obj", V, F)
V, F = icosphere(4)
rock = (V * (1 + 0.03 * rng.standard_normal(len(V)))[:, None]) * np.array([0.05, 0.035, 0.025])
parts = [(rock, F)]
for _ in range(30):
    c, s = rng.uniform(-0.08, 0.08, 3), rng.uniform(0.0003, 0.001)
    parts.append((np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float) * s + c,
                  [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)]))
for _ in range(10):
    parts.append((rng.uniform(-0.08, 0.08, 3) + rng.uniform(-0.002, 0.002, (3, 3)), [(0, 1, 2)]))
V2, F2 = merge(parts)
write("rock_specks.obj", V2, F2)
V, F = icosphere(7)
V = V * (1 + 0.002 * rng.standard_normal(len(V)))[:, None] * np.array([0.06, 0.06, 0.09])
write("scan_327k.obj", V, F)
V2, F2 = merge([(BOX_V, BOX_F), box((0.15, 0, 0), (0.25, 0.06, 0.002))])
write("box_and_plate.obj", V2, F2)
a, b = 0.5, 0.3
turn = np.array([[1, 0, 0], [0, np.cos(b), -np.sin(b)], [0, np.sin(b), np.cos(b)]]) @ \
    np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
write("box_rotated.obj", BOX_V @ turn.T, BOX_F)

# --- Quirks combined (fifth sweep). Appended: the files above stay byte for byte.
write("box_double_sided_t_junction.obj", t_v, t_f + reversed_faces(t_f))
write("box_half_double_sided.obj", BOX_V, BOX_F + reversed_faces(BOX_F[::2]))


def write_digits(name, V, F, digits):
    with open(f"{out}/{name}", "w") as f:
        for v in V:
            f.write(("v %.{0}g %.{0}g %.{0}g\n".format(digits)) % tuple(v))
        for t in F:
            f.write("f " + " ".join(str(k + 1) for k in t) + "\n")


R = BOX_V @ turn.T
write_digits("box_rotated_6digits.obj", R, BOX_F, 6)
# Top face z = 0.04 (corners 1, 3, 5, 7) split at a third of edge 1-5; the front face (0, 5, 1)
# keeps 5-1 whole, and the sliver (1, 5, m) fills the gap between them.
m = R[1] + (R[5] - R[1]) / 3
RF = np.vstack([R, [m]])
FF = [t for t in BOX_F if t != (1, 5, 7)] + [(1, 8, 7), (8, 5, 7), (1, 5, 8)]
write_digits("box_rotated_filler_6digits.obj", RF, FF, 6)
soup_rng = np.random.default_rng(11)
SV = np.array([R[k] + soup_rng.uniform(-2e-12, 2e-12, 3) for t in BOX_F for k in t])
write_digits("box_rotated_soup_ulps.obj", SV, [(3 * i, 3 * i + 1, 3 * i + 2) for i in range(len(BOX_F))], 17)
if "--scan-1m" in sys.argv[2:]:
    V, F = icosphere(8)
    V = V * (1 + 0.002 * np.random.default_rng(3).standard_normal(len(V)))[:, None] * np.array([0.06, 0.06, 0.09])
    write("scan_1m.obj", V, F)
