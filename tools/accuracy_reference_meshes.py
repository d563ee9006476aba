#!/usr/bin/env python3
"""Independent Gmsh TET10 meshes of corpus assets, for the converged references of
issue 14 (BENCHMARKS.md, "Real assets"). Only the reference runs need this script;
no test does.

usage: accuracy_reference_meshes.py ASSET CORPUS_DIR OUT.msh --h SIZE

ASSET: bracket | nonmanifold | soup | thin_shell. The geometry is the asset's own:
- bracket, nonmanifold, soup: flat-faced solids rebuilt with OpenCASCADE from the
  dimensions in crates/modal-tetra/src/corpus.rs, scaled like the corpus OBJ (the scale
  is read from the OBJ's bounding box); the bracket's gusset is fused with the L, the
  two boxes of `nonmanifold` stay separate volumes touching along one edge (the fin has
  no volume); a TET10 mesh of a flat-faced solid has no geometry error.
- thin_shell: the OBJ's own closed triangle surface is the boundary (discrete
  geometry, reparametrized so it can be remeshed at SIZE); straight-sided TET10
  (their corners lie on the OBJ facets, so the geometry error vanishes with SIZE).
Element size SIZE [m] (MeshSizeMax; MeshSizeMin = SIZE / 3), second order (10 nodes).
--fine-box X0,Y0,Z0,X1,Y1,Z1 --fine-h H: elements of size H inside the box [m] (a Gmsh Box
field, grading over one SIZE outside it), to converge a mode that lives in one region (the
bell's crown plate) without refining the whole object.

Environment used (2026-11-25): python3 -m venv /work/venvs/w14e-gmsh &&
/work/venvs/w14e-gmsh/bin/pip install gmsh   (gmsh 4.15.2)
"""
import argparse
import math

import gmsh


def obj_vertices(path):
    out = []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                out.append(tuple(float(x) for x in line.split()[1:4]))
    return out


def obj_triangles(path):
    tris = []
    with open(path) as f:
        for line in f:
            if line.startswith("f "):
                tris.append(tuple(int(w.split("/")[0]) for w in line.split()[1:4]))
    return tris


def prism(occ, outline, z0, z1, s):
    pts = [occ.addPoint(x * s, y * s, z0 * s) for (x, y) in outline]
    lines = [occ.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
    face = occ.addPlaneSurface([occ.addCurveLoop(lines)])
    return occ.extrude([(2, face)], 0, 0, (z1 - z0) * s)


def volume_tags(dimtags):
    return [t for (d, t) in dimtags if d == 3]


ap = argparse.ArgumentParser()
ap.add_argument("asset", choices=["bracket", "nonmanifold", "soup", "thin_shell"])
ap.add_argument("corpus")
ap.add_argument("out")
ap.add_argument("--h", type=float, required=True)
ap.add_argument("--fine-box", type=lambda t: [float(x) for x in t.split(",")])
ap.add_argument("--fine-h", type=float)
a = ap.parse_args()
if (a.fine_box is None) != (a.fine_h is None) or (a.fine_box is not None and len(a.fine_box) != 6):
    ap.error("--fine-box X0,Y0,Z0,X1,Y1,Z1 and --fine-h H go together")

obj = f"{a.corpus}/{a.asset}.obj"
verts = obj_vertices(obj)
hi = [max(v[c] for v in verts) for c in range(3)]

gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add(a.asset)
occ = gmsh.model.occ
if a.asset == "bracket":
    arm, t = 0.12, 0.012
    s = hi[0] / arm
    l_shape = [(0.0, 0.0), (arm, 0.0), (arm, t), (t, t), (t, arm), (0.0, arm)]
    gusset = [(t - 0.002, t - 0.002), (0.06, t - 0.002), (t - 0.002, 0.06)]
    b1 = volume_tags(prism(occ, l_shape, 0.0, 0.05, s))
    b2 = volume_tags(prism(occ, gusset, 0.019, 0.031, s))
    occ.fuse([(3, b1[0])], [(3, b2[0])])
elif a.asset == "nonmanifold":
    s = hi[0] / 0.14
    occ.addBox(0, 0, 0, 0.08 * s, 0.08 * s, 0.05 * s)
    occ.addBox(0.08 * s, 0.08 * s, 0, 0.06 * s, 0.06 * s, 0.05 * s)
elif a.asset == "soup":
    occ.addBox(0, 0, 0, hi[0], hi[1], hi[2])
occ.synchronize()
if a.asset == "thin_shell":
    tris = obj_triangles(obj)
    surf = gmsh.model.addDiscreteEntity(2)
    gmsh.model.mesh.addNodes(2, surf, list(range(1, len(verts) + 1)), [x for v in verts for x in v])
    gmsh.model.mesh.addElementsByType(surf, 2, [], [i for t in tris for i in t])
    gmsh.model.mesh.removeDuplicateNodes()
    # Split the surface at sharp edges (rim, lip) so it can be reparametrized and remeshed.
    gmsh.model.mesh.classifySurfaces(40 * math.pi / 180, True, True, math.pi)
    gmsh.model.mesh.createGeometry()
    surfaces = [t for (_, t) in gmsh.model.getEntities(2)]
    gmsh.model.geo.addVolume([gmsh.model.geo.addSurfaceLoop(surfaces)])
    gmsh.model.geo.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", a.h)
gmsh.option.setNumber("Mesh.MeshSizeMin", min(a.h, a.fine_h or a.h) / 3)
if a.fine_box is not None:
    box = gmsh.model.mesh.field.add("Box")
    for name, value in zip(["XMin", "YMin", "ZMin", "XMax", "YMax", "ZMax"], a.fine_box):
        gmsh.model.mesh.field.setNumber(box, name, value)
    gmsh.model.mesh.field.setNumber(box, "VIn", a.fine_h)
    gmsh.model.mesh.field.setNumber(box, "VOut", a.h)
    gmsh.model.mesh.field.setNumber(box, "Thickness", a.h)
    gmsh.model.mesh.field.setAsBackgroundMesh(box)
gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 12)
if a.asset == "thin_shell":
    # Mid-edge nodes at the straight midpoints: curving them onto the reparametrized
    # surface inverted elements of the thin wall; the corners lie on the OBJ facets.
    gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)
gmsh.model.mesh.generate(3)
gmsh.model.mesh.setOrder(2)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.Binary", 1)
gmsh.option.setNumber("Mesh.SaveAll", 0)
gmsh.write(a.out)
n = len(gmsh.model.mesh.getNodes()[0])
gmsh.finalize()
fine = f", {a.fine_h} m in {a.fine_box}" if a.fine_box else ""
print(f"{a.asset}: h = {a.h} m{fine}, {n} nodes, {3 * n} DOF -> {a.out}")
