#!/bin/sh
# Sizes and speeds of complete .amc files, two builds side by side (docs/CODEC.md, "Geometry mode
# 3"): for each model and coordinate mode, bench/codec_speed of build A, then of build B, in turn,
# so that both see the same load. Prints one Markdown row per model and mode.
#   scripts/codec_speed_table.sh CODEC_SPEED_A CODEC_SPEED_B RUNS corpus/*.amh
# (CODEC_SPEED_A: e.g. bench/codec_speed built against an older tree: it uses only <amc/codec.h>.)
set -eu
a=$1 b=$2 runs=$3
shift 3
echo "| model | coordinates | bytes A | bytes B | B / A | bits/vertex A | bits/vertex B | encode A | encode B | decode A | decode B |"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
for model in "$@"; do
  for bits in 12 16 0; do
    ra=$("$a" "$runs" "$bits" "$model" | tail -1)
    rb=$("$b" "$runs" "$bits" "$model" | tail -1)
    printf '%s\n%s\n' "$ra" "$rb" | awk -F'|' -v bits="$bits" '
      NR == 1 { name = $2; ba = $5; va = $6; ea = $7; da = $8 }
      NR == 2 { gsub(/ /, "", name); mode = bits == 0 ? "lossless" : bits " bits";
                printf "| %s | %s | %d | %d | %.3f | %.2f | %.2f | %s | %s | %s | %s |\n",
                       name, mode, ba, $5, $5 / ba, va, $6, ea, $7, da, $8 }'
  done
done
