#!/usr/bin/env bash
# Poisson meshing side by side: COLMAP 3.8's poisson_mesher (Kazhdan's PoissonRecon) and
# `reconar mesh` on the same oriented points (the Stanford Bunny's ten real range scans, see
# tests/support/bunny_scans.h), in one invocation. Runs alternate (colmap, ours, colmap, ours, ...),
# each timed with /usr/bin/time -v (wall clock, peak RSS); every output is measured against
# bun_zipper.ply with evaluate_mesh (mean/median/rms distances both ways, millimetres). Then one
# extra COLMAP run without trimming (trim 0) is scored.
#
# Usage: bench/mesh/compare_poisson.sh [--colmap-only] [WORK_DIR]
#   WORK_DIR  where points, meshes and logs go (default: a new /tmp/compare_poisson.XXXXXX)
# Environment:
#   BUILD_DIR   build with -DRECONAR_BUILD_BENCH=ON (default: <repo>/build)
#   RECONAR     the reconar binary (default: $BUILD_DIR/bin/reconar); skipped when it has no
#               `mesh` subcommand
#   COLMAP      the colmap binary (default: colmap)
#   REPEATS     timed runs of each program (default: 3)
#   DEPTH       octree depth for both (default: 8)
#   TRIM        COLMAP's --PoissonMeshing.trim, and ours' --trim when it has one (default: 7)
#   SAMPLES     surface samples per mesh for evaluate_mesh (default: 1000000)
#   DATA_DIR    ../shared/data (default: /work/shared/data)
set -euo pipefail

usage() {
  sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'
  exit "$1"
}

colmap_only=0
positional=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --colmap-only) colmap_only=1 ;;
    -h | --help) usage 0 ;;
    -*) echo "unknown option: $1" >&2; usage 2 ;;
    *) positional+=("$1") ;;
  esac
  shift
