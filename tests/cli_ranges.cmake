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
)
set(failures "")
foreach(case IN LISTS cases)
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 expected_code)
  list(GET parts 1 expected_words)
  list(GET parts 2 argument_text)
  separate_arguments(arguments UNIX_COMMAND "${argument_text}")
  execute_process(COMMAND "${AMC}" ${arguments} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
  string(FIND "${out}${err}" "${expected_words}" position)
  if(NOT result STREQUAL expected_code OR position EQUAL -1)
    string(APPEND failures "\n  amc ${arguments}: exit '${result}' (expected ${expected_code}), output: ${out}${err}")
  endif()
endforeach()
if(NOT failures STREQUAL "")
  message(FATAL_ERROR "range arguments not refused as expected:${failures}")
endif()
list(LENGTH cases count)
message(STATUS "all ${count} out-of-range arguments refused")
