#!/usr/bin/env bash
# The byte check of encoder changes: md5 of `amc encode` of every hierarchy in CORPUS_DIR (the
# corpus of scripts/corpus.sh, make_corpus) bit-exactly and at 12 and 16 bits, one line per file
# ("md5 model.bits", 72 lines for the 24-model corpus). Two builds' outputs compared with diff.
# Usage: scripts/corpus_hashes.sh AMC CORPUS_DIR > hashes.txt
set -euo pipefail
amc=$1
corpus=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for file in "$corpus"/*.amh; do
  model=$(basename "$file" .amh)
  for bits in 0 12 16; do
    "$amc" -f -q encode "$file" --quantize "$bits" -o "$tmp/x.amc"
    echo "$(md5sum < "$tmp/x.amc" | cut -c1-32) $model.$bits"
  done
done
