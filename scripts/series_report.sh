#!/usr/bin/env bash
# The figures of docs/SERIES.md: bench/series_bench on the adaptive heat runs (L-shape, rotating
# source) and the moving front, the same sequence with keyframes, and the speed on frames of about
# 10^5 faces, each speed measured in several runs (ranges). Sizes are deterministic; times are CPU
# seconds. Needs a build with -DAMC_BUILD_BENCH=ON (scripts/install-deps.sh --bench: zstd, xz, zfp).
#
#   scripts/series_report.sh [BUILD_DIR] [RUNS] > series_report.txt
set -euo pipefail
build=${1:-build}
runs=${2:-3}
bench="$build/bench/series_bench"
[[ -x $bench ]] || { echo "no $bench: cmake -S . -B $build -DAMC_BUILD_BENCH=ON && cmake --build $build -j2" >&2; exit 1; }
echo "# scripts/series_report.sh $build $runs on $(uname -m), $(nproc) cores, $(date -u +%Y-%m-%d)"
echo
run() { nice -n 19 "$bench" "$@"; echo; }
run --scenario lshape --frames 100 --repeat "$runs"
run --scenario rotating --frames 100 --repeat "$runs"
run --scenario front --frames 100 --max-level 8 --repeat "$runs"
run --scenario lshape --frames 100 --keyframe 10 --repeat "$runs" --speed-only 1
run --scenario lshape --frames 20 --target 100000 --max-level 12 --repeat "$runs" --speed-only 1
