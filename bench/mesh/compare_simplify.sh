#!/usr/bin/env bash
# Mesh simplification side by side: Open3D's simplify_quadric_decimation (Garland & Heckbert
# quadrics, Debian's python3-open3d) and `reconar export --max-faces` (core/mesh/simplify.h) on
# the same mesh and face targets, in one invocation; each run timed with /usr/bin/time -v (wall
# clock, peak RSS) and each result measured against the input mesh with evaluate_mesh (mean and
# max distances both ways, millimetres for a mesh in metres).
#
# Usage: bench/mesh/compare_simplify.sh [MESH.ply [FACES ...]]
#   MESH   default ../shared/data/stanford_bunny/reconstruction/bun_zipper.ply (69,451 faces)
#   FACES  targets (default 6945 1000: 10 % and 1.4 %)
# Environment: BUILD_DIR (a build with -DRECONAR_BUILD_BENCH=ON, default <repo>/build), WORK_DIR
# (default a new /tmp/compare_simplify.XXXXXX), SAMPLES (evaluate_mesh samples, default 300000).
set -euo pipefail

if [[ ${1:-} == -h || ${1:-} == --help ]]; then
  sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'
  exit 0
fi
repo=$(cd "$(dirname "$0")/../.." && pwd)
mesh=$(realpath "${1:-$repo/../shared/data/stanford_bunny/reconstruction/bun_zipper.ply}")
shift || true
targets=("$@")
[[ ${#targets[@]} -gt 0 ]] || targets=(6945 1000)
build=${BUILD_DIR:-$repo/build}
work=${WORK_DIR:-$(mktemp -d /tmp/compare_simplify.XXXXXX)}
mkdir -p "$work"
samples=${SAMPLES:-300000}
python=/usr/bin/python3
[[ -x $build/bin/evaluate_mesh ]] || { echo "evaluate_mesh not found in $build/bin (-DRECONAR_BUILD_BENCH=ON)" >&2; exit 2; }
if ! $python -c 'import open3d' 2>/dev/null; then
  echo "Open3D not found; installing python3-open3d with apt-get" >&2
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo=sudo
  $sudo apt-get install -y python3-open3d >&2
fi

cat >"$work/open3d_simplify.py" <<'EOF'
import sys, time
import open3d as o3d
mesh = o3d.io.read_triangle_mesh(sys.argv[1])
start = time.perf_counter()
out = mesh.simplify_quadric_decimation(target_number_of_triangles=int(sys.argv[3]))
seconds = time.perf_counter() - start
out.remove_unreferenced_vertices()
o3d.io.write_triangle_mesh(sys.argv[2], out)
print(f"open3d: {len(out.triangles)} triangles in {seconds:.3f} s")
EOF

wall() { awk -F': ' '/Elapsed \(wall clock\)/ { n = split($2, p, ":"); s = 0; for (i = 1; i <= n; ++i) s = s * 60 + p[i]; print s }' "$1"; }
rss() { awk -F': ' '/Maximum resident set size/ { printf "%.0f", $2 / 1024 }' "$1"; }
faces() { awk '/^element face/ { print $3; exit }' "$1"; }
# distances OUT: "mesh->ref mean, ref->mesh mean, max of both maxima" from evaluate_mesh.
distances() {
  "$build/bin/evaluate_mesh" "$1" "$mesh" --samples "$samples" >"$1.eval" 2>&1
  awk '/mesh->reference/ { a = $3; am = $11 } /reference->mesh/ { b = $3; bm = $11 }
       END { printf "%10s %10s %10s", a, b, (am > bm ? am : bm) }' "$1.eval"
}

echo "mesh: $mesh ($(faces "$mesh") faces)   work: $work"
printf '%-8s %-8s %8s %8s %8s %10s %10s %10s\n' target tool faces "wall s" "RSS MiB" "to ref" "from ref" "max (mm)"
for target in "${targets[@]}"; do
  /usr/bin/time -v -o "$work/open3d_$target.time" $python "$work/open3d_simplify.py" "$mesh" \
    "$work/open3d_$target.ply" "$target" >"$work/open3d_$target.log" 2>&1
  /usr/bin/time -v -o "$work/reconar_$target.time" "$build/bin/reconar" export "$mesh" "$work/reconar_$target.ply" \
    --max-faces "$target" >"$work/reconar_$target.log" 2>&1
  for tool in open3d reconar; do
    out=$work/${tool}_$target.ply
    # Open3D's time excludes Python start-up and reading: its own timer; ours is the whole process.
    seconds=$(wall "$work/${tool}_$target.time")
    [[ $tool == open3d ]] && seconds="$(awk '{ print $5 }' "$work/open3d_$target.log")(+io)"
    printf '%-8s %-8s %8s %8s %8s %s\n' "$target" "$tool" "$(faces "$out")" "$seconds" \
      "$(rss "$work/${tool}_$target.time")" "$(distances "$out")"
  done
done
