#!/usr/bin/env python3
"""NEES of chained odometry edges (docs/LOOP.md "Do no harm: what is left").

The loop closer's graph and its plausibility test treat the keyframe-to-keyframe odometry edges as
independent: the covariance of a chain of L edges is the sum of each edge's calibrated covariance
moved into the last keyframe's frame. This compares that with ground truth, by chain length: NEES
per dof ~1 at every length when the edges are calibrated AND independent.

  plumb run --dataset D --no-loops --out t.txt --covariance cov.txt
  scripts/odometry_chain_nees.py GROUNDTRUTH.txt cov.txt [lengths, default 1,2,5,10,20,30,40]

GROUNDTRUTH in TUM format (a synthetic scene's: `plumb synth ... --out DIR`, DIR/groundtruth.txt).
Small-angle rotation errors; ground truth taken at the nearest stamp within 20 ms. Python 3
standard library only.
"""
import sys, math, bisect
def qmat(x,y,z,w):
    n=math.sqrt(x*x+y*y+z*z+w*w); x,y,z,w=x/n,y/n,z/n,w/n
    return [[1-2*(y*y+z*z),2*(x*y-z*w),2*(x*z+y*w)],[2*(x*y+z*w),1-2*(x*x+z*z),2*(y*z-x*w)],[2*(x*z-y*w),2*(y*z+x*w),1-2*(x*x+y*y)]]
def mm(A,B): return [[sum(A[i][k]*B[k][j] for k in range(len(B))) for j in range(len(B[0]))] for i in range(len(A))]
def T(A): return [list(r) for r in zip(*A)]
def mv(A,v): return [sum(A[i][k]*v[k] for k in range(len(v))) for i in range(len(A))]
def pose(R,t): return (R,t)
def comp(a,b): return (mm(a[0],b[0]), [x+y for x,y in zip(mv(a[0],b[1]),a[1])])
def inv(a): Rt=T(a[0]); return (Rt,[-x for x in mv(Rt,a[1])])
def hat(v): return [[0,-v[2],v[1]],[v[2],0,-v[0]],[-v[1],v[0],0]]
def adj(a):
    R,t=a; tR=mm(hat(t),R); M=[[0.0]*6 for _ in range(6)]
    for i in range(3):
        for j in range(3):
            M[i][j]=R[i][j]; M[i][j+3]=tR[i][j]; M[i+3][j+3]=R[i][j]
    return M
def sym21(v):
    M=[[0.0]*6 for _ in range(6)]; k=0
    for i in range(6):
        for j in range(i,6): M[i][j]=M[j][i]=v[k]; k+=1
    return M
def solve(A,b):
    n=len(b); M=[A[i][:]+[b[i]] for i in range(n)]
    for c in range(n):
        p=max(range(c,n),key=lambda r:abs(M[r][c])); M[c],M[p]=M[p],M[c]
        for r in range(n):
            if r!=c:
                f=M[r][c]/M[c][c]
                for k in range(c,n+1): M[r][k]-=f*M[c][k]
    return [M[i][n]/M[i][i] for i in range(n)]
gt=[]
for l in open(sys.argv[1]):
    if l.startswith('#') or not l.strip(): continue
    f=list(map(float,l.split())); gt.append((f[0],pose(qmat(*f[4:8]),f[1:4])))
gts=[g[0] for g in gt]
def gtat(t):
    i=bisect.bisect_left(gts,t)
    best=min([j for j in (i-1,i) if 0<=j<len(gt)],key=lambda j:abs(gts[j]-t))
    return gt[best][1] if abs(gts[best]-t)<0.02 else None
kfs=[]
for l in open(sys.argv[2]):
    if l.startswith('#'): continue
    f=list(map(float,l.split()))
    if len(f)<51: kfs.append(None); continue
    kfs.append((f[0],f[22],pose(qmat(*f[26:30]),f[23:26]),sym21(f[30:51])))
LENGTHS = [int(x) for x in sys.argv[3].split(",")] if len(sys.argv) > 3 else [1, 2, 5, 10, 20, 30, 40]
for L in LENGTHS:
    tot=0;n=0;tt=0;rr=0
    for s in range(len(kfs)-L):
        chain=kfs[s+1:s+1+L]
        if any(c is None for c in chain): continue
        if any(chain[i+1][1]!=chain[i][0] for i in range(L-1)): continue
        # compose T_first_last and covariance of its right perturbation (frame of last)
        Tc=pose([[1,0,0],[0,1,0],[0,0,1]],[0,0,0]); rel=[]
        for c in chain: Tc=comp(Tc,c[2]); rel.append(Tc)
        C=[[0.0]*6 for _ in range(6)]
        for i,c in enumerate(chain):
            T_last_i=comp(inv(rel[-1]),rel[i]); A=adj(T_last_i); C=[[x+y for x,y in zip(r1,r2)] for r1,r2 in zip(C,mm(mm(A,c[3]),T(A)))]
        g0=gtat(chain[0][1]); g1=gtat(chain[-1][0])
        if g0 is None or g1 is None: continue
        Tg=comp(inv(g0),g1); D=comp(inv(Tg),Tc)  # T_true^-1 T_est = exp(e)
        R=D[0]; ang=[(R[2][1]-R[1][2])/2,(R[0][2]-R[2][0])/2,(R[1][0]-R[0][1])/2]
        e=D[1]+ang
        x=solve(C,e); tot+=sum(a*b for a,b in zip(e,x)); n+=1
        tt+=sum(v*v for v in e[:3]); rr+=sum(v*v for v in e[3:])
    if n: print(f"chain {L:2d} keyframes: NEES/dof {tot/n/6:.3f} (n {n}), rms err {math.sqrt(tt/n)*1000:.1f} mm {math.degrees(math.sqrt(rr/n)):.3f} deg")
