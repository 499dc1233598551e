#!/usr/bin/env python3
"""Pixels to points: the same feature picked in two photos must give the same 3D point within 2 sigma.

usage: pick_agreement.py RECONAR PROJECT tags [--corner K]
       pick_agreement.py RECONAR PROJECT tracks [--count N] [--angle DEG]

tags:   each tag's corner K as libapriltag detected it (tags/detections.txt) in the two registered
        photos that see it at the widest angle; also each pick against the model's corner tag:ID:cK.
tracks: N sparse tracks of 3+ views, the feature's keypoints (sparse/images.txt) in the two photos
        of its track whose angle at the point is nearest DEG (default 20).
Each pick is one pixel met with the mesh (`reconar measure --distance A@x,y B@x,y --json`).
Prints each pair and the share within 2 sigma. Python 3 standard library only.
"""
import argparse, json, math, subprocess, sys


def sub(a, b): return [a[i] - b[i] for i in range(3)]
def dot(a, b): return sum(a[i] * b[i] for i in range(3))


def rotation(qw, qx, qy, qz):
    return [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
            [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
            [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]]


def angle(a, b, x):
    u, v = sub(a, x), sub(b, x)
    return math.degrees(math.acos(max(-1.0, min(1.0, dot(u, v) / math.sqrt(dot(u, u) * dot(v, v))))))


def read_model(project):
    """Camera centres by photo name; track observations (photo, x, y) in our pixel convention; points."""
    centres, tracks, points = {}, {}, {}
    lines = [l for l in open(project + '/sparse/images.txt') if not l.startswith('#')]
    for k in range(0, len(lines) - 1, 2):
        f = lines[k].split()
        R, t = rotation(*map(float, f[1:5])), list(map(float, f[5:8]))
        centres[f[9]] = [-sum(R[r][c] * t[r] for r in range(3)) for c in range(3)]
        p = lines[k + 1].split()
        for j in range(0, len(p), 3):
            if int(p[j + 2]) >= 0:  # COLMAP puts the top-left pixel's centre at 0.5
                tracks.setdefault(int(p[j + 2]), []).append((f[9], float(p[j]) - 0.5, float(p[j + 1]) - 0.5))
    for l in open(project + '/sparse/points3D.txt'):
        if not l.startswith('#'):
            f = l.split()
            points[int(f[0])] = list(map(float, f[1:4]))
    return centres, tracks, points


def measure(reconar, project, items):
    run = subprocess.run([reconar, 'measure', project] + items + ['--json'], capture_output=True, text=True)
    if run.returncode != 0:
        return None, run.stderr.strip()
    return json.loads(run.stdout), None


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('reconar'); parser.add_argument('project'); parser.add_argument('mode', choices=['tags', 'tracks'])
    parser.add_argument('--corner', type=int, default=0); parser.add_argument('--count', type=int, default=60)
    parser.add_argument('--angle', type=float, default=20.0)
    args = parser.parse_args()
    centres, tracks, points = read_model(args.project)
    pairs = []  # (name, pick A, pick B, angle, model point name or None)
    if args.mode == 'tags':
        tags = json.load(open(args.project + '/tags.json'))
        corner_of = {t['id']: t['corners'][args.corner] for t in tags['tags']}
        seen, image = {}, None
        for l in open(args.project + '/tags/detections.txt'):
            f = l.split()
            if not f or f[0].startswith('#') or f[0] == 'family':
                continue
            if f[0] == 'image':
                image = f[1]
                continue
            if image in centres:
                seen.setdefault(int(f[0]), []).append((image, float(f[1 + 2 * args.corner]), float(f[2 + 2 * args.corner])))
        for tag, views in sorted(seen.items()):
            if tag not in corner_of or len(views) < 2:
                continue
            a, b = max(((a, b) for i, a in enumerate(views) for b in views[i + 1:]),
                       key=lambda p: angle(centres[p[0][0]], centres[p[1][0]], corner_of[tag]))
            pairs.append(('tag %d c%d' % (tag, args.corner), a, b, angle(centres[a[0]], centres[b[0]], corner_of[tag]),
                          'tag:%d:c%d' % (tag, args.corner)))
    else:
        ids = sorted(p for p in tracks if len(tracks[p]) >= 3 and p in points)
        for pid in ids[::max(1, len(ids) // args.count)][:args.count]:
            views = tracks[pid]
            candidates = [(a, b) for i, a in enumerate(views) for b in views[i + 1:] if a[0] != b[0]]
            if not candidates:
                continue
            a, b = min(candidates, key=lambda p: abs(angle(centres[p[0][0]], centres[p[1][0]], points[pid]) - args.angle))
            pairs.append(('track %d' % pid, a, b, angle(centres[a[0]], centres[b[0]], points[pid]), None))
    within = with_model = placed = 0
    sigmas = []
    unit = ''
    for name, a, b, degrees, model_point in pairs:
        pick_a, pick_b = '%s@%.4f,%.4f' % a, '%s@%.4f,%.4f' % b
        items = ['--distance', pick_a, pick_b] + (['--distance', pick_a, model_point] if model_point else [])
        result, error = measure(args.reconar, args.project, items)
        if result is None:
            print('%s (%.0f deg): %s' % (name, degrees, error))
            continue
        placed += 1
        gap = result['items'][0]
        unit = gap['unit']
        ok = gap['value'] <= 2 * gap['sigma']
        within += ok
        sigmas.append(gap['sigma'])
        line = '%s (%.0f deg): picks %.4g apart, sigma %.4g %s' % (name, degrees, gap['value'], gap['sigma'], 'ok' if ok else 'OUT')
        if model_point:
            to_model = result['items'][1]
            with_model += to_model['value'] <= 2 * to_model['sigma']
            line += '; first pick to %s %.4g, sigma %.4g' % (model_point, to_model['value'], to_model['sigma'])
        print(line)
    if not sigmas:
        sys.exit('no pair placed')
    sigmas.sort()
    print('%d pairs, %d placed: %d within 2 sigma of each other (%.1f %%), median sigma %.4g %s%s' % (
        len(pairs), placed, within, 100.0 * within / placed, sigmas[len(sigmas) // 2], unit,
        '; %d first picks within 2 sigma of the model corner' % with_model if args.mode == 'tags' else ''))


if __name__ == '__main__':
    main()
