#!/bin/sh
# The textured model against the vertex-coloured mesh, from photos texturing did not use: holds out
# every 5th registered photo (by name order: the 5th, 10th, ...), textures the project without them
# (`reconar texture --exclude`), renders the textured model and mesh/mesh.ply from each held-out
# pose (`reconar render`), compares both with the photos (texture_quality), and textures the
# project again with every photo so that it is left as it was.
# Usage: bench/texture/heldout_texture.sh BUILD_DIR PROJECT [OUT_DIR]
set -eu
build_dir=${1:?usage: heldout_texture.sh BUILD_DIR PROJECT [OUT_DIR]}
project=${2:?usage: heldout_texture.sh BUILD_DIR PROJECT [OUT_DIR]}
out=${3:-$(mktemp -d)}
reconar="$build_dir/bin/reconar"
quality="$build_dir/bin/texture_quality"
for binary in "$reconar" "$quality"; do
  [ -x "$binary" ] || { echo "heldout_texture.sh: $binary not built (configure with -DRECONAR_BUILD_BENCH=ON)" >&2; exit 2; }
done
images="$project/sparse/images.txt"
[ -f "$images" ] || { echo "heldout_texture.sh: $images missing: reconstruct the project first" >&2; exit 2; }
# images.txt: two lines per registered image, the first ending in its name.
held=$(grep -v '^#' "$images" | awk 'NR % 2 == 1 { print $NF }' | sort | awk 'NR % 5 == 0')
[ -n "$held" ] || { echo "heldout_texture.sh: fewer than 5 registered photos in $project" >&2; exit 2; }
list=$(echo $held | tr ' ' ',')
echo "held out: $list"
/usr/bin/time -f "texture: %e s, peak %M KiB" "$reconar" texture "$project" --exclude "$list"
"$reconar" render "$project" $held --out "$out/textured" >/dev/null
"$reconar" render "$project" $held --out "$out/vertex" --model "$project/mesh/mesh.ply" --no-photos >/dev/null
"$quality" "$out" $held
grep -E '"(patches|seam_step_before|seam_step_after|faces)"' "$project/mesh/texture_report.json" | tr -d ' ,' | tr '\n' ' '
echo
echo "renders in $out; texturing again with every photo"
"$reconar" texture "$project" >/dev/null
