#!/bin/sh
# .amc sizes at each encode effort (docs/CODEC.md, "Encode effort"): every model encoded by the amc
# binary AMC with --quantize BITS (0: bit-exact) at each effort from TOP (default: the highest
# `amc encode --help` offers) down to 0; one Markdown row per model with the exact file sizes and
# each size over effort TOP's.
#   [TOP=2] scripts/effort_table.sh AMC BITS corpus/*.amh
set -eu
amc=$1 bits=$2
shift 2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
max=${TOP:-$("$amc" encode --help | sed -n 's/.*--effort INT:INT in \[0 - \([0-9]*\)\].*/\1/p' | head -n 1)}
max=${max:-2}
printf '| model | bits |'
e=$max
while [ "$e" -ge 0 ]; do printf ' effort %s |' "$e"; e=$((e - 1)); done
e=$((max - 1))
while [ "$e" -ge 0 ]; do printf ' %s / %s |' "$e" "$max"; e=$((e - 1)); done
printf '\n|---|---:|'
e=0
while [ "$e" -lt $((2 * max + 1)) ]; do printf -- '---:|'; e=$((e + 1)); done
printf '\n'
for model in "$@"; do
  name=$(basename "$model" .amh)
  row="| $name | $bits |" sizes=""
  e=$max
  while [ "$e" -ge 0 ]; do
    "$amc" -q -f encode "$model" --quantize "$bits" --effort "$e" -o "$out/$name.amc"
    size=$(wc -c < "$out/$name.amc" | tr -d ' ')
    row="$row $size |"
    sizes="$sizes $size"
    e=$((e - 1))
  done
  echo "$row$(echo "$sizes" | awk '{ for (i = 2; i <= NF; ++i) printf " %.4f |", $i / $1 }')"
done
