#!/bin/sh
# PMVS against PatchMatch on one project, one after the other in the same run (issue 16's side by
# side figures): each method gets a fresh copy of the sparse project and runs the product's
# `reconar reconstruct` (dense, mesh, exports, preview; the sparse stages are reused), under
# /usr/bin/time -v (its log kept); then bench/dense/mesh_coverage on its mesh. Prints per method
# the dense and whole-run seconds, points, peak RSS (dense stage and whole run, from the reports),
# median/mean coverage of the photos by the mesh, and the ratios to the first variant. The projects
# stay in OUT_DIR/<variant> (previews there).
# Usage: [VARIANTS="..."] bench/dense/compare_dense_methods.sh BUILD_DIR IMAGES_DIR SPARSE_PROJECT OUT_DIR [reconstruct args...]
#   e.g. ... build /data/fountain/images /tmp/fountain_sparse /tmp/cmp --level 1 --threads 2
# VARIANTS: space-separated, each a method and its extra reconstruct flags joined by commas
# (default "pmvs patchmatch"; e.g. "patchmatch patchmatch,--no-fill").
set -eu
usage="usage: compare_dense_methods.sh BUILD_DIR IMAGES_DIR SPARSE_PROJECT OUT_DIR [reconstruct args...]"
build_dir=${1:?$usage}
images=${2:?$usage}
sparse=${3:?$usage}
out=${4:?$usage}
shift 4
reconar="$build_dir/bin/reconar"
coverage="$build_dir/bin/mesh_coverage"
for binary in "$reconar" "$coverage"; do
  [ -x "$binary" ] || { echo "compare_dense_methods.sh: $binary not built (-DRECONAR_BUILD_BENCH=ON)" >&2; exit 2; }
done
[ -f "$sparse/sparse/images.txt" ] || { echo "compare_dense_methods.sh: $sparse has no sparse/ model" >&2; exit 2; }
mkdir -p "$out"
variants=${VARIANTS:-pmvs patchmatch}
for variant in $variants; do
  method=${variant%%,*}
  flags=$(echo "$variant" | cut -s -d, -f2- | tr , ' ')
  project="$out/$(echo "$variant" | tr -c 'A-Za-z0-9_\n-' _)"
  rm -rf "$project"
  mkdir -p "$project"
  for entry in "$sparse"/*; do
    case "$(basename "$entry")" in dense | mesh | preview.png | report.json) ;; *) cp -r "$entry" "$project/" ;; esac
  done
  echo "== $variant: reconar reconstruct $images $project --method $method $flags $*" >&2
  # shellcheck disable=SC2086 # $flags: the variant's words
  /usr/bin/time -v "$reconar" reconstruct "$images" "$project" --method "$method" $flags "$@" --json \
    >"$project/run.json" 2>"$project/run.log" || { tail -5 "$project/run.log" >&2; exit 1; }
  "$coverage" "$project" >"$project/coverage.txt"
done
python3 - "$out" $variants <<'PY'
import json, re, sys
out = sys.argv[1]
rows = {}
for variant in sys.argv[2:]:
    method = re.sub(r"[^A-Za-z0-9_\n-]", "_", variant)
    report = json.load(open(f"{out}/{method}/run.json"))
    stages = {s["name"]: s for s in report["stages"]}
    # The stages reset the peak between phases (so /usr/bin/time's maximum undercounts): the
    # reports' per-phase peaks are the figures.
    rss = report["peak_rss_mib"]
    cov = open(f"{out}/{method}/coverage.txt").read()
    median, mean = map(float, re.search(r"COVERAGE .*median ([0-9.]+), mean ([0-9.]+)", cov).groups())
    dense = report["dense"] or {}
    dense_rss = max(phase["peak_rss_mib"] for phase in dense.get("phases", {}).values()) if dense else 0.0
    rows[variant] = dict(dense_s=stages["dense"]["seconds"], dense_rss=dense_rss, mesh_s=stages.get("mesh", {}).get("seconds", 0.0),
                        total_s=report["seconds"], points=dense.get("points", 0), level=dense.get("level", -1),
                        rss=rss, median=median, mean=mean)
width = max(12, max(len(v) for v in rows) + 2)
print(f"{'':{width}}{'dense s':>9}{'mesh s':>8}{'run s':>8}{'points':>10}{'level':>6}{'dense MiB':>10}{'run MiB':>9}"
      f"{'cover med':>10}{'mean':>7}")
for method, r in rows.items():
    print(f"{method:{width}}{r['dense_s']:9.1f}{r['mesh_s']:8.1f}{r['total_s']:8.1f}{r['points']:10d}{r['level']:6d}"
          f"{r['dense_rss']:10.0f}{r['rss']:9.0f}{r['median']:10.3f}{r['mean']:7.3f}")
first = sys.argv[2]
p = rows[first]
for variant, q in rows.items():
    if variant == first:
        continue
    print(f"{variant} / {first}: dense time {q['dense_s'] / p['dense_s']:.3f}, points {q['points'] / max(1, p['points']):.2f}, "
          f"coverage median {q['median'] / max(1e-9, p['median']):.2f}")
PY
