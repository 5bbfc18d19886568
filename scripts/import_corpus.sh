#!/usr/bin/env bash
# The corpus check of issue 23 (docs/IMPORT.md, "The corpus check"): builds amc and
# bench/import_corpus (Release), makes the corpus of scripts/benchmarks.sh (the same models and
# commands) unless it exists, and prints the table: every model's leaf mesh, shuffled and moved,
# imported with its base (identical?) and without (connectivity against the true hierarchy's).
# Usage: scripts/import_corpus.sh [build-dir] [move]   (default build-bench and 0.3: every non-base
# vertex moved by up to move times its shortest edge per coordinate; the corpus goes to
# build-dir/bench-corpus, which scripts/benchmarks.sh remakes on each of its runs). The table goes
# to stdout, the build's output to stderr; exit status 1 if an import with the base is not identical.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build-bench}
move=${2:-0.3}
data=$here/../shared/data
corpus=$build/bench-corpus

cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DAMC_BUILD_BENCH=ON -DAMC_BUILD_TESTS=OFF > /dev/null
cmake --build "$build" -j2 --target amc import_corpus >&2
amc=$build/amc

if [[ ! -d $corpus ]] || ! compgen -G "$corpus/*.amh" > /dev/null; then
  source "$here/scripts/corpus.sh"
  make_corpus "$amc" "$data" "$corpus"
fi
"$build/bench/import_corpus" --move "$move" "$corpus"/*.amh
