#!/usr/bin/env bash
# The command-line conventions of `amc` (those of zstd and xz): exit codes 0/1/2, default output
# names, refusal to overwrite without -f, - for stdin and stdout, input kind from magic bytes,
# output kind from the extension, range checks, -q, --version, the numbering restored.
# Usage: cli_conventions.sh AMC DATA_DIR
set -u
amc=$1
data=$2
source "$(dirname "${BASH_SOURCE[0]}")/cli_lib.sh"
# The mesh of an OBJ file without comments: vertices and faces as numbers.
mesh_of() { grep -v '^#' "$1" | awk '{print $1, $2 + 0, $3 + 0, $4 + 0}'; }

expect 0 "$amc" --version
grep -q '^amc [0-9]' out.txt || fail "--version prints no version"
expect 2 "$amc"
expect 2 "$amc" encode
expect 2 "$amc" encode --no-such-option x
expect 0 "$amc" --help
grep -q 'Examples' out.txt || fail "--help shows no examples"

# A plain mesh and a hierarchy to work on.
expect 2 "$amc" refine --model random --faces 3000 --seed 3
expect 0 "$amc" refine --model random --faces 3000 --seed 3 -o r.amh --leaf-mesh r.obj
expect 1 "$amc" refine --model random --faces 3000 --seed 3 -o r.amh
expect 0 "$amc" -f refine --model random --faces 3000 --seed 3 -o r.amh
expect 0 "$amc" refine --model front --steps 2 --max-level 5 -o front.amh
[[ -f front_0.amh && -f front_1.amh ]] || fail "refine --model front -o front.amh wrote no front_0.amh, front_1.amh"
expect 2 "$amc" refine --model lshape --max-level 40 -o l.amh

# The base search's threads change no byte of the hierarchy (the second search, run beside the
# first on two threads, is cancelled or kept exactly as one thread would).
expect 0 "$amc" import r.obj -o import1.amh --threads 1
expect 0 "$amc" import r.obj -o import2.amh --threads 2
cmp -s import1.amh import2.amh || fail "import --threads 2 wrote another hierarchy than --threads 1"
expect 0 "$amc" encode r.obj -o import1.amc --threads 1
expect 0 "$amc" encode r.obj -o import2.amc --threads 2
cmp -s import1.amc import2.amc || fail "encode of a mesh --threads 2 wrote another file than --threads 1"

# Progress only on a terminal: a run of a few seconds with stderr in a file leaves it empty.
expect 0 "$amc" refine --model random --faces 600000 --max-level 9 -o big.amh
[[ -s err.txt ]] && fail "progress or messages written to stderr that is not a terminal: $(head -c 200 err.txt)"

# Default names, refusal, -f.
expect 0 "$amc" encode r.amh
[[ -s r.amc ]] || fail "encode r.amh wrote no r.amc"
expect 1 "$amc" encode r.amh
grep -q 'already exists' err.txt || fail "refusal does not say the file exists"
expect 0 "$amc" encode -f r.amh
expect 0 "$amc" encode r.amh -o r2.amc -q
[[ -s out.txt ]] && fail "-q printed: $(head -c 200 out.txt)"
expect 0 "$amc" decode r.amc
[[ -s r.ply ]] || fail "decode r.amc wrote no r.ply"
expect 2 "$amc" encode r.amh -o r.obj
[[ -e r.obj.tmp* ]] && fail "a temporary file was left"
expect 2 "$amc" decode r.amc -o x.amc
expect 2 "$amc" decode r.amc -o x.bin
[[ -e x.bin ]] && fail "decode wrote x.bin after refusing it"

# Ranges, the same in every subcommand.
expect 2 "$amc" decode r.amc -o l.ply --level -5
expect 2 "$amc" decode r.amc -o l.ply --level 99
expect 1 "$amc" decode r.amc -o l.ply --level 29
[[ -e l.ply ]] && fail "decode --level past the depth wrote l.ply"
expect 1 "$amc" extract r.amh -o l.ply --level 29
expect 0 "$amc" decode r.amc -o l1.vtu --level 1
expect 2 "$amc" encode r.amh -o q.amc --quantize 31

# --traversal naive: another file, the same hierarchy back.
expect 0 "$amc" encode front_1.amh -o tn.amc --traversal naive --quantize 12
expect 0 "$amc" encode front_1.amh -o ti.amc --quantize 12
cmp -s tn.amc ti.amc && fail "--traversal naive wrote the file of the improved traversal"
expect 0 "$amc" decode tn.amc -o tn.amh
expect 0 "$amc" decode ti.amc -o ti.amh
cmp -s tn.amh ti.amh || fail "the naive traversal's file decodes to another hierarchy"
expect 2 "$amc" encode front_1.amh -o tx.amc --traversal sideways
# A series (here of one frame) is coded in the improved traversal: naming it is no usage error,
# naming naive is.
expect 0 "$amc" encode --series front_1.amh -o tx.amcs --traversal improved
expect 2 "$amc" encode --series front_1.amh -o tx.amcs --traversal naive

# Kinds from magic bytes, not from names.
cp r.amc renamed.bin
expect 0 "$amc" info renamed.bin
grep -q 'amc version' out.txt || fail "info did not see .amc data in renamed.bin"
expect 0 "$amc" info "$data/tetrahedron_off_no_extension"
grep -q '4 vertices, 4 triangles' out.txt || fail "info did not read the OFF file without extension"
expect 1 "$amc" decode r.amh -o x.ply
grep -q 'expected compressed' err.txt || fail "decode of a hierarchy says: $(cat err.txt)"

