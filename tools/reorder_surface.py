#!/usr/bin/env python3
"""The same OBJ surface written another way, for the order, crack and unit checks in
BENCHMARKS.md ("One surface, one mesh: a canonical order"; "Files in other units").
Standard library only.

  reorder_surface.py shuffle IN.obj OUT.obj SEED
      vertices and faces in a random order, each triangle starting at a random corner
      (polygons of more corners keep their first corner: their fan depends on it)
  reorder_surface.py crack IN.obj OUT.obj REL [--half-twice] [--seed S]
      an unwelded soup of triangles, each copy of a corner moved by up to REL x the
      bounding-box diagonal in each coordinate (per-face transforms, single precision);
      --half-twice also writes every other face again, reversed
  reorder_surface.py scale IN.obj OUT.obj FACTOR
      every coordinate times FACTOR: a file in metres written as millimetres is FACTOR 1000,
      centimetres 100, inches 39.37
"""
import argparse
import random


def read_obj(path):
    vertices, faces = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                vertices.append([float(x) for x in p[1:4]])
            elif p[0] == "f":
                faces.append([int(x.split("/")[0]) - 1 for x in p[1:]])
    return vertices, faces


def write_obj(path, vertices, faces):
    with open(path, "w") as f:
        for v in vertices:
            f.write("v %.17g %.17g %.17g\n" % tuple(v))
        for face in faces:
            f.write("f " + " ".join(str(i + 1) for i in face) + "\n")


def shuffle(vertices, faces, rng):
    order = list(range(len(vertices)))
    rng.shuffle(order)
    new_index = {old: new for new, old in enumerate(order)}
    faces = [[new_index[i] for i in face] for face in faces]
    rng.shuffle(faces)
    turned = []
    for face in faces:
        k = rng.randrange(3) if len(face) == 3 else 0
        turned.append(face[k:] + face[:k])
    return [vertices[i] for i in order], turned


def crack(vertices, faces, rel, half_twice, rng):
    lo = [min(v[c] for v in vertices) for c in range(3)]
    hi = [max(v[c] for v in vertices) for c in range(3)]
    shift = rel * sum((hi[c] - lo[c]) ** 2 for c in range(3)) ** 0.5
    triangles = [[f[0], f[k], f[k + 1]] for f in faces for k in range(1, len(f) - 1)]
    if half_twice:
        triangles += [[a, c, b] for a, b, c in triangles[::2]]
    soup, out = [], []
    for t in triangles:
        out.append([len(soup), len(soup) + 1, len(soup) + 2])
        soup += [[x + rng.uniform(-shift, shift) for x in vertices[v]] for v in t]
    return soup, out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("how", choices=["shuffle", "crack", "scale"])
    ap.add_argument("input")
    ap.add_argument("output")
    ap.add_argument("amount", type=float, help="SEED for shuffle, REL for crack, FACTOR for scale")
    ap.add_argument("--half-twice", action="store_true")
    ap.add_argument("--seed", type=int, default=5)
    a = ap.parse_args()
    vertices, faces = read_obj(a.input)
    if a.how == "shuffle":
        vertices, faces = shuffle(vertices, faces, random.Random(int(a.amount)))
    elif a.how == "scale":
        vertices = [[x * a.amount for x in v] for v in vertices]
    else:
        vertices, faces = crack(vertices, faces, a.amount, a.half_twice, random.Random(a.seed))
    write_obj(a.output, vertices, faces)


if __name__ == "__main__":
    main()
