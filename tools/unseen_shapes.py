#!/usr/bin/env python3
"""Shapes of the second unseen-input sweep (BENCHMARKS.md, "A second sweep of unseen
inputs"): OBJ files of a box 1 km from the origin, the same box in millimetres, a 1 m x 2 mm
wire, a tuning fork of four overlapping boxes, a hollow 5 cm ball with a 3 mm wall (inner
sphere facing out: hollow_sphere.obj; facing the cavity, as exporters write it:
hollow_sphere_in.obj) and a wine glass (1.5 mm bowl wall, 7 mm stem, 3 mm foot).

Needs numpy. Usage: python tools/unseen_shapes.py OUT_DIR
"""
import numpy as np, sys
out = sys.argv[1]
import os
os.makedirs(out, exist_ok=True)
def write(name, V, F):
    with open(f"{out}/{name}.obj", "w") as f:
        for v in V: f.write("v %.9g %.9g %.9g\n" % tuple(v))
        for t in F: f.write("f %d %d %d\n" % (t[0]+1, t[1]+1, t[2]+1))
def revolve(profile, n):
    # profile: list of (r,z) closed polyline from axis to axis (first and last r=0)
    V=[]; F=[]; idx={}
    for i,(r,z) in enumerate(profile):
        if r==0:
            idx[(i,0)]=len(V); V.append((0,0,z))
            for j in range(n): idx[(i,j)]=idx[(i,0)]
        else:
            for j in range(n):
                a=2*np.pi*j/n; idx[(i,j)]=len(V); V.append((r*np.cos(a), r*np.sin(a), z))
    for i in range(len(profile)-1):
        for j in range(n):
            a,b,c,d = idx[(i,j)], idx[(i,(j+1)%n)], idx[(i+1,j)], idx[(i+1,(j+1)%n)]
            for t in ((a,b,d),(a,d,c)):
                if len(set(t))==3: F.append(t)
    return np.array(V), F
def box(lo, hi):
    V=np.array([[x,y,z] for x in (lo[0],hi[0]) for y in (lo[1],hi[1]) for z in (lo[2],hi[2])],float)
    F=[(0,1,3),(0,3,2),(4,6,7),(4,7,5),(0,4,5),(0,5,1),(2,3,7),(2,7,6),(0,2,6),(0,6,4),(1,5,7),(1,7,3)]
    return V,F
def merge(parts):
    V=[];F=[];o=0
    for v,f in parts:
        V.extend(v); F.extend([(a+o,b+o,c+o) for a,b,c in f]); o+=len(v)
    return np.array(V),F
# wine glass: foot, stem, bowl (closed profile, outer then inner)
prof=[(0,0),(0.035,0),(0.035,0.003),(0.006,0.005),(0.0035,0.012),(0.0035,0.075)]
for k in range(1,13):
    a=np.pi/2*k/12; prof.append((0.04*np.sin(a), 0.075+0.04*(1-np.cos(a))))
prof.append((0.04,0.16))
prof.append((0.0385,0.16))
for k in range(12,0,-1):
    a=np.pi/2*k/12; prof.append((0.0385*np.sin(a), 0.0765+0.0385*(1-np.cos(a))))
prof.append((0,0.0765))
V,F=revolve(prof,48); write("wineglass",V,F)
# tuning fork: stem + base + two prongs (overlapping boxes)
parts=[box((-0.003,-0.003,0),(0.003,0.003,0.04)), box((-0.009,-0.003,0.038),(0.009,0.003,0.046)),
       box((-0.009,-0.003,0.044),(-0.005,0.003,0.13)), box((0.005,-0.003,0.044),(0.009,0.003,0.13))]
V,F=merge(parts); write("fork",V,F)
# far-away box, and mm box
V,F=box((0,0,0),(0.1,0.05,0.03)); write("far_box", V+np.array([1000.0,2000.0,500.0]), F)
write("mm_box", V*1000, F)
# wire
prof=[(0,0),(0.001,0),(0.001,0.5),(0,0.5)]; V,F=revolve(prof,12); write("wire",V,F)
# hollow sphere: two icosphere-ish UV spheres, inner one outward facing (as exported)
def uvs(r,n=32,m=16,flip=False):
    prof=[(0,-r)]+[(r*np.sin(np.pi*i/m), -r*np.cos(np.pi*i/m)) for i in range(1,m)]+[(0,r)]
    V,F=revolve(prof,n)
    if flip: F=[(a,c,b) for a,b,c in F]
    return V,F
V,F=merge([uvs(0.05),uvs(0.047)]); write("hollow_sphere",V,F)
V,F=merge([uvs(0.05),uvs(0.047,flip=True)]); write("hollow_sphere_in",V,F)