# stdin and stdout.
"$amc" encode - -q < r.amh > s.amc || fail "encode - > s.amc"
cmp -s s.amc r.amc || fail "encode from stdin differs from encode from the file"
"$amc" decode - -o - --format obj -q < r.amc > s.obj || fail "decode - -o -"
expect 0 "$amc" decode r.amc -o d.obj -q
cmp -s s.obj d.obj || fail "decode to stdout differs from decode to a file"

# A plain mesh in, its own numbering back.
expect 0 "$amc" encode r.obj -o m.amc --keep-numbering --map m.map
expect 0 "$amc" decode m.amc -o m.obj
diff -q <(mesh_of m.obj) <(mesh_of r.obj) > /dev/null || fail "decode of --keep-numbering is not the input mesh"
head -1 m.map | grep -q 'amc-numbering-map 1' || fail "encode --map wrote no map"
# Base detection undoes part of a random adaptive refinement (docs/IMPORT.md): a coarser base than the mesh.
"$amc" info m.amc | awk '/base mesh/ {exit !($5 + 0 < $13 + 0)}' || fail "encode of a plain mesh found no coarser base: $("$amc" info m.amc | head -2)"
expect 0 "$amc" decode m.amc -o mc.obj --canonical
expect 0 "$amc" decode m.amc -o m2.ply --map m2.map
cmp -s m.map m2.map || fail "the map stored in the file differs from the one encode wrote"
expect 1 "$amc" decode r.amc -o r3.ply --map r3.map
expect 2 "$amc" encode r.amh -o r4.amc --keep-numbering

# A base whose vertices lie elsewhere than the leaf mesh's (written with other digits, moved) is
# matched by --base-map (per base vertex its leaf vertex); by position it is refused.
expect 0 "$amc" extract r.amh -o leaf.obj
expect 0 "$amc" extract r.amh --level 0 -o base.obj
awk 'NR == FNR { if ($1 == "v") index_of[$2 " " $3 " " $4] = n++; next } $1 == "v" { print index_of[$2 " " $3 " " $4] }' \
  leaf.obj base.obj > base.map
awk '$1 == "v" { printf "v %.9g %s %s\n", $2 + 0.001, $3, $4; next } { print }' base.obj > moved_base.obj
expect 0 "$amc" import leaf.obj --base base.obj -o by_position.amh
expect 1 "$amc" import leaf.obj --base moved_base.obj -o moved.amh
[[ -e moved.amh ]] && fail "import of a base that does not fit wrote its output"
expect 0 "$amc" import leaf.obj --base moved_base.obj --base-map base.map -o by_map.amh
cmp -s by_position.amh by_map.amh || fail "import --base-map made another hierarchy than the base's exact positions"
expect 0 "$amc" encode leaf.obj --base moved_base.obj --base-map base.map -o by_map.amc
expect 0 "$amc" encode leaf.obj --base base.obj -o by_position.amc
cmp -s by_position.amc by_map.amc || fail "encode --base-map wrote another file than the base's exact positions"
expect 2 "$amc" import leaf.obj --base-map base.map -o x.amh
head -2 base.map > short.map
expect 1 "$amc" import leaf.obj --base moved_base.obj --base-map short.map -o x.amh
grep -q 'short.map: 2 vertex indices for the' err.txt || fail "a short base map is not named: $(cat err.txt)"
expect 1 "$amc" import leaf.obj --base moved_base.obj --base-map leaf.obj -o x.amh
grep -q 'not a base vertex map' err.txt || fail "an OBJ as base map is not refused as such: $(cat err.txt)"

# A file still arriving: --partial decodes the complete levels and says how far it got.
size=$(stat -c %s r.amc)
head -c $((size * 3 / 4)) r.amc > cut.amc
expect 1 "$amc" decode cut.amc -o cut.ply
grep -q 'truncated' err.txt || fail "a cut file is not refused as truncated without --partial"
expect 0 "$amc" decode --partial cut.amc -o cut.ply
grep -q 'partial: levels 0\.\.' out.txt || fail "decode --partial does not say which level it reached: $(cat out.txt)"
head -c 40 r.amc > cut2.amc
expect 1 "$amc" decode --partial cut2.amc -o cut2.ply
grep -q 'base mesh' err.txt || fail "a prefix that cuts the base mesh is not refused as such: $(cat err.txt)"
[[ -e cut2.ply ]] && fail "decode --partial wrote cut2.ply for a prefix without the base mesh"
expect 0 "$amc" decode --partial r.amc -o whole.ply
cmp -s whole.ply r.ply || fail "decode --partial of a whole file differs from decode"
grep -q 'partial' out.txt && fail "decode --partial of a whole file calls it partial"

# --ascii: text PLY with the level and green face properties.
expect 0 "$amc" decode r.amc -o a.ply --ascii
head -3 a.ply | grep -q 'format ascii' || fail "--ascii wrote no ASCII PLY"
grep -q 'property uchar level' a.ply || fail "ASCII PLY lacks the level property"
grep -q 'property uchar level' r.ply && fail "binary PLY has face properties (meshio 5 can not read them)"

finish cli_conventions
