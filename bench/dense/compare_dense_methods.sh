#!/bin/sh
# PMVS against PatchMatch on one project, one after the other in the same run (issue 16's side by
# side figures): each method gets a fresh copy of the sparse project and runs the product's
# `reconar reconstruct` (dense, mesh, exports, preview; the sparse stages are reused), under
# /usr/bin/time -v (its log kept); then bench/dense/mesh_coverage on its mesh. Prints per method
# the dense and whole-run seconds, points, peak RSS (dense stage and whole run, from the reports),
# median/mean coverage of the photos by the mesh, and the ratios. The projects stay in OUT_DIR/pmvs and OUT_DIR/patchmatch (previews there).
# Usage: bench/dense/compare_dense_methods.sh BUILD_DIR IMAGES_DIR SPARSE_PROJECT OUT_DIR [reconstruct args...]
#   e.g. ... build /data/fountain/images /tmp/fountain_sparse /tmp/cmp --level 1 --threads 2
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
for method in pmvs patchmatch; do
  project="$out/$method"
  rm -rf "$project"
  mkdir -p "$project"
  for entry in "$sparse"/*; do
    case "$(basename "$entry")" in dense | mesh | preview.png | report.json) ;; *) cp -r "$entry" "$project/" ;; esac
  done
  echo "== $method: reconar reconstruct $images $project --method $method $*" >&2
  /usr/bin/time -v "$reconar" reconstruct "$images" "$project" --method "$method" "$@" --json \
    >"$project/run.json" 2>"$project/run.log" || { tail -5 "$project/run.log" >&2; exit 1; }
  "$coverage" "$project" >"$project/coverage.txt"
done
python3 - "$out" <<'PY'
import json, re, sys
out = sys.argv[1]
rows = {}
for method in ("pmvs", "patchmatch"):
    report = json.load(open(f"{out}/{method}/run.json"))
    stages = {s["name"]: s for s in report["stages"]}
    # The stages reset the peak between phases (so /usr/bin/time's maximum undercounts): the
    # reports' per-phase peaks are the figures.
    rss = report["peak_rss_mib"]
    cov = open(f"{out}/{method}/coverage.txt").read()
    median, mean = map(float, re.search(r"COVERAGE .*median ([0-9.]+), mean ([0-9.]+)", cov).groups())
    dense = report["dense"] or {}
    dense_rss = max(phase["peak_rss_mib"] for phase in dense.get("phases", {}).values()) if dense else 0.0
    rows[method] = dict(dense_s=stages["dense"]["seconds"], dense_rss=dense_rss, mesh_s=stages.get("mesh", {}).get("seconds", 0.0),
                        total_s=report["seconds"], points=dense.get("points", 0), level=dense.get("level", -1),
                        rss=rss, median=median, mean=mean)
print(f"{'':12}{'dense s':>9}{'mesh s':>8}{'run s':>8}{'points':>10}{'level':>6}{'dense MiB':>10}{'run MiB':>9}"
      f"{'cover med':>10}{'mean':>7}")
for method, r in rows.items():
    print(f"{method:12}{r['dense_s']:9.1f}{r['mesh_s']:8.1f}{r['total_s']:8.1f}{r['points']:10d}{r['level']:6d}"
          f"{r['dense_rss']:10.0f}{r['rss']:9.0f}{r['median']:10.3f}{r['mean']:7.3f}")
p, q = rows["pmvs"], rows["patchmatch"]
print(f"patchmatch / pmvs: dense time {q['dense_s'] / p['dense_s']:.3f}, points {q['points'] / max(1, p['points']):.2f}, "
      f"coverage median {q['median'] / max(1e-9, p['median']):.2f}")
PY
