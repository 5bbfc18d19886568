#!/usr/bin/env bash
# The figures of docs/SERIES.md: bench/series_bench on the adaptive heat runs (L-shape, rotating
# source) and the moving front, the same sequence with keyframes, and the speed on frames of about
# 10^5 faces, each speed measured in several runs (ranges); the front's motion study
# (series_motion_study); then the forest series (forest_series_bench). Sizes are deterministic; times are CPU
# seconds. Needs a build with -DAMC_BUILD_BENCH=ON (scripts/install-deps.sh --bench: zstd, xz, zfp).
#
#   scripts/series_report.sh [BUILD_DIR] [RUNS] [ELEMENTS] > series_report.txt
#
# ELEMENTS (default 5000) is the heat runs' target mesh size; the peers (xz -9 above all) cost
# about 2 CPU s a frame at 20000.
set -euo pipefail
build=${1:-build}
runs=${2:-3}
elements=${3:-5000}
bench="$build/bench/series_bench"
[[ -x $bench ]] || { echo "no $bench: cmake -S . -B $build -DAMC_BUILD_BENCH=ON && cmake --build $build -j2" >&2; exit 1; }
echo "# scripts/series_report.sh $build $runs on $(uname -m), $(nproc) cores, $(date -u +%Y-%m-%d)"
echo
run() { nice -n 19 "$bench" "$@"; echo; }
# The comparison with the peers (zstd -19, xz -9, zfp) on the L-shape run: the costly part.
run --scenario lshape --frames 100 --target "$elements" --repeat "$runs"
# Speed on frames of about 10^5 faces (57,000-188,000, 134,000 on average).
run --scenario lshape --frames 8 --target 140000 --max-level 12 --repeat "$runs" --speed-only 1
# The other sequences, without the peers: sizes against independent .amc files, changed nodes,
# and every frame's connectivity against the frame alone by share of nodes changed.
run --scenario front --frames 100 --max-level 8 --repeat "$runs" --peers 0
run --scenario rotating --frames 100 --target "$elements" --repeat "$runs" --peers 0
# Smaller output intervals (dt five times smaller: the first fifth of the source's path), and the
# front advancing half a finest element and two finest elements a step (CFL-like).
run --scenario lshape --frames 100 --target "$elements" --end-time 0.2 --repeat 1 --peers 0
run --scenario rotating --frames 100 --target "$elements" --end-time 0.2 --repeat 1 --peers 0
run --scenario front-cfl --frames 100 --max-level 8 --cfl 0.5 --repeat 1 --peers 0
run --scenario front-cfl --frames 100 --max-level 8 --cfl 2 --repeat 1 --peers 0
# Random access with a keyframe every 10 frames.
run --scenario lshape --frames 100 --target "$elements" --keyframe 10 --repeat "$runs" --speed-only 1
# The inter-frame connectivity's context designs: H(X|ctx) and adaptive code lengths.
designs="$build/bench/series_context_designs"
[[ -x $designs ]] && { nice -n 19 "$designs" --scenario lshape --frames 100 --target "$elements"; echo; }
# Motion-compensated prediction of the front's refinement (H(X|ctx) and adaptive code lengths per
# prediction): the model's step, and the CFL-like steps with pixels fine enough for their motion.
motion="$build/bench/series_motion_study"
if [[ -x $motion ]]; then
  nice -n 19 "$motion" --scenario front --frames 100 --max-level 8; echo
  nice -n 19 "$motion" --scenario front-cfl --cfl 0.5 --frames 100 --max-level 8 --subpixels 2 --search 16; echo
  nice -n 19 "$motion" --scenario front-cfl --cfl 0.5 --frames 100 --max-level 8 --subpixels 4 --search 16 --block 128; echo
  nice -n 19 "$motion" --scenario front-cfl --cfl 2 --frames 100 --max-level 8 --search 16; echo
fi
# Forest series (issue 28): a p4est-like moving front in 2D and 3D against .amq and p4est_save files.
forests="$build/bench/forest_series_bench"
if [[ -x $forests ]]; then
  # Half a finest leaf a frame, and a larger step (4 leaves in 2D; 1 in 3D, where 100 frames of 4
  # would carry the front out of the domain).
  for run in "2 0.5" "2 4" "3 0.5" "3 1"; do
    set -- $run
    nice -n 19 "$forests" --dim "$1" --frames 100 --cfl "$2"; echo
  done
fi
