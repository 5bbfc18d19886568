#!/usr/bin/env bash
# `amc series` and the series paths of encode, decode and info: a run of frames to .amcs and back
# through a ParaView collection, one frame by random access, exit codes 0/1/2, -f, -q, default
# names, truncated and foreign files; series of forests (.amq frames).
# Usage: cli_series.sh AMC
set -u
amc=$1
source "$(dirname "${BASH_SOURCE[0]}")/cli_lib.sh"

# Frames: a moving front, refined ahead and coarsened behind, as hierarchy files.
expect 0 "$amc" refine --model front --steps 6 --max-level 6 -o front.amh
expect 0 "$amc" extract front_0.amh --level 0 -o base.vtu

# Hierarchies -> series -> collection; default names.
expect 0 "$amc" series encode front_0.amh front_1.amh front_2.amh front_3.amh front_4.amh front_5.amh
[[ -s front_0.amcs ]] || fail "series encode wrote no front_0.amcs"
grep -q '6 frames' out.txt || fail "series encode does not report 6 frames: $(head -c 200 out.txt)"
expect 1 "$amc" series encode front_0.amh front_1.amh
grep -q 'already exists' err.txt || fail "series encode overwrote front_0.amcs"
expect 0 "$amc" series decode front_0.amcs
[[ -s front_0.pvd && -s front_0_5.vtu ]] || fail "series decode wrote no front_0.pvd + front_0_<k>.vtu"
[[ $(grep -c '<DataSet' front_0.pvd) == 6 ]] || fail "front_0.pvd does not list 6 frames"
expect 1 "$amc" series decode front_0.amcs
expect 0 "$amc" -f series decode front_0.amcs -q
[[ -s out.txt ]] && fail "-q printed: $(head -c 200 out.txt)"

# The collection (frames with the cell data "level" and "green") -> series with keyframes;
# `amc encode` of a .pvd is a series encode.
expect 0 "$amc" encode front_0.pvd --base base.vtu -o run.amcs
expect 0 "$amc" series encode front_0.pvd --base base.vtu -o key.amcs --keyframe 2 --fixed-keyframes
grep -q '3 keyframes' out.txt || fail "--keyframe 2 over 6 frames did not make 3 keyframes: $(head -c 300 out.txt)"
grep -q 'field green' out.txt || fail "the VTU cell data did not become fields"
expect 0 "$amc" series encode front_0.pvd --base base.vtu -o chosen.amcs --keyframe 2
expect 0 "$amc" series info chosen.amcs
grep -q 'amc series version 3' out.txt || fail "series info does not give the version: $(head -c 300 out.txt)"
# Without --base: the base found in the first frame.
expect 0 "$amc" series encode front_0.pvd -o nobase.amcs
expect 0 "$amc" series info nobase.amcs
[[ $(grep -cE '^ +[0-9]+ ' out.txt) -ge 6 ]] || fail "series encode without --base lost frames"
expect 0 "$amc" refine --model random --faces 2000 --seed 5 -o other.amh --leaf-mesh other.vtu
expect 1 "$amc" series encode front_0_1.vtu other.vtu -o mixed.amcs
grep -q 'without --base' err.txt || fail "a frame over another base does not hint at --base: $(head -c 300 err.txt)"

# Info, per frame.
expect 0 "$amc" info key.amcs
[[ $(grep -cE '^ +[0-9]+ ' out.txt) -ge 6 ]] || fail "info lists fewer than 6 frames"
grep -q 'decodes: yes' out.txt || fail "info did not decode the frames"
expect 0 "$amc" series info key.amcs --frame 3
grep -q 'fields of frame 3' out.txt || fail "series info --frame 3 describes no fields"

# Random access: frame 3 alone equals frame 3 of the whole decode, in every file.
expect 0 "$amc" series decode key.amcs -o all.pvd
expect 0 "$amc" decode key.amcs --frame 3 -o key3.vtu
expect 0 "$amc" series decode run.amcs --frame 3 -o run3.vtu
cmp -s key3.vtu all_3.vtu || fail "decode --frame 3 differs from frame 3 of the collection"
cmp -s run3.vtu all_3.vtu || fail "frame 3 differs between a file with keyframes and one without"
expect 0 "$amc" series decode key.amcs --frame 3 --level 2 -o key3_level2.vtu
expect 0 "$amc" series decode key.amcs --frame 4 -o key4.amh
expect 0 "$amc" info key4.amh
expect 1 "$amc" decode key.amcs --frame 6 -o x.vtu
grep -q 'frames 0..5' err.txt || fail "an absent frame is not named: $(head -c 200 err.txt)"
expect 1 "$amc" series decode key.amcs --frame 1 --level 30 -o x.vtu
# The nodes-per-byte bound: lowered below the frames' density it refuses, 0 lifts it.
expect 1 "$amc" series info key.amcs --max-nodes-per-byte 1
grep -q 'per byte' err.txt || fail "node bound: $(head -c 300 err.txt)"
expect 1 "$amc" series decode key.amcs --frame 3 --max-nodes-per-byte 1 -o x.vtu
expect 0 "$amc" series decode key.amcs --frame 3 --max-nodes-per-byte 0 -o bound0.vtu
cmp -s bound0.vtu all_3.vtu || fail "frame 3 read without the node bound differs"
expect 2 "$amc" series info key.amcs --max-nodes-per-byte -1

