# Every range argument of every subcommand is checked: each command below must fail (exit code 2,
# a usage error, for arguments outside their static range; 1, an error in the data, for a level
# the file does not have) with a message that names the argument or the level.
#   cmake -DAMC=<path to amc> -DGOLDEN=<an .amc file of levels 0..2> -DOUT=<scratch folder> -P cli_ranges.cmake
if(NOT DEFINED AMC OR NOT DEFINED GOLDEN OR NOT DEFINED OUT)
  message(FATAL_ERROR "usage: cmake -DAMC=<amc> -DGOLDEN=<file.amc> -DOUT=<folder> -P cli_ranges.cmake")
endif()
file(MAKE_DIRECTORY "${OUT}")
set(mesh "${OUT}/out.obj")
# Each case: expected exit code | expected words in stderr or stdout | arguments
set(cases
  "2|--level|decode ${GOLDEN} -o ${mesh} --level 99"
  "2|--level|decode ${GOLDEN} -o ${mesh} --level -5"
  "1|level 3 requested but the hierarchy has levels 0..2|decode ${GOLDEN} -o ${mesh} --level 3"
  "2|--level|extract ${GOLDEN} -o ${mesh} --level 99"
  "2|--level|extract ${GOLDEN} -o ${mesh} --level -2"
  "1|level 3 requested but the hierarchy has levels 0..2|extract ${GOLDEN} -o ${mesh} --level 3"
  "2|--max-nodes|decode ${GOLDEN} -o ${mesh} --max-nodes 0"
  "1|more than the limit of 100|decode ${GOLDEN} -o ${mesh} --max-nodes 100"
  "1|more than the limit of 100|info ${GOLDEN} --max-nodes 100"
  "1|more than the limit of 100|extract ${GOLDEN} -o ${mesh} --max-nodes 100"
  "2|--max-level|refine --model lshape --max-level 40"
  "2|--max-level|refine --model lshape --max-level -1"
  "2|--levels|refine --model uniform --levels 31"
  "2|--faces|refine --model random --faces 0"
  "2|--base-faces|refine --model bumpy --base-faces 0"
  "2|--max-nodes|info ${GOLDEN} --max-nodes 0"
  "2|--max-nodes|extract ${GOLDEN} -o ${mesh} --max-nodes 99999999999999"
  "2|--steps|refine --model front --steps 0"
  "2|--quantize|encode x.amh -o ${OUT}/x.amc --quantize 31"
  "2|--runs|report x.amh --runs 0"
  "1|chunk 1073741823 is not in the file (it has 1 chunk)|decode ${GOLDEN} -o ${OUT}/chunks.amh --chunks 0-1073741823"
  # The review of the command line (2026-12-07): sizes asked for that cannot fit, refused before
  # they are made, and numbers CLI11's checks let through (NaN, overflow, trailing text).
  "2|--trees 4194304x4194304x4194304: brick: sizes must be|octree make --dim 3 --trees 4194304x4194304x4194304 -o ${OUT}/t.amq"
  "2|--trees: expected|octree make --dim 2 --trees 99999999999x1 -o ${OUT}/t.amq"
  "2|--trees: expected|octree make --dim 2 --trees 2x2junk -o ${OUT}/t.amq"
  "2|--trees: expected|octree make --dim 2 --trees 2x2x5 -o ${OUT}/t.amq"
  "2|the uniform forest: more than 4096 leaves (--max-leaves)|octree make --dim 3 --model uniform --level 18 --max-leaves 4096 -o ${OUT}/u.amq"
  "2|the sphere forest: more than 4096 leaves (--max-leaves)|octree make --dim 3 --model sphere --level 18 --max-leaves 4096 -o ${OUT}/s.amq"
  "2|make more than the 67108864 nodes of --max-nodes|refine --model uniform --levels 30 -o ${OUT}/u.amh"
  "2|make more than the 1000 nodes of --max-nodes|refine --model uniform --levels 3 --max-nodes 1000 -o ${OUT}/u.amh"
  "2|--faces 1073741824 --max-level 30: more leaves than the 67108864 nodes of --max-nodes|refine --model random --faces 1073741824 --max-level 30 -o ${OUT}/r.amh"
  "2|: the front makes more than 10000 nodes in its first 1 steps (--max-nodes)|refine --model front --max-level 30 --max-nodes 10000 -o ${OUT}/front.amh"
  "2|--steps 100000: the front makes more than 100000 nodes|refine --model front --max-level 3 --steps 100000 --max-nodes 100000 -o ${OUT}/front.amh"
  "2|--faces 1073741824 --max-level 30: remesh: at least 357913941 leaves, more than 67108864 nodes (--max-nodes)|refine --model bumpy --faces 1073741824 --max-level 30 --no-measure -o ${OUT}/bumpy.amh"
  "2|--faces 250000 --max-level 30: remesh: more than 100000 nodes (--max-nodes)|refine --model bumpy --faces 250000 --max-level 30 --no-measure --max-nodes 100000 -o ${OUT}/bumpy.amh"
  "2|--error-bound: NaN is not a number here|series encode ${GOLDEN} -o ${OUT}/s.amcs --error-bound nan"
  "2|--vertex-step: NaN is not a number here|octree encode ${OUT}/none.amq -o ${OUT}/v.amq --vertex-step nan"
  # Integers read decimal, as zstd and xz read them (CLI11 alone reads base 0: 010 is 8, 0x1 is 1,
  # and an unsigned option takes -1 as 2^64 - 1).
  "1|level 10 requested but the hierarchy has levels 0..2|decode ${GOLDEN} -o ${mesh} --level 010"
  "2|--level: '0x1' is not a decimal integer|decode ${GOLDEN} -o ${mesh} --level 0x1"
  "2|--seed: '-1' is not a decimal number|refine --model random --faces 100 --seed -1 -o ${OUT}/seed.amh"
  "2|--triangles: '0x0' is not a decimal number|decode ${GOLDEN} -o ${mesh} --triangles 0x0"
)
set(failures "")
foreach(case IN LISTS cases)
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 expected_code)
  list(GET parts 1 expected_words)
  list(GET parts 2 argument_text)
  separate_arguments(arguments UNIX_COMMAND "${argument_text}")
  # A bound on a run that would not stop, not a speed test: the remesher's refusals come after its
  # base is made, 2.5 s of CPU in Release and 30 s under ASan, more on a busy machine.
  execute_process(COMMAND "${AMC}" ${arguments} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
  string(FIND "${out}${err}" "${expected_words}" position)
  if(NOT result STREQUAL expected_code OR position EQUAL -1)
    string(APPEND failures "\n  amc ${arguments}: exit '${result}' (expected ${expected_code}), output: ${out}${err}")
  endif()
endforeach()
# An empty list, an empty argument (which the cases above cannot hold), is a usage error: it
# decoded every chunk.
foreach(option --chunks --triangles)
  execute_process(COMMAND "${AMC}" -f decode "${GOLDEN}" -o "${OUT}/empty.obj" ${option} ""
                  RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
  string(FIND "${out}${err}" "${option}: " position)
  if(NOT result STREQUAL "2" OR position EQUAL -1)
    string(APPEND failures "\n  amc decode ${option} '': exit '${result}' (expected 2), output: ${out}${err}")
  endif()
endforeach()
if(NOT failures STREQUAL "")
  message(FATAL_ERROR "range arguments not refused as expected:${failures}")
endif()
list(LENGTH cases count)
message(STATUS "all ${count} out-of-range arguments refused")
