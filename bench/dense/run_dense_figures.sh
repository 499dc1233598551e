#!/bin/sh
# Dense-accuracy figures with wall time and peak RSS (/usr/bin/time -v), one process per scene:
# the rendered bunny (dense points + Poisson mesh vs bun_zipper.ply) and templeRing (points in the
# README's bounding box). Extra arguments go to bench_dense_figures (e.g. --level 1 --threads 2).
# Usage: bench/dense/run_dense_figures.sh BUILD_DIR [bunny|templering|all] [args...]
set -eu
build_dir=${1:?usage: run_dense_figures.sh BUILD_DIR [bunny|templering|all] [args...]}
scenes=${2:-all}
[ $# -ge 2 ] && shift 2 || shift 1
binary="$build_dir/bin/bench_dense_figures"
[ -x "$binary" ] || { echo "run_dense_figures.sh: $binary not built (configure with -DRECONAR_BUILD_BENCH=ON)" >&2; exit 2; }
[ "$scenes" = all ] && scenes="bunny templering"
status=0
for scene in $scenes; do
  log=$(mktemp)
  echo "== $scene"
  if /usr/bin/time -v "$binary" "$scene" "$@" 2>"$log"; then :; else status=1; grep -v '^\s' "$log" >&2 || true; fi
  grep -E 'Elapsed \(wall clock\)|Maximum resident set size|User time|System time' "$log" | sed 's/^\s*/   /'
  rm -f "$log"
done
exit $status
