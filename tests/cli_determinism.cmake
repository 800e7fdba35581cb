# Runs a match through the command line: twice with --trace, which must give
# byte-identical traces; once with no trace at all and once with every other
# sink (--vcd, --replay). The JSON must be identical in all four once
# wall_seconds is removed: no sink changes the result. Then simbot view of
# the trace must write the very page --replay wrote.
set(runs traced1 traced2 plain sinks)
set(args_traced1 --trace ${OUT}/trace1.jsonl)
set(args_traced2 --trace ${OUT}/trace2.jsonl)
set(args_plain)
set(args_sinks --vcd ${OUT}/match.vcd --replay ${REPLAY})
foreach(run ${runs})
  execute_process(
    COMMAND ${SIMBOT} match ${A} ${B} --seconds ${SECONDS} --seed 1 --json ${args_${run}}
    OUTPUT_VARIABLE json_${run} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "simbot match (${run}) failed (${rc})")
  endif()
  string(REGEX REPLACE "\"wall_seconds\": [0-9.e+-]+" "" json_${run} "${json_${run}}")
  if(NOT json_${run} STREQUAL json_traced1)
    message(FATAL_ERROR "JSON differs between runs (${run}):\n${json_traced1}\n${json_${run}}")
  endif()
endforeach()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT}/trace1.jsonl ${OUT}/trace2.jsonl
                RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  message(FATAL_ERROR "traces differ between runs")
endif()
# The replay page from the recorded trace is the page --replay wrote.
execute_process(COMMAND ${SIMBOT} view ${OUT}/trace1.jsonl -o ${OUT}/view.html RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "simbot view failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT}/view.html ${REPLAY}
                RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  message(FATAL_ERROR "simbot view of the trace differs from the page --replay wrote")
endif()
