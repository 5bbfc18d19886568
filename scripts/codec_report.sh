#!/usr/bin/env bash
# Builds the corpus (scripts/hierarchy_coder_tables.sh) and prints the .amc report of every model:
# sizes by part, lossless and at 16 and 12 bits, median encode/decode speeds of 3 runs.
# Usage: scripts/codec_report.sh [build-dir] [corpus-dir]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
out=${2:-$here/build/corpus}
"$here/scripts/hierarchy_coder_tables.sh" "$build" "$out" > /dev/null
"$build/amc" report "$out"/*.amh --runs 3
