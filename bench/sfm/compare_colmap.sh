#!/usr/bin/env bash
# Sparse reconstruction side by side: COLMAP (CPU) and `reconar sfm` on the same images, in one
# invocation, each timed with /usr/bin/time -v (wall clock, peak RSS) and evaluated against the
# dataset's ground truth with evaluate_sfm.
#
# Usage: bench/sfm/compare_colmap.sh [--colmap-only | --reconar-only] DATASET_DIR [WORK_DIR]
#   DATASET_DIR  a dataset of ../shared/data: Strecha (images/ + gt_cameras/) or Middlebury
#                (*.png + *_par.txt), or a rendered set (bench/sfm/render_capture: images/ +
#                truth/); any other folder of images runs without ground truth.
#   WORK_DIR     where both projects go (default: a new /tmp/compare_colmap.XXXXXX).
# Environment:
#   BUILD_DIR     reconar build with -DRECONAR_BUILD_BENCH=ON (default: <repo>/build)
#   RECONAR       the reconar binary (default: $BUILD_DIR/bin/reconar)
#   EVALUATE_SFM  the evaluator (default: $BUILD_DIR/bin/evaluate_sfm)
#   COLMAP        the colmap binary (default: colmap; installed with apt-get if missing)
#   THREADS       threads for both programs (default: 2)
#   COLMAP_CAMERA_MODEL  (default: RADIAL, the model reconar estimates: f, cx, cy, k1, k2)
set -euo pipefail

usage() {
  sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'
  exit "$1"
}

only=both
positional=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --colmap-only) only=colmap ;;
    --reconar-only) only=reconar ;;
    -h | --help) usage 0 ;;
    -*) echo "unknown option: $1" >&2; usage 2 ;;
    *) positional+=("$1") ;;
  esac
  shift
