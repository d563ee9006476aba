"""Moves every mid-edge node of a 10-node tet mesh to its edge midpoint (straight-sided P2).

Used to compare `modal precompute` (isoparametric, keeps curved mid-edge nodes) with
../shared/tools/reference_modes.py (straight-sided P2 on the corner nodes) on one geometry:
    python tools/straighten_tet10.py IN.msh OUT.msh
Benchmark helper only; needs meshio. The project's tests never run it.
"""
import meshio, numpy as np, sys
m = meshio.read(sys.argv[1])
t10 = m.cells_dict["tetra10"]
p = m.points.copy()
# meshio's tetra10 node order (VTK): mid-edge nodes 4..9 on edges (0,1) (1,2) (0,2) (0,3) (1,3) (2,3)
edges = [(0,1),(1,2),(0,2),(0,3),(1,3),(2,3)]
for k,(a,b) in enumerate(edges):
    p[t10[:,4+k]] = 0.5*(m.points[t10[:,a]] + m.points[t10[:,b]])
meshio.write(sys.argv[2], meshio.Mesh(p, [("tetra10", t10)]), file_format="gmsh22", binary=False)
