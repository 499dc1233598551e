#!/usr/bin/env python3
# Usage: tag_reprojection.py PROJECT (tags.json, sparse/*.txt and tags/detections.txt of a reconstructed project).
# Per image, the reprojection error (px) of each tag's corners (from tags.json, world frame) with the
# sparse model's cameras (sparse/images.txt + cameras.txt, COLMAP text, world frame).
import json, sys, math
P = sys.argv[1]
tags = {t['id']: t['corners'] for t in json.load(open(P + '/tags.json'))['tags']}
cams = {}
for l in open(P + '/sparse/cameras.txt'):
    if l.startswith('#') or not l.strip(): continue
    f = l.split(); cams[f[0]] = (f[1], [float(x) for x in f[4:]])
def qrot(q, v):
    w, x, y, z = q
    R = [[1-2*(y*y+z*z), 2*(x*y-w*z), 2*(x*z+w*y)], [2*(x*y+w*z), 1-2*(x*x+z*z), 2*(y*z-w*x)], [2*(x*z-w*y), 2*(y*z+w*x), 1-2*(x*x+y*y)]]
    return [sum(R[i][j]*v[j] for j in range(3)) for i in range(3)]
imgs = {}
lines = [l for l in open(P + '/sparse/images.txt') if not l.startswith('#')]
for i in range(0, len(lines), 2):
    f = lines[i].split()
    if len(f) < 10: continue
    imgs[f[9]] = ([float(x) for x in f[1:5]], [float(x) for x in f[5:8]], f[8])
det = {}
cur = None
for l in open(P + '/tags/detections.txt'):
    f = l.split()
    if not f or f[0].startswith('#') or f[0] == 'family': continue
    if f[0] == 'image': cur = f[1]; det[cur] = []; continue
    det[cur].append((int(f[0]), [float(x) for x in f[1:9]]))
for name in sorted(det):
    if name not in imgs: print(name, 'not registered'); continue
    q, t, cid = imgs[name]; model, p = cams[cid]
    out = []
    for tid, c in det[name]:
        if tid not in tags: continue
        errs = []
        for k in range(4):
            X = qrot(q, tags[tid][k]); X = [X[i] + t[i] for i in range(3)]
            x, y = X[0]/X[2], X[1]/X[2]
            if model == 'SIMPLE_RADIAL': fx, cx, cy, k1 = p; fy = fx; k2 = 0
            elif model == 'RADIAL': fx, cx, cy, k1, k2 = p; fy = fx
            else: fx, fy, cx, cy = p[:4]; k1 = k2 = 0
            r2 = x*x + y*y; d = 1 + k1*r2 + k2*r2*r2
            u, v = fx*d*x + cx, fy*d*y + cy
            errs.append(math.hypot(u - c[2*k], v - c[2*k+1]))
        out.append('%d:%.1f' % (tid, max(errs)))
    print(name, ' '.join(out))
