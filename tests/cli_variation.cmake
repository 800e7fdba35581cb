# Issue 14 through the command line, with short (20 s) runs: under the
# default profile four seeds of ICEMAN vs fig92 give four different traces
# and the same seed twice the same bytes; a bench of one fixed scenario and a
# tournament give the same tables on 1 and on 2 worker threads, and the
# bench's runs differ from seed to seed.
file(REMOVE_RECURSE ${OUT}/variation)
file(MAKE_DIRECTORY ${OUT}/variation)
set(dir ${OUT}/variation)
foreach(seed 1 2 3 4 1)
  set(name ${dir}/trace${seed}.jsonl)
  if(EXISTS ${name})
    set(name ${dir}/trace${seed}-again.jsonl)
  endif()
  execute_process(
    COMMAND ${SIMBOT} match ${ICEMAN} ${FIG92} --seconds 20 --seed ${seed} --profile default
            --trace ${name}
    OUTPUT_QUIET ERROR_QUIET RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "simbot match --seed ${seed} failed (${rc})")
  endif()
endforeach()
foreach(i 1 2 3 4)
  file(SHA256 ${dir}/trace${i}.jsonl h${i})
endforeach()
foreach(i 1 2 3)
  math(EXPR next "${i} + 1")
  foreach(j RANGE ${next} 4)
    if(h${i} STREQUAL h${j})
      message(FATAL_ERROR "seeds ${i} and ${j} gave the same trace under default")
    endif()
  endforeach()
endforeach()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${dir}/trace1.jsonl
                        ${dir}/trace1-again.jsonl RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  message(FATAL_ERROR "seed 1 twice gave different traces")
endif()

# One scenario, fixed poses: the runs differ only by their seeds.
file(WRITE ${dir}/duel.toml "profile = \"default\"\nseconds = 20\n[B]\nprogram = \"${FIG92}\"\n")
foreach(threads 1 2)
  execute_process(
    COMMAND ${SIMBOT} bench ${ICEMAN} --scenario ${dir}/duel.toml --seeds 6 --threads ${threads}
            --out ${dir}/bench${threads}
    OUTPUT_QUIET ERROR_QUIET RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "simbot bench --threads ${threads} failed (${rc})")
  endif()
  execute_process(
    COMMAND ${SIMBOT} tournament ${ICEMAN} ${FIG92} --rounds 2 --seconds 20 --seed 3
            --threads ${threads} --out ${dir}/tournament${threads}
    OUTPUT_QUIET ERROR_QUIET RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "simbot tournament --threads ${threads} failed (${rc})")
  endif()
endforeach()
foreach(f bench1/runs.csv bench1/summary.json tournament1/games.csv tournament1/standings.json)
  string(REPLACE "1/" "2/" g ${f})
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${dir}/${f} ${dir}/${g}
                  RESULT_VARIABLE same)
  if(NOT same EQUAL 0)
    message(FATAL_ERROR "${f} differs between 1 and 2 threads")
  endif()
endforeach()
# The bench's rows, less the run index and seed columns, are not all alike.
file(STRINGS ${dir}/bench1/runs.csv rows)
list(POP_FRONT rows)
set(bodies)
foreach(row ${rows})
  # (REGEX MATCH, not REPLACE: REPLACE applies "^" again after each match)
  string(REGEX MATCH "^[^,]*,[^,]*,[^,]*,(.*)$" whole "${row}")
  list(APPEND bodies "${CMAKE_MATCH_1}")
endforeach()
list(REMOVE_DUPLICATES bodies)
list(LENGTH bodies distinct)
if(distinct LESS 2)
  message(FATAL_ERROR "all bench runs of one scenario are alike under default:\n${rows}")
endif()
