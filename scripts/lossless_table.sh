#!/bin/sh
# Bit-exact .amc sizes, builds side by side (docs/CODEC.md, "Geometry mode 5"): every model encoded
# with default options (bit-exact coordinates) by each amc binary given before `--`; one Markdown
# row per model with the exact file sizes and the last build's size over the first's.
#   scripts/lossless_table.sh AMC_A AMC_B ... -- corpus/*.amh
set -eu
builds=""
while [ "$1" != "--" ]; do builds="$builds $1"; shift; done
shift
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
printf '| model |'
for b in $builds; do printf ' %s |' "$b"; done
printf ' last / first |\n|---|'
for b in $builds; do printf -- '---:|'; done
printf -- '---:|\n'
for model in "$@"; do
  name=$(basename "$model" .amh)
  row="| $name |" first="" last=""
  for b in $builds; do
    "$b" -q -f encode "$model" -o "$out/$name.amc"
    size=$(wc -c < "$out/$name.amc" | tr -d ' ')
    row="$row $size |"
    first=${first:-$size} last=$size
  done
  echo "$row $(awk -v a="$first" -v b="$last" 'BEGIN { printf "%.3f", b / a }') |"
done
