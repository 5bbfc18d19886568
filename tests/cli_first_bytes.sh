#!/usr/bin/env bash
# Inputs judged on their first bytes: an endless stream or a large file that cannot be a file amc
# reads is refused at once (exit 1, the usual message), not read until memory runs out; valid
# inputs longer than those first bytes still read whole, from stdin too. Each refusal runs under a
# memory cap (1 GB of address space) and a time limit, which the old whole-input reads ran into.
# Usage: cli_first_bytes.sh AMC
set -u
amc=$1
source "$(dirname "${BASH_SOURCE[0]}")/cli_lib.sh"

# `expect_refused MESSAGE STDIN CMD...`: exit 1 and MESSAGE on stderr, under the cap; STDIN is
# "endless" (the output of yes) or "none".
expect_refused() {
  local message=$1 input=$2; shift 2
  if [[ $input == endless ]]; then
    (ulimit -v 1000000; yes | timeout 60 "$@") > out.txt 2> err.txt
  else
    (ulimit -v 1000000; timeout 60 "$@" < /dev/null) > out.txt 2> err.txt
  fi
  local got=$?
  [[ $got == 1 ]] || fail "'$*' exited $got, expected 1; stderr: $(head -c 300 err.txt)"
  grep -qF -- "$message" err.txt || fail "'$*': expected '$message' on stderr, got: $(head -c 300 err.txt)"
}

expect_refused "stdin: not a file amc reads" endless "$amc" info -
expect_refused "stdin: not a file amc reads" endless "$amc" decode - -o x.ply
expect_refused "stdin: not a file amc reads" endless "$amc" series info -
expect_refused "-: not an .amq file (bad magic)" endless "$amc" octree info -
expect_refused "-: not an .amq file (bad magic)" endless "$amc" octree decode - -o x.vtu
expect_refused "/dev/zero: not an .amq file (bad magic)" none "$amc" octree decode /dev/zero -o x.vtu
truncate -s 2G zeros.bin  # sparse: 2 GB of zeros, more than the cap
expect_refused "zeros.bin: not a file amc reads" none "$amc" info zeros.bin
expect_refused "zeros.bin: not an .amq file (bad magic)" none "$amc" octree info zeros.bin
[[ -e x.ply || -e x.vtu ]] && fail "a refused input left an output"

# Valid inputs longer than the first bytes judged (64 KiB), from stdin and from files.
expect 0 "$amc" refine --model random --faces 40000 --seed 3 -o r.amh --leaf-mesh r.obj
expect 0 "$amc" encode r.obj -o r.amc --quantize 0
expect 0 "$amc" octree make --dim 2 --model random --level 5 --trees 100x100 -o f.amq
for file in r.amh r.obj r.amc f.amq; do
  (( $(stat -c %s "$file") > 65536 )) || fail "$file is not longer than 64 KiB"
done
"$amc" info - < r.amh > piped.txt 2>&1 || fail "info - < r.amh: $(head -c 300 piped.txt)"
grep -q "faces" piped.txt || fail "info - < r.amh printed: $(head -c 300 piped.txt)"
"$amc" -q encode - -o piped.amc --quantize 0 < r.obj 2> err.txt || fail "encode - < r.obj: $(head -c 300 err.txt)"
"$amc" -q encode r.obj -o file.amc --quantize 0 2> err.txt || fail "encode r.obj: $(head -c 300 err.txt)"
cmp -s piped.amc file.amc || fail "encode of r.obj from stdin and from the file differ"
"$amc" octree decode - -o piped.vtu < f.amq 2> err.txt || fail "octree decode - < f.amq: $(head -c 300 err.txt)"
"$amc" octree decode f.amq -o file.vtu 2> err.txt || fail "octree decode f.amq: $(head -c 300 err.txt)"
cmp -s piped.vtu file.vtu || fail "octree decode of f.amq from stdin and from the file differ"
"$amc" decode - -o - < r.amc > piped.ply 2> err.txt || fail "decode - < r.amc: $(head -c 300 err.txt)"
"$amc" -q decode r.amc -o file.ply 2> err.txt || fail "decode r.amc: $(head -c 300 err.txt)"
cmp -s piped.ply file.ply || fail "decode of r.amc to stdout and to a file differ"

finish cli_first_bytes
