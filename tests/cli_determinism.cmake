# Runs a match twice through the command line; the traces must be
# byte-identical and the JSON identical once wall_seconds is removed.
foreach(run 1 2)
  execute_process(
    COMMAND ${SIMBOT} match ${A} ${B} --seconds ${SECONDS} --seed 1 --json --trace ${OUT}/trace${run}.jsonl
    OUTPUT_VARIABLE json${run} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "simbot match failed (${rc})")
  endif()
  string(REGEX REPLACE "\"wall_seconds\": [0-9.e+-]+" "" json${run} "${json${run}}")
endforeach()
if(NOT json1 STREQUAL json2)
  message(FATAL_ERROR "JSON differs between runs:\n${json1}\n${json2}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT}/trace1.jsonl ${OUT}/trace2.jsonl
                RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  message(FATAL_ERROR "traces differ between runs")
endif()
