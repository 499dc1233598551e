#!/usr/bin/env bash
# How repeatable a tagged reconstruction is: the photos split into their odd and even halves (by
# name order), each half reconstructed on its own, and the two compared through their tags (the
# frames' angle and the tag centres, as they stand and after the best rigid fit, which no choice
# of frame can beat). Side by side in one invocation:
#   reconar sfm with the tags (tags.json: corners adjusted, frame from the tag board);
#   COLMAP's sparse model of each half (bench/sfm/compare_colmap.sh --colmap-only) with the same
#   detections triangulated from its cameras and framed by the world tag alone (evaluate_tags).
#
# Usage: bench/sfm/compare_halves.sh IMAGES_DIR TAG_SIZE [WORK_DIR]
#   e.g. bench/sfm/compare_halves.sh data/swatbotics_room 0.127
# Environment: BUILD_DIR (a build with -DRECONAR_BUILD_BENCH=ON, default <repo>/build), THREADS
# (default 2), COLMAP (default colmap; installed with apt-get by compare_colmap.sh if missing).
set -euo pipefail

# shellcheck source=bench/sfm/tag_bench_args.sh
source "$(dirname "$0")/tag_bench_args.sh"

# The photos of the top folder, in name order, alternately into the two halves.
for half in odd even; do rm -rf "$work/$half" && mkdir -p "$work/$half/images"; done
index=0
while IFS= read -r photo; do
  if (( index % 2 == 0 )); then half=even; else half=odd; fi
  ln -s "$photo" "$work/$half/images/"
  index=$((index + 1))
done < <(find "$dataset" -maxdepth 1 -type f \( -iname '*.jpg' -o -iname '*.jpeg' -o -iname '*.png' \) | sort)

for half in odd even; do
  echo "== reconar sfm, $half half" >&2
  "$reconar" sfm "$work/$half/images" "$work/$half/reconar" --tag-size "$tag_size" --threads "$threads" \
    >"$work/$half/reconar.log" 2>&1 || { tail -n 20 "$work/$half/reconar.log" >&2; exit 1; }
  echo "== COLMAP, $half half" >&2
  BUILD_DIR=$build THREADS=$threads "$repo/bench/sfm/compare_colmap.sh" --colmap-only "$work/$half/images" \
    "$work/$half/colmap_run" >&2
  "$evaluate" "$work/$half/colmap_run/colmap/text" "$work/$half/reconar/tags/detections.txt" --tag-size "$tag_size" \
    --tags-json "$work/$half/colmap.tags.json" >/dev/null
done

echo
echo "photos: $dataset, odd and even halves   tag size $tag_size m   (work: $work)"
echo "-- reconar (tags.json)"
python3 "$repo/bench/sfm/compare_tag_frames.py" "$work/odd/reconar/tags.json" "$work/even/reconar/tags.json"
echo "-- COLMAP (its cameras, the same detections triangulated)"
python3 "$repo/bench/sfm/compare_tag_frames.py" "$work/odd/colmap.tags.json" "$work/even/colmap.tags.json"
