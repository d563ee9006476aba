#!/usr/bin/env python3
"""Inputs of the third unseen-input sweep (BENCHMARKS.md, "A third sweep: unseen scenes,
sheets, plates and dataset files"), written into OUT_DIR:
- sheet.obj: an open flat disc, r = 15 cm, 12 rings of 64 segments (one surface, no thickness);
- cymbal_sheet.obj: the same disc domed 2 cm (z = 0.02 (1 - r²/R²)), the 30 cm cymbal;
- closed.obj: the flat disc built closed, 2 mm thick (two faces and a rim);
- table_openlegs.obj: a closed table top with four open (uncapped) cylinder legs through it;
- sign_zero_thickness.obj: a closed 2 cm post with a zero-thickness plate through it;
- a.toml, b.toml: scenes A and B (they use tools/unseen_shapes.py's fork, mm_box, far_box,
  hollow_sphere and wire OBJ files and meshes/mug.obj, copied into OUT_DIR beside them).

No dependencies. Usage: python tools/sheet_shapes.py OUT_DIR
"""
import math, os, sys

out = sys.argv[1]
os.makedirs(out, exist_ok=True)


def write(name, parts, fmt="%.9g"):
    with open(os.path.join(out, name), "w") as f:
        base = 1
        for k, (vs, fs) in enumerate(parts):
            if len(parts) > 1:
                f.write(f"o part{k}\n")
            for v in vs:
                f.write(("v " + " ".join([fmt] * 3) + "\n") % tuple(v))
            for t in fs:
                f.write("f %d %d %d\n" % tuple(i + base for i in t))
            base += len(vs)


R, RINGS, SEGMENTS = 0.15, 12, 64


def disc(z, flip, vs, fs):
    start = len(vs)
    vs.append((0.0, 0.0, z))
    for i in range(1, RINGS + 1):
        for j in range(SEGMENTS):
            a, r = 2 * math.pi * j / SEGMENTS, R * i / RINGS
            vs.append((r * math.cos(a), r * math.sin(a), z))

    def at(i, j):
        return start if i == 0 else start + 1 + (i - 1) * SEGMENTS + j % SEGMENTS

    tris = [(at(0, 0), at(1, j), at(1, j + 1)) for j in range(SEGMENTS)]
    for i in range(1, RINGS):
        for j in range(SEGMENTS):
            a, b, c, d = at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)
            tris += [(a, b, c), (a, c, d)]
    fs.extend(t[::-1] if flip else t for t in tris)
    return at


vs, fs = [], []
disc(0.0, False, vs, fs)
write("sheet.obj", [(vs, fs)])
write("cymbal_sheet.obj", [([(x, y, 0.02 * (1 - (x * x + y * y) / R**2)) for x, y, _ in vs], fs)])
vs, fs = [], []
top, bottom = disc(0.001, False, vs, fs), disc(-0.001, True, vs, fs)
for j in range(SEGMENTS):
    a, b, c, d = top(RINGS, j), top(RINGS, j + 1), bottom(RINGS, j + 1), bottom(RINGS, j)
    fs += [(a, d, c), (a, c, b)]
write("closed.obj", [(vs, fs)])


def box(x0, y0, z0, x1, y1, z1):
    v = [(x, y, z) for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]
    f = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
         (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return v, f


def open_cylinder(cx, cz, r, y0, y1, n=24):
    v, f = [], []
    for i in range(n):
        a = 2 * math.pi * i / n
        v += [(cx + r * math.cos(a), y0, cz + r * math.sin(a)), (cx + r * math.cos(a), y1, cz + r * math.sin(a))]
    for i in range(n):
        a, b, c, d = 2 * i, 2 * i + 1, 2 * ((i + 1) % n), 2 * ((i + 1) % n) + 1
        f += [(a, c, d), (a, d, b)]
    return v, f


legs = [open_cylinder(x, z, 0.012, 0.0, 0.31) for x in (-0.17, 0.17) for z in (-0.12, 0.12)]
write("table_openlegs.obj", [box(-0.2, 0.3, -0.15, 0.2, 0.32, 0.15)] + legs, "%g")
plate = ([(-0.15, 0.35, 0.0), (0.15, 0.35, 0.0), (0.15, 0.5, 0.0), (-0.15, 0.5, 0.0)], [(0, 1, 2), (0, 2, 3)])
write("sign_zero_thickness.obj", [box(-0.01, 0, -0.01, 0.01, 0.5, 0.01), plate], "%g")

SCENE_A = """duration = 2.0
[listener]
position = [0.0, 0.3, 0.6]
[ground]
material = "wood"
[[objects]]
name = "fork"
mesh = "fork.obj"
material = "steel"
collider = "decomposition"
position = [0.0, 0.25, 0.0]
rotation = { euler = [80.0, 10.0, 0.0] }
angular_velocity = [0.0, 3.0, 1.0]
[[objects]]
name = "mmbox"
mesh = "mm_box.obj"
scale = 0.001
material = "ceramic"
position = [0.2, 0.15, 0.0]
rotation = { euler = [30.0, 20.0, 10.0] }
[[objects]]
name = "farbox"
mesh = "far_box.obj"
material = "aluminium"
position = [-0.2, 0.2, 0.0]
"""
SCENE_B = """duration = 2.5
sample_rate = 44100
[listener]
position = [0.0, 0.3, 0.5]
channels = "mono"
[ground]
material = "steel"
size = [0.6, 0.4]
thickness = 0.01
[[objects]]
name = "mug"
mesh = "mug.obj"
material = "ceramic"
position = [0.0, 0.12, 0.0]
rotation = { euler = [-90.0, 0.0, 30.0] }
[[objects]]
name = "ball"
mesh = "hollow_sphere.obj"
material = "steel"
position = [0.15, 0.3, 0.0]
linear_velocity = [-0.5, 0.0, 0.0]
[[objects]]
name = "wire"
mesh = "wire.obj"
material = "brass"
position = [-0.2, 0.05, 0.0]
rotation = { euler = [0.0, 90.0, 0.0] }
"""
for name, text in (("a.toml", SCENE_A), ("b.toml", SCENE_B)):
    with open(os.path.join(out, name), "w") as f:
        f.write(text)