done
[[ ${#positional[@]} -ge 1 && ${#positional[@]} -le 2 ]] || usage 2

repo=$(cd "$(dirname "$0")/../.." && pwd)
dataset=$(realpath "${positional[0]}")
work=${positional[1]:-$(mktemp -d /tmp/compare_colmap.XXXXXX)}
mkdir -p "$work"
work=$(realpath "$work")
build=${BUILD_DIR:-$repo/build}
reconar=${RECONAR:-$build/bin/reconar}
evaluate=${EVALUATE_SFM:-$build/bin/evaluate_sfm}
colmap=${COLMAP:-colmap}
threads=${THREADS:-2}
camera_model=${COLMAP_CAMERA_MODEL:-RADIAL}

if [[ -d $dataset/images ]]; then images=$dataset/images; else images=$dataset; fi
gt_args=()
if [[ -d $dataset/gt_cameras ]]; then
  gt_args=(--strecha "$dataset/gt_cameras")
elif [[ -f $dataset/truth/images.txt ]]; then
  gt_args=(--colmap-truth "$dataset/truth")
else
  par=$(find "$dataset" -maxdepth 1 -name '*_par.txt' | sort | head -n 1)
  if [[ -n $par ]]; then gt_args=(--middlebury-par "$par"); fi
fi
[[ -x $evaluate ]] || { echo "evaluate_sfm not found at $evaluate (build with -DRECONAR_BUILD_BENCH=ON)" >&2; exit 2; }

# timed NAME COMMAND...: runs COMMAND with its output in $work/NAME.log and the
# /usr/bin/time -v report in $work/NAME.time.
timed() {
  local name=$1
  shift
  echo "== $name: $*" >&2
  if ! /usr/bin/time -v -o "$work/$name.time" "$@" >"$work/$name.log" 2>&1; then
    echo "$name failed; last lines of $work/$name.log:" >&2
    tail -n 20 "$work/$name.log" >&2
    return 1
  fi
}

# Wall and CPU seconds summed, peak RSS (MiB) maxed over the given .time files.
wall_seconds() {
  awk -F': ' '/Elapsed \(wall clock\)/ {
      n = split($2, p, ":"); s = 0
      for (i = 1; i <= n; ++i) s = s * 60 + p[i]
      total += s
    } END { printf "%.1f", total }' "$@"
}
cpu_seconds() {
  awk -F': ' '/(User|System) time \(seconds\)/ { total += $2 } END { printf "%.1f", total }' "$@"
}
peak_rss_mib() {
  awk -F': ' '/Maximum resident set size/ { if ($2 > m) m = $2 } END { printf "%.0f", m / 1024 }' "$@"
}

# json_value FILE KEY: a scalar of evaluate_sfm's flat JSON (one "key": value per line).
json_value() {
  awk -v key="\"$2\":" '$1 == key { v = $2; sub(/,$/, "", v); print v; exit }' "$1"
}

run_colmap() {
  if ! command -v "$colmap" >/dev/null; then
    echo "colmap not found; installing it with apt-get" >&2
    local sudo=""
    [[ $(id -u) -eq 0 ]] || sudo=sudo
    $sudo apt-get install -y colmap >&2
  fi
  local project=$work/colmap
  rm -rf "$project"
  mkdir -p "$project/sparse" "$project/text"
  export QT_QPA_PLATFORM=offscreen
  timed colmap_features "$colmap" feature_extractor \
    --database_path "$project/database.db" --image_path "$images" \
    --ImageReader.camera_model "$camera_model" \
    --SiftExtraction.use_gpu 0 --SiftExtraction.num_threads "$threads" || return 1
  timed colmap_matching "$colmap" exhaustive_matcher \
    --database_path "$project/database.db" \
    --SiftMatching.use_gpu 0 --SiftMatching.num_threads "$threads" || return 1
  timed colmap_mapper "$colmap" mapper \
    --database_path "$project/database.db" --image_path "$images" \
    --output_path "$project/sparse" --Mapper.num_threads "$threads" || return 1
  # The mapper may split the scene into several models; keep the one with the most registered
  # images (the size of images.bin is no proxy for that: it holds every keypoint of every image).
  local model best="" best_count=-1 count
  : >"$work/colmap_convert.log"
  for model in "$project"/sparse/*/; do
    [[ -f $model/images.bin ]] || continue
    rm -rf "$project/text.tmp" && mkdir -p "$project/text.tmp"
    "$colmap" model_converter --input_path "$model" \
      --output_path "$project/text.tmp" --output_type TXT >>"$work/colmap_convert.log" 2>&1 || return 1
    # images.txt: comment lines, then two lines per registered image.
    count=$(awk '!/^#/ { n++ } END { print int(n / 2) }' "$project/text.tmp/images.txt")
    echo "colmap model $model: $count registered images" >&2
    if ((count > best_count)); then
      best=$model best_count=$count
      rm -rf "$project/text" && mv "$project/text.tmp" "$project/text"
    fi
  done
  rm -rf "$project/text.tmp"
  [[ -n $best ]] || { echo "colmap produced no model" >&2; return 1; }
  wall_seconds "$work"/colmap_{features,matching,mapper}.time >"$work/colmap.wall"
  cpu_seconds "$work"/colmap_{features,matching,mapper}.time >"$work/colmap.cpu"
  peak_rss_mib "$work"/colmap_{features,matching,mapper}.time >"$work/colmap.rss"
  "$evaluate" "$project/text" "${gt_args[@]}" >"$work/colmap_eval.json" || return 1
}

run_reconar() {
  [[ -x $reconar ]] || { echo "reconar not found at $reconar" >&2; return 1; }
  local project=$work/reconar
  rm -rf "$project"
  timed reconar_sfm "$reconar" sfm "$images" "$project" --threads "$threads" || return 1
  wall_seconds "$work/reconar_sfm.time" >"$work/reconar.wall"
  cpu_seconds "$work/reconar_sfm.time" >"$work/reconar.cpu"
  peak_rss_mib "$work/reconar_sfm.time" >"$work/reconar.rss"
  "$evaluate" "$project/sparse" "${gt_args[@]}" >"$work/reconar_eval.json" || return 1
}

# Each run_* stops at its first failure (set -e does not apply inside a || list).
status=0
if [[ $only != reconar ]]; then run_colmap || status=1; fi
if [[ $only != colmap ]]; then run_reconar || status=1; fi

# stage_seconds TOOL STAGE: wall seconds of one stage (features, matching, mapping), "-" when
# missing. COLMAP: its own process per stage (/usr/bin/time); reconar: report.json "stages"
# (in-process timers, so they exclude start-up and do not add up to the process wall time).
stage_seconds() {
  local tool=$1 stage=$2
  if [[ $tool == colmap ]]; then
    [[ $stage == mapping ]] && stage=mapper
    if [[ -s $work/colmap_$stage.time ]]; then wall_seconds "$work/colmap_$stage.time"; else echo -; fi
  elif [[ -s $work/reconar/report.json ]]; then
    awk -v stage="\"$stage\"," '$1 == "\"name\":" && $2 == stage { inside = 1 }
      inside && $1 == "\"seconds\":" { v = $2; sub(/,$/, "", v); printf "%.1f", v; found = 1; exit }
      END { if (!found) print "-" }' "$work/reconar/report.json"
  else
    echo -
  fi
}

# value TOOL ROW: one cell of the table, "-" when that run is missing.
value() {
  local tool=$1 row=$2
  case "$row" in
    stage_*) stage_seconds "$tool" "${row#stage_}" ;;
    wall) cat "$work/$tool.wall" 2>/dev/null || echo - ;;
    cpu) cat "$work/$tool.cpu" 2>/dev/null || echo - ;;
    rss) cat "$work/$tool.rss" 2>/dev/null || echo - ;;
    *) if [[ -s $work/${tool}_eval.json ]]; then json_value "$work/${tool}_eval.json" "$row"; else echo -; fi ;;
  esac
}
ratio() {
  awk -v a="$1" -v b="$2" 'BEGIN { if (a + 0 == a && b + 0 == b && b != 0) printf "%.2f", a / b; else print "-" }'
}

unit=$(value colmap centre_error_unit)
if [[ $unit == - ]]; then unit=$(value reconar centre_error_unit); fi
echo
echo "dataset: $dataset   (work: $work)"
printf '%-28s %14s %14s %10s\n' "" reconar colmap reconar/colmap
rows=(stage_features:"features wall (s)" stage_matching:"matching wall (s)"
  stage_mapping:"mapping wall (s)" wall:"wall time, total (s)" cpu:"CPU time, user+sys (s)" rss:"peak RSS (MiB)"
  registered:"registered images" total:"images"
  num_points:"3D points" mean_track_length:"mean track length"
  centre_error_mean:"centre error mean (${unit//\"/})" centre_error_median:"centre error median"
  centre_error_max:"centre error max" rotation_error_mean_deg:"rotation error mean (deg)"
  relative_rotation_error_mean_deg:"relative rotation err (deg)"
  focal_ratio_mean:"focal / GT focal (mean)" reprojection_error_mean:"reprojection error (px)")
for entry in "${rows[@]}"; do
  key=${entry%%:*}
  label=${entry#*:}
  a=$(value reconar "$key")
  b=$(value colmap "$key")
  printf '%-28s %14s %14s %10s\n' "$label" "$a" "$b" "$(ratio "$a" "$b")"
done
exit "$status"
