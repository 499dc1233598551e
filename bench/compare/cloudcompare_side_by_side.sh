#!/usr/bin/env bash
# `reconar compare` beside CloudCompare's cloud-to-mesh distance (Debian's `cloudcompare`, its
# command-line mode) on the same points and the same design, in one invocation:
#   the as-built points: PROJECT/dense/points.ply;
#   the design: DESIGN (a mesh already in the project's world frame, e.g. a registered design's
#     compare/design_registered.glb) or, when none is given, the project's own Poisson mesh
#     simplified to 100k triangles (`reconar export --max-faces 100000`): a design of realistic
#     complexity that the points lie on;
#   times: the whole `reconar compare PROJECT DESIGN --no-icp` (reading, distances with the normal
#     check, per-element fits, what photos saw, three files written) and our distance computation
#     alone on 1 and 2 threads (bench/compare/deviation_dump, no normal check, as CloudCompare);
#     CloudCompare's whole run (-C2M_DIST with -MAX_DIST, which it runs on one thread, and without,
#     on 2) without saving, and its own log's timings;
#   agreement: per point, our signed distance against CloudCompare's (saved as ASCII in a third run).
#
# Usage: bench/compare/cloudcompare_side_by_side.sh PROJECT [DESIGN] [WORK_DIR]
# Environment: BUILD_DIR (a build with -DRECONAR_BUILD_BENCH=ON, default <repo>/build), MAX_DISTANCE
# (default 0.1 m). Needs `apt-get install cloudcompare python3-numpy`.
set -euo pipefail

repo=$(cd "$(dirname "$0")/../.." && pwd)
build=${BUILD_DIR:-$repo/build}
project=${1:?usage: cloudcompare_side_by_side.sh PROJECT [DESIGN] [WORK_DIR]}
design=${2:-}
work=${3:-$(mktemp -d /tmp/cloudcompare_side_by_side.XXXXXX)}
max_distance=${MAX_DISTANCE:-0.1}
mkdir -p "$work"
command -v CloudCompare > /dev/null || { echo "CloudCompare is not installed: apt-get install cloudcompare" >&2; exit 2; }
points="$project/dense/points.ply"
[[ -f "$points" ]] || { echo "$points: missing (run reconar dense first)" >&2; exit 2; }

if [[ -z "$design" ]]; then
  design="$work/design100k.ply"
  "$build/bin/reconar" export "$project/mesh/mesh.ply" "$design" --max-faces 100000 > /dev/null
fi
# CloudCompare reads no glTF: both tools get the design as one PLY (the elements joined).
"$build/bin/deviation_dump" "$design" "$points" "$work" "$max_distance" | tee "$work/ours.txt"

seconds() { /usr/bin/time -f "%e" "$@" 2>&1 > /dev/null | tail -1; }
ours_whole=$(seconds "$build/bin/reconar" compare "$project" "$work/design.ply" --no-icp --max-distance "$max_distance")
export QT_QPA_PLATFORM=offscreen
cc() { local log=$1; shift; CloudCompare -SILENT -LOG_FILE "$log" -NO_TIMESTAMP -AUTO_SAVE OFF -O "$points" -O "$work/design.ply" -C2M_DIST "$@"; }
export -f cc
export points work
cc_bounded=$(seconds bash -c 'cc "$0" -MAX_DIST "$1" -MAX_TCOUNT 2' "$work/cc_bounded.log" "$max_distance")
cc_threads=$(seconds bash -c 'cc "$0" -MAX_TCOUNT 2' "$work/cc_threads.log")
cc "$work/cc_save.log" -MAX_DIST "$max_distance" -MAX_TCOUNT 2 -C_EXPORT_FMT ASC -PREC 9 -SAVE_CLOUDS FILE "$work/cc.asc" \
  > /dev/null 2>&1

echo "whole runs (s): reconar compare $ours_whole; CloudCompare -MAX_DIST (1 thread) $cc_bounded, unbounded (2 threads) $cc_threads"
echo "CloudCompare's log, bounded:   $(grep -o 'Time: [0-9.]* s' "$work/cc_bounded.log" | tr '\n' ' ')"
echo "CloudCompare's log, unbounded: $(grep -o 'Time: [0-9.]* s' "$work/cc_threads.log" | tr '\n' ' ')"
/usr/bin/python3 - "$work" "$max_distance" <<'PY'
import sys
import numpy as np
work, bound = sys.argv[1], float(sys.argv[2])
ours = np.fromfile(work + "/ours.f32", dtype=np.float32).astype(np.float64)
theirs = np.loadtxt(work + "/cc.asc")[:, -4]  # x y z r g b distance nx ny nz
if theirs.shape != ours.shape:
    sys.exit(f"point counts differ: ours {ours.shape}, CloudCompare {theirs.shape}")
both = np.isfinite(ours) & (np.abs(theirs) < bound)
print(f"points: {ours.size}; on a surface within {bound} m: ours {np.isfinite(ours).sum()}, "
      f"CloudCompare {(np.abs(theirs) < bound).sum()}, both {both.sum()}")
magnitude = np.abs(np.abs(ours[both]) - np.abs(theirs[both]))
print(f"|distance| difference: max {magnitude.max():.3g} m, 99th percentile {np.percentile(magnitude, 99):.3g} m")
flipped = np.sign(ours[both]) != np.sign(theirs[both])
print(f"opposite signs: {flipped.sum()} points (|d| up to {np.abs(theirs[both][flipped]).max() if flipped.any() else 0:.3g} m: "
      "nearest point on an edge or corner, where the faces met disagree)")
PY
