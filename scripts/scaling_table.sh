#!/usr/bin/env bash
# The scaling tables of docs/BENCHMARKS.md ("Scaling"): models of 10^4 .. 5*10^7 leaf faces, each
# encoded and decoded lossless and at 12 bits by bench/scaling_bench on one thread, RUNS times
# (default 3): file size, bits per face, median CPU time [range] and M faces/s, and each step's
# memory peak over what was resident before it (MiB, and bytes per node). Sizes are exact; times
# are CPU seconds (wall clock on a shared machine says little).
# Models (AMC_SCALING_MODEL): torus (default): random leaves of a torus refined, new vertices on a
# bumpy torus (scaling_bench make: linear time, any size); feline: feline remeshed by mean
# curvature as in scripts/chunks_table.sh (needs ../shared/data; the remesher takes minutes at
# 10^7 faces). AMC_SCALING_SIZES chooses the face counts, AMC_REUSE_MODELS=1 keeps models made
# before. The 5*10^7-face torus takes about 6 GB to make and to encode.
# Usage: scripts/scaling_table.sh [build-dir] [runs]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build-bench}
runs=${2:-3}
data=$here/../shared/data
sizes=${AMC_SCALING_SIZES:-"10000 100000 1000000 10000000 50000000"}
kind=${AMC_SCALING_MODEL:-torus}
models=$build/scaling-models
if [[ $kind == feline && ! -f $data/feline.off ]]; then
  echo "scaling_table.sh: $data/feline.off is absent" >&2
  exit 1
fi
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DAMC_BUILD_BENCH=ON -DAMC_BUILD_TESTS=OFF > /dev/null
cmake --build "$build" -j2 --target amc scaling_bench >&2
mkdir -p "$models"

# The finest level the remesh may use: two past the uniform level of that many faces over 500.
max_level_for() {
  local faces=$1 level=0 uniform=500
  while (( uniform < faces )); do uniform=$((uniform * 4)); level=$((level + 1)); done
  echo $((level + 2))
}
field() { tr ' ' '\n' <<< "$1" | sed -n "s/^$2=//p"; }

echo "| faces | nodes | bits | bytes | bits/face | encode CPU s [range] | encode M faces/s | encode peak MiB (B/node) | decode CPU s [range] | decode M faces/s | decode peak MiB (B/node) |"
echo "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
for faces in $sizes; do
  model=$models/${kind}_$faces.amh
  if [[ ${AMC_REUSE_MODELS:-0} != 1 || ! -s $model ]]; then
    if [[ $kind == feline ]]; then
      "$build/amc" -f -q refine --input "$data/feline.off" --criterion mean --faces "$faces" --base-faces 500 \
        --max-level "$(max_level_for "$faces")" --no-measure -o "$model"
    else
      "$build/bench/scaling_bench" make $((faces * 3 / 4)) "$model"  # about 4 faces for 3 leaves
    fi
  fi
  for bits in 0 12; do
    file=$models/${kind}_${faces}_$bits.amc
    e=$("$build/bench/scaling_bench" encode "$bits" "$runs" 1 "$model" "$file")
    d=$("$build/bench/scaling_bench" decode "$runs" 1 "$file")
    printf "| %s | %s | %s | %s | %s | %s [%s-%s] | %s | %s (%s) | %s [%s-%s] | %s | %s (%s) |\n" \
      "$(field "$e" faces)" "$(field "$e" nodes)" "$bits" "$(field "$e" bytes)" "$(field "$e" bits_per_face)" \
      "$(field "$e" cpu)" "$(field "$e" cpu_low)" "$(field "$e" cpu_high)" "$(field "$e" mfaces_per_s)" \
      "$(field "$e" step_peak_mib)" "$(field "$e" bytes_per_node)" \
      "$(field "$d" cpu)" "$(field "$d" cpu_low)" "$(field "$d" cpu_high)" "$(field "$d" mfaces_per_s)" \
      "$(field "$d" step_peak_mib)" "$(field "$d" bytes_per_node)"
    rm -f "$file"
  done
done
