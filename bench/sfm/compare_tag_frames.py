#!/usr/bin/env python3
# Usage: compare_tag_frames.py A/tags.json B/tags.json (two projects of the same tags, e.g. the room's odd and even photos).
# Compare the world frames of two reconar projects through their tags.json: the common tags'
# centres as they stand (no fit), and the rotation of the rigid fit of A's common corners onto B's.
import json, sys, math

def load(p):
    d = json.load(open(p))
    return {t['id']: t['corners'] for t in d['tags']}, d

def sub(a, b): return [a[i]-b[i] for i in range(3)]
def add(a, b): return [a[i]+b[i] for i in range(3)]
def mul(a, s): return [x*s for x in a]
def norm(a): return math.sqrt(sum(x*x for x in a))

def jacobi_eig(A, iters=100):
    n = len(A); A = [row[:] for row in A]; V = [[float(i == j) for j in range(n)] for i in range(n)]
    for _ in range(iters):
        off = sum(A[i][j]**2 for i in range(n) for j in range(n) if i != j)
        if off < 1e-30: break
        for p in range(n):
            for q in range(p+1, n):
                if abs(A[p][q]) < 1e-300: continue
                th = (A[q][q]-A[p][p])/(2*A[p][q]); t = (1 if th >= 0 else -1)/(abs(th)+math.sqrt(th*th+1))
                c = 1/math.sqrt(t*t+1); s = t*c
                for k in range(n):
                    akp, akq = A[k][p], A[k][q]; A[k][p] = c*akp - s*akq; A[k][q] = s*akp + c*akq
                for k in range(n):
                    apk, aqk = A[p][k], A[q][k]; A[p][k] = c*apk - s*aqk; A[q][k] = s*apk + c*aqk
                for k in range(n):
                    vkp, vkq = V[k][p], V[k][q]; V[k][p] = c*vkp - s*vkq; V[k][q] = s*vkp + c*vkq
    return [A[i][i] for i in range(n)], V

def quat_to_R(q):
    w,x,y,z = q
    return [[1-2*(y*y+z*z), 2*(x*y-w*z), 2*(x*z+w*y)],[2*(x*y+w*z), 1-2*(x*x+z*z), 2*(y*z-w*x)],[2*(x*z-w*y), 2*(y*z+w*x), 1-2*(x*x+y*y)]]

def horn(P, Q):  # Horn's quaternion fit: (angle in degrees, residual distances) of the rotation R, t minimising |R p + t - q|
    cp = mul([sum(p[i] for p in P) for i in range(3)], 1/len(P)); cq = mul([sum(q[i] for q in Q) for i in range(3)], 1/len(Q))
    S = [[0]*3 for _ in range(3)]
    for p, q in zip(P, Q):
        a, b = sub(p, cp), sub(q, cq)
        for i in range(3):
            for j in range(3): S[i][j] += a[i]*b[j]
    Sxx,Sxy,Sxz,Syx,Syy,Syz,Szx,Szy,Szz = S[0][0],S[0][1],S[0][2],S[1][0],S[1][1],S[1][2],S[2][0],S[2][1],S[2][2]
    N = [[Sxx+Syy+Szz, Syz-Szy, Szx-Sxz, Sxy-Syx],
         [Syz-Szy, Sxx-Syy-Szz, Sxy+Syx, Szx+Sxz],
         [Szx-Sxz, Sxy+Syx, -Sxx+Syy-Szz, Syz+Szy],
         [Sxy-Syx, Szx+Sxz, Syz+Szy, -Sxx-Syy+Szz]]
    w, V = jacobi_eig(N); k = max(range(4), key=lambda i: w[i]); q = [V[i][k] for i in range(4)]
    R = quat_to_R(q)
    res = []
    for p, qq in zip(P, Q):
        a = sub(p, cp); ra = [sum(R[i][j]*a[j] for j in range(3)) for i in range(3)]
        res.append(norm(sub(add(ra, cq), qq)))
    return 2*math.degrees(math.acos(min(1.0, abs(q[0])))), res

A, da = load(sys.argv[1]); B, db = load(sys.argv[2])
common = sorted(set(A) & set(B))
P = [c for i in common for c in A[i]]; Q = [c for i in common for c in B[i]]
d = []
for i in common:
    ca = mul([sum(c[k] for c in A[i]) for k in range(3)], 0.25); cb = mul([sum(c[k] for c in B[i]) for k in range(3)], 0.25)
    d.append((norm(sub(ca, cb)), i))
d.sort()
print("world tags %s / %s; %d common tags; frame rotation between them %.3f deg; centre differences: median %.1f mm, max %.1f mm (tag %d)" % (
    da.get('world_tag'), db.get('world_tag'), len(common), horn(P, Q)[0], 1000*d[len(d)//2][0], 1000*d[-1][0], d[-1][1]))

# Residual after the best rigid fit of A's centres onto B's (how far the two models differ in shape).
cA = [mul([sum(c[k] for c in A[i]) for k in range(3)], 0.25) for i in common]
cB = [mul([sum(c[k] for c in B[i]) for k in range(3)], 0.25) for i in common]
res = sorted(horn(cA, cB)[1])
print("  after the best rigid fit of the centres: residual median %.1f mm, max %.1f mm" % (1000*res[len(res)//2], 1000*res[-1]))
import itertools
ratios = []
for (i, j) in itertools.combinations(range(len(common)), 2):
    da_ = norm(sub(cA[i], cA[j])); db_ = norm(sub(cB[i], cB[j]))
    if da_ > 1.0: ratios.append(db_/da_)
ratios.sort()
print("  B/A distance ratio over pairs > 1 m: median %.4f, range %.4f..%.4f" % (ratios[len(ratios)//2], ratios[0], ratios[-1]))
s = ratios[len(ratios)//2]
res = sorted(horn([mul(c, s) for c in cA], cB)[1])
print("  after scaling A by the median ratio and the best rigid fit: residual median %.1f mm, max %.1f mm" % (1000*res[len(res)//2], 1000*res[-1]))
