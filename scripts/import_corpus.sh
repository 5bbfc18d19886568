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
  mkdir -p "$corpus"
  if [[ -d $data ]]; then
    while read -r model file mean_faces gauss_faces; do
      for criterion in mean gauss; do
        faces=$mean_faces
        [[ $criterion == gauss ]] && faces=$gauss_faces
        "$amc" -f refine --input "$data/$file" --criterion "$criterion" --faces "$faces" --base-faces 500 --max-level 5 \
          -o "$corpus/${model}_$criterion.amh" > /dev/null
      done
    done <<'LIST'
bunny-hr    bunny-hr.obj    100000 100000
horse       horse.obj       100000 100000
feline      feline.off      250000 200000
venus       venus.off       140000 140000
fandisk     fandisk.obj     100000 100000
rocker-arm  rocker-arm.obj  100000 100000
femur       femur.obj       100000 100000
camelhead   camelhead.off   100000 100000
mountain    mountain.obj    100000 100000
LIST
  else
    echo "note: $data is absent; the remeshed surface models are skipped" >&2
  fi
  "$amc" -f refine --model lshape --max-level 10 -o "$corpus/lshape.amh" > /dev/null
  "$amc" -f refine --model front --steps 3 --max-level 9 -o "$corpus/front" > /dev/null
  "$amc" -f refine --model uniform --levels 7 -o "$corpus/uniform.amh" > /dev/null
  "$amc" -f refine --model random --faces 150000 --seed 7 -o "$corpus/random.amh" > /dev/null
fi
"$build/bench/import_corpus" --move "$move" "$corpus"/*.amh