# Usage errors (2).
expect 0 "$amc" encode front_0.amh
expect 2 "$amc" series
expect 2 "$amc" series decode key.amcs -o x.amc
expect 2 "$amc" series decode key.amcs -o -
expect 2 "$amc" series encode front_0.pvd -o x.amc
expect 2 "$amc" series encode front_0.pvd --base base.vtu --field-bound level -o y.amcs
# A bound naming no field is refused, not ignored (the fields of front_0.pvd include "level").
expect 2 "$amc" series encode front_0.pvd --base base.vtu --field-bound levle=0.5 -o y.amcs
grep -q 'no frame has a field of that name' err.txt || fail "a bound naming no field: $(head -c 200 err.txt)"
expect 0 "$amc" series encode front_0.pvd --base base.vtu --field-bound level=0.5 -o named.amcs
expect 2 "$amc" series decode key.amcs --frame -1
expect 2 "$amc" decode front_0.amc --frame 1
expect 2 "$amc" encode front_0.pvd --quantize 12 -o z.amcs
[[ -e x.amc || -e y.amcs || -e z.amcs ]] && fail "an output was written after a usage error"

# Bad data (1): truncated, corrupted, not a series.
head -c 3000 key.amcs > cut.amcs
expect 1 "$amc" series info cut.amcs
grep -q 'truncated' err.txt || fail "a truncated series is not called truncated: $(head -c 200 err.txt)"
expect 0 "$amc" series info cut.amcs --partial
grep -q 'unfinished' out.txt || fail "--partial does not say the file is unfinished"
cp key.amcs bad.amcs
printf '\x00\x11\x22\x33' | dd of=bad.amcs bs=1 seek=2500 conv=notrunc 2> /dev/null
cmp -s key.amcs bad.amcs && fail "bad.amcs is not corrupted"
expect 1 "$amc" series decode bad.amcs -o bad.pvd
grep -q 'checksum' err.txt || fail "a corrupted series is not called a checksum error: $(head -c 200 err.txt)"
[[ -e bad.pvd ]] && fail "a collection was written for a corrupted series"
expect 1 "$amc" series info front_0.amh
grep -q 'expected a series' err.txt || fail "a hierarchy given to series info is not refused by kind"
echo "not a series" > junk.amcs
expect 1 "$amc" series info junk.amcs
expect 1 "$amc" extract key.amcs -o e.ply

# Forests (.amq frames) -> a forest series; one frame back as .amq (the same bytes as the input),
# all frames as a collection of VTU files; info; a bound refused; a forest series cut short.
expect 0 "$amc" octree make --dim 2 --model front --level 6 --trees 2x1 -o q0.amq
expect 0 "$amc" octree make --dim 2 --model front --level 7 --trees 2x1 -o q1.amq
expect 0 "$amc" octree make --dim 2 --model sphere --level 7 --trees 2x1 -o q2.amq
expect 0 "$amc" series encode q0.amq q1.amq q2.amq q1.amq -o forests.amcs
grep -q '4 forest frames' out.txt || fail "series encode of .amq frames does not report 4 forest frames: $(head -c 300 out.txt)"
expect 0 "$amc" series decode forests.amcs --frame 2 -o back2.amq
cmp -s q2.amq back2.amq || fail "frame 2 of the forest series is not the .amq file it came from"
expect 0 "$amc" series decode forests.amcs -o forests.pvd
[[ -s forests_3.vtu && $(grep -c '<DataSet' forests.pvd) == 4 ]] || fail "forest series decode wrote no collection of 4 VTU files"
expect 0 "$amc" series info forests.amcs
grep -q '2D forests of 2 trees' out.txt || fail "series info does not describe the forests: $(head -c 300 out.txt)"
expect 1 "$amc" series info forests.amcs --max-nodes-per-byte 1
expect 0 "$amc" series info forests.amcs --max-nodes-per-byte 0
expect 2 "$amc" series encode q0.amq q1.amq -o bounded.amcs --error-bound 0.1
expect 2 "$amc" series encode q0.amq front_1.amh -o mixed.amcs
head -c 200 forests.amcs > cutf.amcs
expect 1 "$amc" series decode cutf.amcs -o cutf.pvd
grep -q 'truncated' err.txt || fail "a truncated forest series is not called truncated: $(head -c 200 err.txt)"

finish cli_series
