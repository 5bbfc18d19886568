#!/usr/bin/env bash
# `amc octree make | encode | decode | info`: forests to .amq and back, VTU output, progressive
# decoding, exit codes 0/1/2, -f, truncated and foreign files.
# Usage: cli_octree.sh AMC
set -u
amc=$1
source "$(dirname "${BASH_SOURCE[0]}")/cli_lib.sh"

expect 0 "$amc" octree make --dim 3 --model sphere --level 5 --trees 2x2x1 -o sphere.amq
[[ -s sphere.amq ]] || fail "make wrote no sphere.amq"
expect 0 "$amc" octree info sphere.amq
grep -q '3D forest of 4 trees' out.txt || fail "info: $(head -c 200 out.txt)"
grep -q 'face balanced: yes' out.txt || fail "info does not see a balanced forest: $(head -c 300 out.txt)"
expect 0 "$amc" octree decode sphere.amq
grep -q 'NumberOfCells' sphere.vtu || fail "decode wrote no VTU cells"
expect 1 "$amc" octree decode sphere.amq
grep -q 'already exists' err.txt || fail "decode overwrote sphere.vtu"
expect 0 "$amc" -f octree decode sphere.amq --level 2 -o coarse.vtu
# --conforming: tetrahedra (VTK type 10) and triangles (5) instead of hexahedra and quads.
expect 0 "$amc" octree decode sphere.amq --conforming -o tets.vtu
grep -q 'Name="added_point"' tets.vtu || fail "conforming VTU without its point array"
expect 0 "$amc" octree make --dim 2 --model sphere --level 4 --conforming -o tris.vtu
expect 0 "$amc" octree make --dim 2 --model sphere --level 4 -o quads.vtu
cells() { sed -n 's/.*NumberOfCells="\([0-9]*\)".*/\1/p' "$1"; }
(( $(cells tris.vtu) > 2 * $(cells quads.vtu) )) || fail "conforming: $(cells tris.vtu) triangles for $(cells quads.vtu) quads"
expect 2 "$amc" octree decode sphere.amq --conforming -o x.p4est
expect 2 "$amc" octree make --dim 2 --conforming -o x.amq
expect 0 "$amc" octree make --dim 2 --model front --level 7 --balance corner -o - 
[[ -s out.txt ]] || fail "make to stdout wrote nothing"
cp out.txt front.amq
expect 0 "$amc" octree info - < front.amq
grep -q '2D forest of 1 trees' out.txt || fail "info of stdin: $(head -c 200 out.txt)"
# The octants-per-byte bound: lowered below the file's density it refuses, 0 lifts it.
expect 1 "$amc" octree info sphere.amq --max-octants-per-byte 1
grep -qi 'octants' err.txt || fail "octant bound: $(head -c 300 err.txt)"
expect 0 "$amc" octree info sphere.amq --max-octants-per-byte 0
expect 2 "$amc" octree info sphere.amq --max-octants-per-byte -1
# Bad input: truncated, foreign, and usage errors.
head -c 40 sphere.amq > cut.amq
expect 1 "$amc" octree info cut.amq
expect 1 "$amc" octree decode sphere.vtu -o x.vtu
expect 2 "$amc" octree make --dim 4 -o x.amq
expect 2 "$amc" octree make --model moon -o x.amq
expect 2 "$amc" octree decode sphere.amq -o x.amq
expect 2 "$amc" octree encode sphere.amq --data u:Float64 -o x.amq
expect 2 "$amc" octree encode sphere.amq --vertex-step -1 -o x.amq
expect 0 "$amc" octree encode sphere.amq --vertex-step 0.25 -o again.amq
cmp -s sphere.amq again.amq || fail "re-encoding a brick forest changed its bytes"

finish cli_octree
