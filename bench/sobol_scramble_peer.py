#!/usr/bin/python3
"""Owen's nested uniform scramble against SciPy's scrambled Sobol (random linear
scramble plus digital shift), both through the exact area-preserving maps of
the sphere and the torus (R = 2, r = 1), f = x^2 + 0.3 y z + exp(z), N = 8192,
seeds 1-20 (issue 36). Shares no code with the sampler: the nested scramble is
written here from its definition (a flip bit per node of the binary tree of
prefixes, from a SplitMix64 hash), the torus's exact mean by a 4096^2 periodic
trapezoid.

    /usr/bin/python3 bench/sobol_scramble_peer.py [--plane]

--plane adds smooth integrands on the unit square with closed-form means, periodic
and not, at N = 4096 and 16384 (RMSE over seeds 1-20).
"""
import numpy as np
from scipy.stats import qmc
R,r=2.0,1.0
def mix(z):
    z=(z ^ (z>>np.uint64(30)))*np.uint64(0xbf58476d1ce4e5b9)
    z=(z ^ (z>>np.uint64(27)))*np.uint64(0x94d049bb133111eb)
    return z ^ (z>>np.uint64(31))
def rev32(k):
    k=k.astype(np.uint64); out=np.zeros_like(k)
    for i in range(32): out|=((k>>np.uint64(i))&np.uint64(1))<<np.uint64(31-i)
    return out
def sob2(k):
    k=k.astype(np.uint64); out=np.zeros_like(k); v=np.uint64(0x80000000)
    for i in range(32):
        out^=np.where((k>>np.uint64(i))&np.uint64(1),v,np.uint64(0)); v=v^(v>>np.uint64(1))
    return out
def owen(bits,seed,dim,rng):
    out=np.zeros_like(bits)
    for i in range(32):
        prefix=bits>>np.uint64(32-i) if i>0 else np.zeros_like(bits)
        h=mix(np.uint64(seed*1000003+dim*7919+i*104729)+prefix*np.uint64(0x9e3779b97f4a7c15))
        flip=h>>np.uint64(63)
        out|=(((bits>>np.uint64(31-i))&np.uint64(1))^flip)<<np.uint64(31-i)
    return (out.astype(np.float64)+rng.random(len(bits)))*2.0**-32
def torus_f(s,t):
    phi=2*np.pi*s
    th=2*np.pi*t
    for _ in range(60):
        g=(R*th+r*np.sin(th))/(2*np.pi*R)-t; th-= g/((R+r*np.cos(th))/(2*np.pi*R))
    x=(R+r*np.cos(th))*np.cos(phi); y=(R+r*np.cos(th))*np.sin(phi); z=r*np.sin(th)
    return x*x+0.3*y*z+np.exp(z)
def sphere_f(s,t):
    z=1-2*t; phi=2*np.pi*s; rr=np.sqrt(np.maximum(0,1-z*z))
    x=rr*np.cos(phi); y=rr*np.sin(phi); return x*x+0.3*y*z+np.exp(z)
# exact torus by fine trapezoid in (phi, theta) with area weight
M=4096; ph=np.arange(M)*2*np.pi/M; th=np.arange(M)*2*np.pi/M
P,T=np.meshgrid(ph,th,indexing='ij'); w=(R+r*np.cos(T))
x=(R+r*np.cos(T))*np.cos(P); y=(R+r*np.cos(T))*np.sin(P); z=r*np.sin(T)
ex_t=((x*x+0.3*y*z+np.exp(z))*w).sum()/w.sum()
ex_s=(4*np.pi/3+2*np.pi*(np.e-1/np.e))/(4*np.pi)
N=8192; k=np.arange(N)
for name,f,ex in [('torus',torus_f,ex_t),('sphere',sphere_f,ex_s)]:
    eo=[];el=[]
    for seed in range(1,21):
        rng=np.random.default_rng(seed)
        s=owen(rev32(k),seed,0,rng); t=owen(sob2(k),seed,1,rng)
        eo.append(abs(f(s,t).mean()-ex))
        p=qmc.Sobol(2,scramble=True,seed=seed).random(N)
        el.append(abs(f(p[:,0],p[:,1]).mean()-ex))
    eo=np.array(eo);el=np.array(el)
    se = np.sqrt(20)
    print(name, 'owen mean|err| %.2e +- %.1e   scipy LMS+shift %.2e +- %.1e  (20 seeds)'
          % (eo.mean(), eo.std() / se, el.mean(), el.std() / se))

if "--plane" in __import__("sys").argv:
    from math import erf, pi, sqrt

    def bump(c, a=8.0):
        return sqrt(pi / a) / 2 * (erf(sqrt(a) * (1 - c)) - erf(sqrt(a) * (0 - c)))

    plane = {
        "exp(u+v)": (lambda s, t: np.exp(s + t), (np.e - 1) ** 2),
        "u^2 v^3": (lambda s, t: s**2 * t**3, 1 / 12),
        "1/(1+u+v)": (lambda s, t: 1 / (1 + s + t), 3 * np.log(3) - 4 * np.log(2)),
        "bump at (0.3, 0.6)": (lambda s, t: np.exp(-8 * ((s - .3)**2 + (t - .6)**2)),
                               bump(.3) * bump(.6)),
        "sin(pi u) cos(pi v/2) + 1": (lambda s, t: np.sin(np.pi * s) * np.cos(np.pi * t / 2) + 1,
                                      (2 / np.pi)**2 + 1),
        "cos(2 pi u)^2 (1+v), periodic in u": (lambda s, t: np.cos(2 * np.pi * s)**2 * (1 + t),
                                               0.75),
    }
    for N in (4096, 16384):
        k = np.arange(N)
        for name, (f, ex) in plane.items():
            eo, el = [], []
            for seed in range(1, 21):
                rng = np.random.default_rng(seed)
                s, t = owen(rev32(k), seed, 0, rng), owen(sob2(k), seed, 1, rng)
                eo.append((f(s, t).mean() - ex)**2)
                p = qmc.Sobol(2, scramble=True, seed=seed).random(N)
                el.append((f(p[:, 0], p[:, 1]).mean() - ex)**2)
            print("plane N=%6d %-36s RMSE nested %.2e  LMS+shift %.2e" %
                  (N, name, np.sqrt(np.mean(eo)), np.sqrt(np.mean(el))))
