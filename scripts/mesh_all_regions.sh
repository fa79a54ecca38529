#!/usr/bin/env bash
# Runs `unamalla mesh` with default settings on every bundled region and prints one markdown
# table row per region (used for docs/results.md). Usage: scripts/mesh_all_regions.sh [timeout_s]
set -u
cd "$(dirname "$0")/.."
t=${1:-150}
# UNAMALLA_BIN=path/to/unamalla skips the build and uses that binary
bin=${UNAMALLA_BIN:-}
if [ -z "$bin" ]; then
  cargo build --release -q -p unamalla-cli
  bin=./target/release/unamalla
fi
echo "| region | cells | blocks | non-convex | interior sing. | bent corners | μ ≥ 0.8 % | min SJ | p5 SJ | α₋/ᾱ | area change % | Hausdorff | seconds |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for f in fixtures/regions/*.geojson; do
  r=$(basename "$f" .geojson)
  out=$(timeout "$t" "$bin" mesh "$f" --quiet --json -o "/tmp/unamalla-results/$r" 2>/tmp/unamalla-results-$r.err)
  rc=$?
  if [ $rc -ne 0 ]; then
    if [ $rc -eq 124 ]; then why="did not finish in ${t} s"; else why="error: $(head -c 200 /tmp/unamalla-results-$r.err)"; fi
    echo "| $r | – | – | – | – | – | – | – | – | – | – | – | $why |"
    continue
  fi
  echo "$out" | python3 -c '
import json,sys
d=json.load(sys.stdin)
print("| {region} | {cells} | {blocks} | {non_convex_cells} | {interior_singularities} | {bent_corners} | {mu:.1f} | {sj:.3f} | {p5:.3f} | {am:.3f} | {ac:.3f} | {h:.3g} | {s:.1f} |".format(
  mu=d["mu_ge_0_8_percent"], sj=d["min_scaled_jacobian"], p5=d["p5_scaled_jacobian"], am=d["min_alpha_over_mean"],
  ac=d["area_change_percent"], h=d["hausdorff"], s=d["seconds"], **d))'
done