done
[[ ${#positional[@]} -le 1 ]] || usage 2

repo=$(cd "$(dirname "$0")/../.." && pwd)
work=${positional[0]:-$(mktemp -d /tmp/compare_poisson.XXXXXX)}
mkdir -p "$work"
work=$(realpath "$work")
build=${BUILD_DIR:-$repo/build}
reconar=${RECONAR:-$build/bin/reconar}
colmap=${COLMAP:-colmap}
repeats=${REPEATS:-3}
depth=${DEPTH:-8}
trim=${TRIM:-7}
samples=${SAMPLES:-1000000}
data=${DATA_DIR:-/work/shared/data}
reference=$data/stanford_bunny/reconstruction/bun_zipper.ply
points_tool=$build/bin/bunny_oriented_points
evaluate=$build/bin/evaluate_mesh

for tool in "$points_tool" "$evaluate"; do
  [[ -x $tool ]] || { echo "$tool not found (build with -DRECONAR_BUILD_BENCH=ON)" >&2; exit 2; }
done
command -v "$colmap" > /dev/null || { echo "colmap not found ($colmap)" >&2; exit 2; }
[[ -x /usr/bin/time ]] || { echo "/usr/bin/time not found (apt-get install time)" >&2; exit 2; }

ours_args=(--depth "$depth" --threads 1)
have_ours=0
if [[ $colmap_only == 0 ]]; then
  if [[ -x $reconar ]] && help=$("$reconar" mesh --help 2>&1); then
    have_ours=1
    if grep -q -- '--trim' <<< "$help"; then ours_args+=(--trim "$trim"); fi
  else
    echo "note: $reconar has no working 'mesh' subcommand; measuring COLMAP only" >&2
  fi
fi

# timed NAME COMMAND...: runs COMMAND with stdout+stderr in $work/NAME.log and /usr/bin/time -v's
# report in $work/NAME.time; fails when the command fails.
timed() {
  local name=$1
  shift
  echo "+ $*" > "$work/$name.log"
  if ! /usr/bin/time -v -o "$work/$name.time" "$@" >> "$work/$name.log" 2>&1; then
    echo "$name failed; see $work/$name.log" >&2
    tail -n 5 "$work/$name.log" >&2
    return 1
  fi
}

# Wall seconds and peak RSS (MB) from a /usr/bin/time -v report.
wall_seconds() {
  awk -F': ' '/Elapsed \(wall clock\)/ {
    n = split($2, part, ":"); s = 0; for (i = 1; i <= n; ++i) s = s * 60 + part[i]; printf "%.2f", s }' "$1"
}
cpu_seconds() { awk -F': ' '/User time|System time/ { s += $2 } END { printf "%.2f", s }' "$1"; }
peak_mb() { awk -F': ' '/Maximum resident set size/ { printf "%.1f", $2 / 1024 }' "$1"; }
median() { sort -g | awk '{ v[NR] = $1 } END { if (NR % 2) print v[(NR + 1) / 2]; else printf "%.2f\n", (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

echo "work dir: $work"
# COLMAP's PoissonRecon (run with --colors) rejects a PLY without red/green/blue, so the points
# carry a grey colour; both programs read the same file.
"$points_tool" "$work/points.ply" --grey

colmap_command() {  # colmap_command OUTPUT TRIM
  echo "$colmap" poisson_mesher --input_path "$work/points.ply" --output_path "$1" \
    --PoissonMeshing.depth "$depth" --PoissonMeshing.trim "$2" --PoissonMeshing.num_threads 1
}

run_colmap() {  # run_colmap NAME TRIM
  # shellcheck disable=SC2046
  timed "$1" $(colmap_command "$work/$1.ply" "$2")
  # poisson_mesher exits 0 even when PoissonRecon rejects its input.
  [[ -s $work/$1.ply ]] || { echo "$1: colmap wrote no mesh; see $work/$1.log" >&2; return 1; }
}

for ((run = 1; run <= repeats; ++run)); do
  echo "run $run/$repeats: colmap"
  run_colmap "colmap_$run" "$trim"
  if [[ $have_ours == 1 ]]; then
    echo "run $run/$repeats: reconar"
    timed "reconar_$run" "$reconar" mesh "$work/points.ply" "$work/reconar_$run.ply" "${ours_args[@]}"
  fi
done
echo "extra: colmap trim 0"
run_colmap colmap_trim0 0

evaluate_into() {  # evaluate_into MESH.ply LOG
  "$evaluate" "$1" "$reference" --samples "$samples" > "$2"
}
evaluate_into "$work/colmap_1.ply" "$work/colmap.eval"
evaluate_into "$work/colmap_trim0.ply" "$work/colmap_trim0.eval"
[[ $have_ours == 1 ]] && evaluate_into "$work/reconar_1.ply" "$work/reconar.eval"

summary() {  # summary LABEL NAME_PREFIX EVAL COMMAND
  local label=$1 prefix=$2 eval_file=$3 command=$4
  local times cpu rss
  times=$(for f in "$work/${prefix}"_[0-9]*.time; do wall_seconds "$f"; echo; done | median)
  cpu=$(for f in "$work/${prefix}"_[0-9]*.time; do cpu_seconds "$f"; echo; done | median)
  rss=$(for f in "$work/${prefix}"_[0-9]*.time; do peak_mb "$f"; echo; done | median)
  echo "== $label"
  echo "   command: $command"
  echo "   wall time (median of $repeats): ${times} s; user+sys CPU (median): ${cpu} s; peak RSS (median): ${rss} MB"
  sed -n 's/^/   /; /vertices/p; /->/p' "$eval_file" | grep -v "$reference" || true
  summary_seconds=$times summary_cpu=$cpu summary_rss=$rss
}

echo
echo "Stanford Bunny range scans -> Poisson depth $depth; errors against bun_zipper.ply ($samples samples per surface)"
summary "COLMAP 3.8 poisson_mesher, trim $trim" colmap "$work/colmap.eval" "$(colmap_command OUT.ply "$trim")"
colmap_seconds=$summary_seconds colmap_cpu=$summary_cpu colmap_rss=$summary_rss
if [[ $have_ours == 1 ]]; then
  summary "reconar mesh" reconar "$work/reconar.eval" "$reconar mesh points.ply OUT.ply ${ours_args[*]}"
  awk -v a="$summary_seconds" -v b="$colmap_seconds" -v c="$summary_rss" -v d="$colmap_rss" \
    -v e="$summary_cpu" -v f="$colmap_cpu" \
    'BEGIN { printf "== ratio reconar / colmap: wall time %.2f, CPU time %.2f, peak RSS %.2f\n", a / b, e / f, c / d }'
fi
echo "== COLMAP 3.8 poisson_mesher, trim 0 (one run)"
echo "   command: $(colmap_command OUT.ply 0)"
echo "   wall time: $(wall_seconds "$work/colmap_trim0.time") s; user+sys CPU: $(cpu_seconds "$work/colmap_trim0.time") s; peak RSS: $(peak_mb "$work/colmap_trim0.time") MB"
sed -n 's/^/   /; /vertices/p; /->/p' "$work/colmap_trim0.eval" | grep -v "$reference" || true
