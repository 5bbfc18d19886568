#!/usr/bin/env bash
# Checks that this tree decodes what older amcodec builds wrote. For each COMMIT:VERSION it builds
# that commit's library in a temporary directory, writes test vectors with it
# (scripts/compat/write_vectors.cpp: SEEDS random hierarchies over five bases, their hierarchy
# streams under all 64 coder switch combinations, .amc files lossless, naive, butterfly and
# quantized) and decodes them with this tree (scripts/compat/check_vectors.cpp), reading the
# commit's untagged hierarchy streams as stream VERSION. About 3 minutes per commit on 2 cores.
# Usage: scripts/check_old_versions.sh [SEEDS [COMMIT:VERSION ...]]
# Default: 40 seeds; the first and the last commit of .amc version 1 and the last untagged one of
# version 2.
set -euo pipefail
cd "$(dirname "$0")/.."
seeds=${1:-40}
shift || true
pairs=("$@")
if ((${#pairs[@]} == 0)); then
  pairs=(7146847:1 31e1487:1 73985d0:2)
fi
scripts/install-deps.sh --compat
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake -S scripts/compat -B "$work/new" -DAMC_SOURCE="$PWD" -DPROGRAM=check_vectors -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/new" -j2 --target check_vectors >/dev/null
status=0
for pair in "${pairs[@]}"; do
  commit=${pair%%:*}
  version=${pair##*:}
  mkdir -p "$work/$commit/src" "$work/$commit/vectors"
  git archive "$commit" | tar -x -C "$work/$commit/src"
  cmake -S scripts/compat -B "$work/$commit/build" -DAMC_SOURCE="$work/$commit/src" -DPROGRAM=write_vectors \
    -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$work/$commit/build" -j2 --target write_vectors >/dev/null
  echo "== $commit ($(git log -1 --format='%ad %s' --date=short "$commit" | cut -c1-80))"
  "$work/$commit/build/write_vectors" "$work/$commit/vectors" "$seeds"
  "$work/new/check_vectors" "$work/$commit/vectors" "$version" || status=1
done
exit $status
