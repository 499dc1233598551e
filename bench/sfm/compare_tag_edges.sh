#!/usr/bin/env bash
# How well the tags of a photo set are measured, side by side in one invocation:
#   reconar reconstruct with the tag corners in bundle adjustment (the default),
#   reconar reconstruct --no-tags-in-ba (corners triangulated from the final cameras),
#   COLMAP's sparse model (bench/sfm/compare_colmap.sh --colmap-only) with the same detections
#   triangulated from its cameras (evaluate_tags).
# Every figure is "held out": each tag measured at the scale set by the other tags only.
#
# Usage: bench/sfm/compare_tag_edges.sh IMAGES_DIR TAG_SIZE [WORK_DIR]
#   e.g. bench/sfm/compare_tag_edges.sh ../shared/data/apriltag_swatbotics_mapping 0.127
# Environment: BUILD_DIR (a build with -DRECONAR_BUILD_BENCH=ON, default <repo>/build), THREADS
# (default 2), COLMAP (default colmap; installed with apt-get by compare_colmap.sh if missing).
set -euo pipefail

# shellcheck source=bench/sfm/tag_bench_args.sh
source "$(dirname "$0")/tag_bench_args.sh"

# The photos of the top folder only, as reconar reads them (COLMAP would also take sub-folders,
# e.g. a calibration/ folder of checkerboards).
images=$work/images
rm -rf "$images" && mkdir -p "$images"
find "$dataset" -maxdepth 1 -type f \( -iname '*.jpg' -o -iname '*.jpeg' -o -iname '*.png' \) \
  -exec ln -s {} "$images/" \;

echo "== reconar reconstruct (tags in BA)" >&2
"$reconar" reconstruct "$images" "$work/reconar" --tag-size "$tag_size" --stages sparse --threads "$threads" \
  --no-preview >"$work/reconar.log" 2>&1 || { tail -n 20 "$work/reconar.log" >&2; exit 1; }
"$evaluate" "$work/reconar/sparse" "$work/reconar/tags/detections.txt" --tag-size "$tag_size" \
  >"$work/reconar_triangulated.json"
cp "$work/reconar/tags.json" "$work/reconar_adjusted.tags.json"
echo "== reconar reconstruct --no-tags-in-ba" >&2
"$reconar" reconstruct "$images" "$work/reconar" --tag-size "$tag_size" --stages sparse --threads "$threads" \
  --no-preview --no-tags-in-ba >"$work/reconar_no_tags.log" 2>&1 || { tail -n 20 "$work/reconar_no_tags.log" >&2; exit 1; }
"$evaluate" "$work/reconar/sparse" "$work/reconar/tags/detections.txt" --tag-size "$tag_size" \
  >"$work/reconar_no_tags.json"
echo "== COLMAP" >&2
BUILD_DIR=$build THREADS=$threads "$repo/bench/sfm/compare_colmap.sh" --colmap-only "$images" "$work/colmap_run" >&2
"$evaluate" "$work/colmap_run/colmap/text" "$work/reconar/tags/detections.txt" --tag-size "$tag_size" \
  >"$work/colmap.json"

# field FILE KEY: a number of a flat JSON object (tags.json or evaluate_tags' line).
field() {
  tr ',{}' '\n\n\n' <"$1" | awk -v key="\"$2\":" '$1 == key { print $2; exit }'
}
row() {
  local name=$1 file=$2 registered=$3 tags=$4
  awk -v name="$name" -v reg="$registered" -v size="$tag_size" -v tags="$tags" \
    -v mean="$(field "$file" held_out_edge_mean_m)" -v sd="$(field "$file" held_out_edge_std_m)" \
    -v max="$(field "$file" held_out_edge_max_abs_error_m)" \
    'BEGIN { printf "%-34s %10s %6s %12.5f %9.2f %%  %9.2f %%\n", name, reg, tags, mean, 100 * sd / size, 100 * max / size }'
}
registered_of() { awk '!/^#/ { n++ } END { print int(n / 2) }' "$1/images.txt"; }
echo
echo "photos: $dataset   tag size $tag_size m   (work: $work)"
printf '%-34s %10s %6s %12s %11s %11s\n' "" registered tags "edge mean" "spread" "worst edge"
tri=$work/reconar_triangulated.json
row "reconar, tags in BA (tags.json)" "$work/reconar_adjusted.tags.json" "$(field "$tri" registered)" \
  "$(field "$work/reconar_adjusted.tags.json" tags_seen)"
row "reconar, tags in BA, triangulated" "$tri" "$(field "$tri" registered)" "$(field "$tri" tags)"
row "reconar --no-tags-in-ba" "$work/reconar_no_tags.json" "$(field "$work/reconar_no_tags.json" registered)" \
  "$(field "$work/reconar_no_tags.json" tags)"
row "COLMAP, triangulated" "$work/colmap.json" "$(registered_of "$work/colmap_run/colmap/text")" \
  "$(field "$work/colmap.json" tags)"
for f in reconar_triangulated reconar_no_tags colmap; do
  echo "$f: tag x edges $(field "$work/$f.json" x_edge_mean_m) m, y edges $(field "$work/$f.json" y_edge_mean_m) m"
done
