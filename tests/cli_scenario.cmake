# --scenario on solo, match, profile and bench, through the command line.
function(run expect_rc)
  execute_process(COMMAND ${SIMBOT} ${ARGN} OUTPUT_VARIABLE out ERROR_VARIABLE err
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL expect_rc)
    message(FATAL_ERROR "simbot ${ARGN}: exit ${rc}, expected ${expect_rc}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
  set(err "${err}" PARENT_SCOPE)
endfunction()
function(expect_json field want)
  string(JSON got GET "${out}" ${field})
  if(NOT got STREQUAL want)
    message(FATAL_ERROR "${field} is ${got}, expected ${want}")
  endif()
endfunction()
function(expect_match text pattern)
  if(NOT text MATCHES "${pattern}")
    message(FATAL_ERROR "expected /${pattern}/ in:\n${text}")
  endif()
endfunction()

# solo: the scenario's length, A's injections and B's path legs.
run(0 solo ${ICEMAN} --scenario ${SCENARIOS}/patrol.toml --json --trace ${OUT}/patrol.jsonl)
expect_json(sim_seconds 45.0)
file(READ ${OUT}/patrol.jsonl trace)
expect_match("${trace}" "\"type\":\"injection\",\"what\":\"A:bumper_front@line:220#3\"")
expect_match("${trace}" "\"time_s\":12.5,\"type\":\"injection\"")
expect_match("${trace}" "\"left_fps\":0.3,\"leg\":2,\"right_fps\":-0.3,\"robot\":\"B\"")
# The command line wins over the scenario.
run(0 solo ${ICEMAN} --scenario ${SCENARIOS}/patrol.toml --seconds 2 --json)
expect_json(sim_seconds 2.0)

# match: B comes from the command line, so a scenario's beacon is an error.
run(1 match ${ICEMAN} ${FIG92} --scenario ${SCENARIOS}/beacon-ahead.toml)
expect_match("${err}" "beacon-ahead.toml:11:10: error: match takes B's program from the command line")
# Exactly the scenario's poses under thesis-1997 (default puts them down by hand).
run(0 match ${ICEMAN} ${FIG92} --scenario ${SCENARIOS}/start-corners.toml --seconds 0.001
    --profile thesis-1997 --json)
expect_json("robots;0;final_pose;x_ft" -5.0)
expect_json("robots;1;final_pose;heading_deg" 225.0)

# profile: ICEMAN with a beacon ahead, for the scenario's 30 s.
run(0 profile ${ICEMAN} --scenario ${SCENARIOS}/beacon-ahead.toml --json)
string(JSON cycles GET "${out}" cycles)
if(cycles LESS 276480000 OR cycles GREATER 276490000)  # 30 s, the VM's last instruction past it
  message(FATAL_ERROR "profile ran ${cycles} T-states, expected 30 s")
endif()

# bench: the scenario as the family, and a family with a scenario that
# places robots (an error).
run(0 bench ${ICEMAN} --scenario ${SCENARIOS}/circle.toml --seeds 2 --seconds 3 --threads 2
    --out ${OUT}/bench-scenario)
file(READ ${OUT}/bench-scenario/summary.json summary)
string(JSON family GET "${summary}" family)
if(NOT family STREQUAL "scenario circle")
  message(FATAL_ERROR "bench family is '${family}'")
endif()
run(1 bench ${ICEMAN} --family stationary --scenario ${SCENARIOS}/beacon-ahead.toml --seeds 2)
expect_match("${err}" "beacon-ahead.toml:11:10: error: a bench family places the robots")
