#!/usr/bin/env bash
# The remesher table of docs/REMESHER.md: every mesh of the shared data remeshed with
# remesh_adaptively (bench/remesh_quality --remesh, the defaults of `amc refine --model surface`:
# base 500, 150000 faces, max level 7, mean curvature) and measured against its input.
# Prints the tab-separated rows, then the same as a Markdown table.
# Usage: scripts/remesher_table.sh [build-dir] [data-dir] [extra remesh_quality options...]
# Needs a build with -DAMC_BUILD_BENCH=ON. Runs one mesh after another (minutes in all).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
data=${2:-$here/../shared/data}
shift $(( $# > 2 ? 2 : $# ))
tool="$build/bench/remesh_quality"
[ -x "$tool" ] || { echo "remesher_table.sh: $tool is missing (configure with -DAMC_BUILD_BENCH=ON)" >&2; exit 1; }
rows=$(mktemp)
trap 'rm -f "$rows"' EXIT
"$tool" --header --remesh mean > "$rows"
for mesh in "$data"/*.obj "$data"/*.off; do
    [ -e "$mesh" ] || continue
    "$tool" --remesh mean "$@" "$mesh" >> "$rows"
done
cat "$rows"
echo
awk -F'\t' '
NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
function c(name) { return $(col[name]) }
BEGIN {
    print "| mesh | input faces | base (attempts) | folds in / out (of them inherited) | coincident | degenerate | worst quality | max distance (certified bound) | RMS distance | faces asked / made | float32 | CPU s |"
    print "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|:-:|---:|"
}
{
    printf "| %s | %s | %s (%s) | %s / %s (%s) | %s | %s | %s | %s (%s) | %s | %s / %s | %s | %s |\n",
        c("file"), c("input_faces"), c("base"), c("base_attempts"), c("input_folds"), c("folds"), c("inherited"),
        c("coincident"), c("degenerate"), c("min_quality"), c("max"), c("max_upper"), c("rms"), c("asked"), c("faces"),
        c("float32") == 1 ? "yes" : "no", c("cpu_s")
}' "$rows"
