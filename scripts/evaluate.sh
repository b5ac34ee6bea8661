#!/usr/bin/env bash
# The evaluation suite of docs/RESULTS.md: builds evaluate_collision, runs every method on every
# workload (W1 piano/room, W2 primitives, W3 real scans), writes CSV files, a markdown summary
# and PNG charts (gnuplot).
#   scripts/evaluate.sh           full run (about 25 min on 2 cores) into docs/results/
#   scripts/evaluate.sh --quick   smoke run (under 3 min after the build) into build/evaluation-quick/
#   --out=DIR                     another output directory
# Fails when a W3 query is not answered as SCENES.md lists, or an output is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
quick=()
out=""
for a in "$@"; do
  case "$a" in
    --quick) quick=(--quick) ;;
    --out=*) out="${a#--out=}" ;;
    *) echo "usage: scripts/evaluate.sh [--quick] [--out=DIR]" >&2; exit 2 ;;
  esac
done
[ -n "$out" ] || { [ ${#quick[@]} -gt 0 ] && out=build/evaluation-quick || out=docs/results; }
data="${PCL_PROBCOLLISION_SHARED_DATA:-$(cd .. && pwd)/shared/data}"
[ -f "$data/meshes/piano_room_rob.obj" ] || { echo "evaluate.sh: shared data not found in $data (set PCL_PROBCOLLISION_SHARED_DATA)" >&2; exit 2; }

bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build -j2 --target evaluate_collision calibration_drift
mkdir -p "$out"
start=$(date +%s)
build/evaluation/evaluate_collision --out "$out" --data "$data" "${quick[@]}"
build/evaluation/calibration_drift > "$out/drift.csv.tmp" && mv "$out/drift.csv.tmp" "$out/drift.csv"
echo "evaluate.sh: evaluation took $(( $(date +%s) - start )) s"

# The summary table as markdown (docs/RESULTS.md quotes it).
awk -F, 'NR == 1 { print "| workload | noise | method | setting | queries | easy | easy acc. | AUC | Brier (near) | flip rate | P std | median us | p90 us | max us | build ms | memory MB |";
                   print "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"; next }
         { mem = ($16 == "nan") ? "nan" : sprintf ("%.2f", $16 / 1e6);
           printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %.0f | %.0f | %.0f | %s | %s |\n",
                  $1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14, $15, mem }' \
  "$out/summary.csv" > "$out/summary.md"

gnuplot -e "dir='$out'" evaluation/charts.gp
for f in queries.csv summary.csv reliability.csv flips.csv model_size.csv summary.md drift.csv \
         accuracy_vs_time.png free_probability_vs_distance.png flip_rate_vs_noise.png \
         model_size_vs_accuracy.png reliability.png; do
  [ -s "$out/$f" ] || { echo "evaluate.sh: $out/$f missing or empty" >&2; exit 1; }
done
echo "evaluate.sh: results in $out"
