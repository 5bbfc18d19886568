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
err=$(mktemp)
trap 'rm -f "$rows" "$err"' EXIT
"$tool" --header --remesh mean > "$rows"
for mesh in "$data"/*.obj "$data"/*.off; do
    [ -e "$mesh" ] || continue
    # A mesh the remesher refuses keeps its row, with the reason.
    if ! "$tool" --remesh mean "$@" "$mesh" >> "$rows" 2> "$err"; then
        printf '%s\trefused: %s\n' "$(basename "$mesh")" "$(tail -n 1 "$err" | tr '\t|' '  ')" >> "$rows"
    fi
    cat "$err" >&2
done
cat "$rows"
echo
awk -F'\t' '
NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
function c(name) { return $(col[name]) }
NF == 2 { printf "| %s | %s |\n", $1, $2; next }
BEGIN {
    print "| mesh | input faces | base (attempts) | base distance | fold-overs in / out | coincident in / out | worst quality in / out | max distance (certified bound) | RMS distance | faces asked / made | float32 | CPU s |"
    print "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|:-:|---:|"
}
{
    printf "| %s | %s | %s (%s) | %s | %s / %s | %s / %s | %s / %s | %s (%s) | %s | %s / %s | %s | %s |\n",
        c("file"), c("input_faces"), c("base"), c("base_attempts"), c("base_distance"), c("input_folds"), c("folds"),
        c("input_coincident"), c("coincident"), c("input_min_quality"), c("min_quality"), c("max"), c("max_upper"),
        c("rms"), c("asked"), c("faces"), c("float32") == 1 ? "yes" : "no", c("cpu_s")
}' "$rows"
