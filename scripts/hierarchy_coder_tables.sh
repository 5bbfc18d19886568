#!/usr/bin/env bash
# Builds the hierarchy-coder corpus from ../shared/data (analogues of the paper's models, with the
# paper's face counts as targets) plus the planar FE models, and prints Tables 1 and 2 with
# `amc stats`. Usage: scripts/hierarchy_coder_tables.sh [build-dir] [out-dir]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
out=${2:-$here/build/corpus}
data=$here/../shared/data
amc=$build/amc
mkdir -p "$out"
if [[ ! -d $data ]]; then
  echo "note: $data is absent; only the procedural models are made" >&2
else
  # model        input             criterion  faces
  while read -r name input criterion faces; do
    "$amc" -f refine --input "$data/$input" --criterion "$criterion" --faces "$faces" --base-faces 500 \
      --max-level 5 -o "$out/$name.amh" > /dev/null
  done <<'LIST'
bunny          bunny-hr.obj    mean   90771
fandisk        fandisk.obj     mean   86092
feline_gauss   feline.off      gauss  199008
feline_mean    feline.off      mean   254044
femur          femur.obj       mean   8944
horse          horse.obj       mean   96368
rabbit         bunny-hr.obj    gauss  68506
venus          venus.off       gauss  138672
LIST
fi
"$amc" -f refine --model lshape --max-level 10 -o "$out/lshape.amh" > /dev/null
"$amc" -f refine --model front --steps 3 --max-level 9 -o "$out/front" > /dev/null
"$amc" stats "$out"/*.amh --groups
