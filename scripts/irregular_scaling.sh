#!/usr/bin/env bash
# Plain irregular meshes at growing sizes, encoded as users run `amc` (docs/BASE_CODER.md, "Large
# meshes and the walk budget"): `scaling_bench make-mesh FACES` (an irregular torus), then `amc
# encode` and `amc decode` once each; prints a markdown row per size with the base connectivity's
# bytes and bits per base triangle, the file's bytes, and CPU seconds and peak memory of each step.
#   scripts/irregular_scaling.sh [BUILD_DIR (build)] [AMC (BUILD_DIR/amc)] [FACES ... (10^4 .. 4*10^6)]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
amc=${2:-$build/amc}
shift $(( $# < 2 ? $# : 2 ))
sizes=("$@")
(( ${#sizes[@]} )) || sizes=(10000 100000 1000000 2000000 4000000)
[[ -x $build/bench/scaling_bench ]] || { echo "no $build/bench/scaling_bench: configure with -DAMC_BUILD_BENCH=ON" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "| faces | base triangles | base connectivity bytes | bits per base triangle | file bytes | encode CPU s | encode peak MiB | decode CPU s | decode peak MiB |"
echo "|--:|--:|--:|--:|--:|--:|--:|--:|--:|"
for faces in "${sizes[@]}"; do
  "$build/bench/scaling_bench" make-mesh "$faces" "$tmp/m.ply"
  enc=$( { /usr/bin/time -f "%U %S %M" "$amc" -f -q encode --threads 1 "$tmp/m.ply" -o "$tmp/m.amc"; } 2>&1 | tail -1)
  dec=$( { /usr/bin/time -f "%U %S %M" "$amc" -f -q decode --threads 1 "$tmp/m.amc" -o "$tmp/d.ply"; } 2>&1 | tail -1)
  info=$("$amc" -v info "$tmp/m.amc")
  base=$(sed -n 's/.*base mesh [0-9]* vertices, \([0-9]*\) triangles.*/\1/p' <<< "$info")
  conn=$(awk '$1 == "base" && $2 == "connectivity" {print $4}' <<< "$info")
  total=$(stat -c %s "$tmp/m.amc")
  read -r eu es em <<< "$enc"
  read -r du ds dm <<< "$dec"
  awk -v f="$faces" -v b="$base" -v c="$conn" -v t="$total" -v eu="$eu" -v es="$es" -v em="$em" \
      -v du="$du" -v ds="$ds" -v dm="$dm" 'BEGIN {
    printf "| %d | %d | %d | %.3f | %d | %.2f | %.0f | %.2f | %.0f |\n", f, b, c, 8 * c / b, t, eu + es, em / 1024, du + ds, dm / 1024 }'
done
