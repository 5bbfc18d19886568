# Runs `${AMC} info FILE` on every file in BAD_DIR. Each run must fail cleanly: exit code 1
# (not 0, not a signal or abort, not a timeout) with an error on stderr that names the file.
#   cmake -DAMC=<path to amc> -DBAD_DIR=<dir> -P cli_bad_inputs.cmake
if(NOT DEFINED AMC OR NOT DEFINED BAD_DIR)
  message(FATAL_ERROR "usage: cmake -DAMC=<path to amc> -DBAD_DIR=<dir> -P cli_bad_inputs.cmake")
endif()
if(NOT EXISTS "${AMC}")
  message(FATAL_ERROR "amc not found: ${AMC}")
endif()

# A data folder, not a source list: globbing is the point here.
file(GLOB bad_files LIST_DIRECTORIES false "${BAD_DIR}/*")
list(SORT bad_files)
list(LENGTH bad_files file_count)
if(file_count EQUAL 0)
  message(FATAL_ERROR "no files in ${BAD_DIR}")
endif()

set(failures "")
foreach(file IN LISTS bad_files)
  get_filename_component(name "${file}" NAME)
  execute_process(
    COMMAND "${AMC}" info "${file}"
    RESULT_VARIABLE result
    OUTPUT_VARIABLE out
    ERROR_VARIABLE err
    TIMEOUT 60)
  # RESULT_VARIABLE is the exit code, or a message such as "Child aborted" or
  # "Process terminated due to timeout" when the process did not exit normally.
  if(NOT result STREQUAL "1")
    string(APPEND failures "\n  ${name}: expected exit code 1, got '${result}'; stderr: ${err}")
  else()
    string(FIND "${err}" "${name}" position)
    if(position EQUAL -1)
      string(APPEND failures "\n  ${name}: stderr does not name the file: ${err}")
    endif()
  endif()
endforeach()

if(NOT failures STREQUAL "")
  message(FATAL_ERROR "bad inputs not rejected cleanly:${failures}")
endif()
message(STATUS "all ${file_count} bad inputs rejected with exit code 1 and the file name")
