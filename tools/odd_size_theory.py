#!/usr/bin/env python3
"""Textbook frequencies for tools/odd_size_assets.py's objects in metres (BENCHMARKS.md, "Files in
other units, odd sizes and faint taps"): Lamb's free sphere, Kirchhoff's free disc with Leissa's
λ², the free-free Euler-Bernoulli beam. Needs numpy."""
import numpy as np
def jn(n,x):
    # spherical Bessel via recurrence (upward OK for x>n-ish); use explicit
    j0=np.sin(x)/x; j1=np.sin(x)/x**2-np.cos(x)/x
    if n==0: return j0
    a,b=j0,j1
    for k in range(1,n): a,b=b,(2*k+1)/x*b-a
    return b
def root(f,lo,hi,N=20000):
    xs=np.linspace(lo,hi,N); v=[f(x) for x in xs]
    for i in range(N-1):
        if np.sign(v[i])!=np.sign(v[i+1]):
            a,b=xs[i],xs[i+1]
            for _ in range(80):
                m=(a+b)/2
                if np.sign(f(m))==np.sign(f(a)): a=m
                else: b=m
            return (a+b)/2
def sphere(E,nu,rho,a):
    G=E/2/(1+nu); cs=np.sqrt(G/rho); cp=cs*np.sqrt(2*(1-nu)/(1-2*nu))
    tors=lambda n: root(lambda x:(n-1)*jn(n,x)-x*jn(n+1,x),0.5,10)
    def sph(n):
        def f(eta):
            xi=eta*cs/cp
            Fe=eta*jn(n+1,eta)/jn(n,eta); Fx=xi*jn(n+1,xi)/jn(n,xi)
            return 2*(eta**2+(n-1)*(n+2)*(Fe-(n+1)))*Fx - eta**4/2+(n-1)*(2*n+1)*eta**2+(eta**2-2*n*(n-1)*(n+2))*Fe
        return root(f,1.0,6)
    for name,x in (("torsional n=2",tors(2)),("spheroidal n=2",sph(2)),("torsional n=3",tors(3)),("spheroidal n=3",sph(3))):
        print(f"  {name}: x={x:.4f} f={x*cs/(2*np.pi*a):.1f} Hz")
print("steel bead r=3mm"); sphere(2e11,0.29,7850,0.003)
def disc(E,nu,rho,a,h):
    D=E*h**3/(12*(1-nu**2)); s=np.sqrt(D/(rho*h))
    return [l/(2*np.pi*a**2)*s for l in (5.253,9.084,12.23,20.52,21.6)]
print("brass coin a=1cm h=1.5mm", ["%.1f"%f for f in disc(1e11,0.34,8500,0.01,0.0015)])
print("brass gong a=0.5 h=3mm", ["%.2f"%f for f in disc(1e11,0.34,8500,0.5,0.003)])
def beam(E,rho,L,b,h):
    r=[]
    for bl in (4.7300,7.8532,10.9956):
        for t in (h,b):
            r.append((bl**2/(2*np.pi*L**2)*np.sqrt(E*t**2/12/rho), t))
    return sorted(r)
print("steel beam 3m x 50 x 30 mm", ["%.2f (t=%g)"%x for x in beam(2e11,7850,3.0,0.05,0.03)])
print("steel bar 0.3 x 20 x 12 mm", ["%.1f (t=%g)"%x for x in beam(2e11,7850,0.3,0.02,0.012)])
