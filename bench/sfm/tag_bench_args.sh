# Sourced by the tag benchmarks (compare_tag_edges.sh, compare_halves.sh) after their usage comment
# and `set -euo pipefail`: IMAGES_DIR TAG_SIZE [WORK_DIR] into $dataset, $tag_size, $work (a new
# /tmp/<script name>.XXXXXX by default), and $repo, $build, $reconar, $evaluate (evaluate_tags),
# $threads; --help prints the caller's usage comment.
if [[ $# -lt 2 || $# -gt 3 || $1 == -h || $1 == --help ]]; then
  sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'
  [[ $# -ge 1 && ($1 == -h || $1 == --help) ]] && exit 0
  exit 2
fi
repo=$(cd "$(dirname "$0")/../.." && pwd)
dataset=$(realpath "$1")
tag_size=$2
work=${3:-$(mktemp -d "/tmp/$(basename "$0" .sh).XXXXXX")}
mkdir -p "$work"
work=$(realpath "$work")
build=${BUILD_DIR:-$repo/build}
reconar=$build/bin/reconar
evaluate=$build/bin/evaluate_tags
threads=${THREADS:-2}
[[ -x $evaluate ]] || { echo "evaluate_tags not found at $evaluate (build with -DRECONAR_BUILD_BENCH=ON)" >&2; exit 2; }
