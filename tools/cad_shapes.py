#!/usr/bin/env python3
"""Thin-walled solids as CAD exports write them, a few large triangles each (BENCHMARKS.md,
"Plates exported as a few triangles, and banks of more than 64 modes"), into OUT_DIR:
- plate.obj: a 20 x 15 cm plate 1 mm thick, the 12 triangles of its box;
- bracket_L.obj: an L bracket, legs 60 and 40 mm, 2 mm thick, 50 mm wide;
- channel_U.obj: a U channel 80 x 30 mm, 2 mm wall, 300 mm long;
- square_tube.obj: a 40 x 40 mm square tube, 2 mm wall, 500 mm long;
- channel_U_voxels.msh, bracket_L_voxels.msh: the channel and the bracket as voxel tet meshes
  (Gmsh 2.2, 4-node tets, 6 per voxel), 1 mm across the walls and 5 mm (channel) or 2.5 mm
  (bracket) along the profile: references with two elements across every wall.

No dependencies. Usage: python tools/cad_shapes.py OUT_DIR
"""
import os, sys

out = sys.argv[1]
os.makedirs(out, exist_ok=True)


def write(name, vertices, faces, header=True):
    with open(os.path.join(out, name), "w") as f:
        if header:
            f.write("# coarse CAD-like export, metres\n")
        for v in vertices:
            f.write("v %r %r %r\n" % tuple(v))
        for t in faces:
            f.write("f %d %d %d\n" % tuple(i + 1 for i in t))


def plate(lx, ly, lz):
    vertices = [(x, y, z) for x in (0, lx) for y in (0, ly) for z in (0, lz)]
    at = {p: i for i, p in enumerate(vertices)}
    quads = [((0, 0, 0), (0, ly, 0), (lx, ly, 0), (lx, 0, 0)), ((0, 0, lz), (lx, 0, lz), (lx, ly, lz), (0, ly, lz)),
             ((0, 0, 0), (lx, 0, 0), (lx, 0, lz), (0, 0, lz)), ((0, ly, 0), (0, ly, lz), (lx, ly, lz), (lx, ly, 0)),
             ((0, 0, 0), (0, 0, lz), (0, ly, lz), (0, ly, 0)), ((lx, 0, 0), (lx, ly, 0), (lx, ly, lz), (lx, 0, lz))]
    faces = []
    for q in quads:
        a, b, c, d = (at[p] for p in q)
        faces += [(a, b, c), (a, c, d)]
    return vertices, faces


def extrude(outline, triangles, length):
    """The prism of a counter-clockwise (x, z) outline along y; `triangles` cover the outline."""
    n = len(outline)
    vertices = [(x, y, z) for y in (0.0, length) for (x, z) in outline]
    faces = []
    for a, b, c in triangles:
        faces += [(a, b, c), (n + a, n + c, n + b)]
    for i in range(n):
        j = (i + 1) % n
        faces += [(i, n + i, n + j), (i, n + j, j)]
    return vertices, faces


def square_tube(w, t, length):
    ring = [(0, 0), (w, 0), (w, w), (0, w), (t, t), (w - t, t), (w - t, w - t), (t, w - t)]
    vertices = [(x, y, z) for y in (0.0, length) for (x, z) in ring]
    faces = []

    def quad(a, b, c, d, flip=False):
        faces.extend([(a, c, b), (a, d, c)] if flip else [(a, b, c), (a, c, d)])

    for base, flip in ((0, False), (8, True)):
        for k in range(4):
            quad(base + k, base + (k + 1) % 4, base + 4 + (k + 1) % 4, base + 4 + k, flip)
    for k in range(4):
        a, b = k, (k + 1) % 4
        quad(a, 8 + a, 8 + b, b)
        quad(4 + a, 4 + b, 12 + b, 12 + a)
    return vertices, faces


t = 0.002
write("plate.obj", *plate(0.2, 0.15, 0.001), header=False)
write("bracket_L.obj", *extrude([(0, 0), (0.06, 0), (0.06, t), (t, t), (t, 0.04), (0, 0.04)],
                                [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 5)], 0.05))
write("channel_U.obj", *extrude([(0, 0), (0.08, 0), (0.08, 0.03), (0.08 - t, 0.03), (0.08 - t, t), (t, t), (t, 0.03), (0, 0.03)],
                                [(0, 1, 4), (0, 4, 5), (1, 2, 3), (1, 3, 4), (0, 5, 6), (0, 6, 7)], 0.3))
write("square_tube.obj", *square_tube(0.04, t, 0.5))


def voxels(name, inside, cells, spacing):
    """The voxels of a box grid (`cells` per axis, `spacing` [m]) whose centre's (x, z) is
    `inside`, six tets each (the Kuhn split along the voxel's main diagonal)."""
    (nx, ny, nz), (dx, dy, dz) = cells, spacing
    index, nodes, tets = {}, [], []

    def node(i, j, k):
        if (i, j, k) not in index:
            index[(i, j, k)] = len(nodes) + 1
            nodes.append((i * dx, j * dy, k * dz))
        return index[(i, j, k)]

    paths = [(1, 2, 4), (1, 4, 2), (2, 1, 4), (2, 4, 1), (4, 1, 2), (4, 2, 1)]
    for i in range(nx):
        for k in range(nz):
            if not inside((i + 0.5) * dx, (k + 0.5) * dz):
                continue
            for j in range(ny):
                corner = lambda b: node(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1))
                for path in paths:
                    bits, seq = 0, [0]
                    for step in path:
                        bits |= step
                        seq.append(bits)
                    tets.append([corner(b) for b in seq])
    with open(os.path.join(out, name), "w") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%d\n" % len(nodes))
        for n, (x, y, z) in enumerate(nodes):
            f.write("%d %r %r %r\n" % (n + 1, x, y, z))
        f.write("$EndNodes\n$Elements\n%d\n" % len(tets))
        for e, tet in enumerate(tets):
            f.write("%d 4 2 1 1 %d %d %d %d\n" % (e + 1, *tet))
        f.write("$EndElements\n")


voxels("channel_U_voxels.msh", lambda x, z: z < t or x < t or x > 0.08 - t, (80, 60, 30), (0.001, 0.005, 0.001))
voxels("bracket_L_voxels.msh", lambda x, z: x < t or z < t, (60, 20, 40), (0.001, 0.0025, 0.001))
