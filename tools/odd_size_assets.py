#!/usr/bin/env python3
"""Assets of BENCHMARKS.md "Files in other units, odd sizes and faint taps": the repo's mug and
bar written in millimetres, centimetres and inches (OBJ, binary STL, PLY, glTF), and real
objects of odd size in metres (a 6 mm bead, a 2 cm coin, a 1 m gong, a 3 m beam).
Needs numpy. Run from the repository root: python3 tools/odd_size_assets.py OUT_DIR
Textbook values for the metre assets: python3 tools/odd_size_theory.py"""
import numpy as np, sys, os, struct, json
out = sys.argv[1]; os.makedirs(out, exist_ok=True)
def read_obj(p):
    V=[];F=[]
    for l in open(p):
        s=l.split()
        if not s: continue
        if s[0]=='v': V.append([float(x) for x in s[1:4]])
        elif s[0]=='f': F.append([int(x.split('/')[0])-1 for x in s[1:]])
    return np.array(V), F
def write_obj(name,V,F):
    with open(f"{out}/{name}","w") as f:
        for v in V: f.write("v %.9g %.9g %.9g\n"%tuple(v))
        for t in F: f.write("f "+" ".join(str(i+1) for i in t)+"\n")
def write_stl(name,V,F):
    with open(f"{out}/{name}","wb") as f:
        f.write(b"binary STL exported by slicer, units mm".ljust(80,b" "))
        f.write(struct.pack("<I",len(F)))
        for t in F:
            a,b,c=V[t[0]],V[t[1]],V[t[2]]; n=np.cross(b-a,c-a); n=n/(np.linalg.norm(n)+1e-30)
            f.write(struct.pack("<12fH",*n,*a,*b,*c,0))
def write_ply(name,V,F):
    with open(f"{out}/{name}","w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"%(len(V),len(F)))
        for v in V: f.write("%.9g %.9g %.9g\n"%tuple(v))
        for t in F: f.write("3 %d %d %d\n"%tuple(t))
def write_glb(name,V,F):
    pos=np.asarray(V,np.float32).tobytes(); idx=np.asarray(F,np.uint32).ravel().tobytes()
    binb=pos+idx; binb+=b"\0"*((4-len(binb)%4)%4)
    Va=np.asarray(V,np.float32)
    g={"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
       "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
       "buffers":[{"byteLength":len(binb)}],
       "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":len(pos)},{"buffer":0,"byteOffset":len(pos),"byteLength":len(idx)}],
       "accessors":[{"bufferView":0,"componentType":5126,"count":len(V),"type":"VEC3","min":Va.min(0).tolist(),"max":Va.max(0).tolist()},
                    {"bufferView":1,"componentType":5125,"count":len(F)*3,"type":"SCALAR"}]}
    js=json.dumps(g).encode(); js+=b" "*((4-len(js)%4)%4)
    with open(f"{out}/{name}","wb") as f:
        f.write(struct.pack("<III",0x46546C67,2,12+8+len(js)+8+len(binb)))
        f.write(struct.pack("<II",len(js),0x4E4F534A)); f.write(js)
        f.write(struct.pack("<II",len(binb),0x004E4942)); f.write(binb)
def tri(F):
    T=[]
    for t in F:
        for k in range(1,len(t)-1): T.append((t[0],t[k],t[k+1]))
    return T
def box(lx,ly,lz):
    V=np.array([[x,y,z] for x in (0,lx) for y in (0,ly) for z in (0,lz)],float)
    F=[(0,1,3),(0,3,2),(4,6,7),(4,7,5),(0,4,5),(0,5,1),(2,3,7),(2,7,6),(0,2,6),(0,6,4),(1,5,7),(1,7,3)]
    return V,F
def sphere(r,n=48,m=24):
    V=[(0,0,-r)];F=[]
    for i in range(1,m):
        th=np.pi*i/m-np.pi/2
        for j in range(n):
            a=2*np.pi*j/n; V.append((r*np.cos(th)*np.cos(a),r*np.cos(th)*np.sin(a),r*np.sin(th)))
    V.append((0,0,r)); top=len(V)-1
    at=lambda i,j:1+(i-1)*n+j%n
    for j in range(n): F.append((0,at(1,j+1),at(1,j)))
    for i in range(1,m-1):
        for j in range(n):
            a,b,c,d=at(i,j),at(i,j+1),at(i+1,j+1),at(i+1,j); F+=[(a,b,c),(a,c,d)]
    for j in range(n): F.append((top,at(m-1,j),at(m-1,j+1)))
    return np.array(V,float),F
def disc(R,h,n=96,rings=0):
    # closed disc, cylinder along z, centre fan on caps
    V=[(0,0,0),(0,0,h)]; F=[]
    for z in (0,h):
        for j in range(n):
            a=2*np.pi*j/n; V.append((R*np.cos(a),R*np.sin(a),z))
    b0,b1=2,2+n
    for j in range(n):
        k=(j+1)%n
        F.append((0,b0+k,b0+j)); F.append((1,b1+j,b1+k))
        F+=[(b0+j,b0+k,b1+k),(b0+j,b1+k,b1+j)]
    return np.array(V,float),F
mugV,mugF=read_obj('meshes/mug.obj'); mugF=tri(mugF)
bellV,bellF=read_obj('meshes/bell.obj'); bellF=tri(bellF)
# case 1: other units
write_stl('mug_mm.stl',mugV*1000,mugF)
write_obj('mug_mm.obj',mugV*1000,mugF)
write_ply('mug_mm.ply',mugV*1000,mugF)
write_glb('mug_mm.glb',mugV*1000,mugF)
write_obj('mug_cm.obj',mugV*100,mugF)      # 12 cm mug in centimetres (diag ~15 < 20)
write_obj('mug_in.obj',mugV/0.0254,mugF)   # in inches
bV,bF=box(0.3,0.02,0.012)
write_obj('bar_cm.obj',bV*100,bF)          # 30 cm steel bar in cm
write_obj('bar_in.obj',bV/0.0254,bF)       # in inches
sV,sF=sphere(0.003)
write_obj('bead_mm.obj',sV*1000,sF)        # 6 mm bead in mm
write_stl('bead_mm.stl',sV*1000,sF)
# case 2: metres
write_obj('bead_m.obj',sV,sF)
cV,cF=disc(0.01,0.0015); write_obj('coin_m.obj',cV,cF); write_stl('coin_mm.stl',cV*1000,cF)
gV,gF=disc(0.5,0.003,n=192); write_obj('gong_m.obj',gV,gF)
beV,beF=box(3.0,0.05,0.03); write_obj('beam3m.obj',beV,beF)
write_obj('bell15m.obj',bellV*(1.5/0.176),bellF)
