# A scenario's [[obstacles]] through the command line: each mistake is one
# FILE:LINE:COL line and exit status 1; scenarios/mines.toml runs, and its
# trace lists the obstacles and names them in contacts.
file(MAKE_DIRECTORY ${OUT})
function(run expect_rc)
  execute_process(COMMAND ${SIMBOT} ${ARGN} OUTPUT_VARIABLE out ERROR_VARIABLE err
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL expect_rc)
    message(FATAL_ERROR "simbot ${ARGN}: exit ${rc}, expected ${expect_rc}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
  set(err "${err}" PARENT_SCOPE)
endfunction()
# A scenario whose obstacles table is `body`, refused with exactly `line`.
function(refused name body line)
  file(WRITE ${OUT}/${name}.toml "seconds = 1\n\n[[obstacles]]\n${body}")
  run(1 match ${ICEMAN} ${FIG92} --scenario ${OUT}/${name}.toml)
  # The error is the last line (the programs' compiler warnings may come
  # before it: the field checks are made once the run is set up).
  set(want "${OUT}/${name}.toml:${line}\n")
  string(LENGTH "${err}" n)
  string(LENGTH "${want}" m)
  if(n LESS m)
    set(n ${m})
  endif()
  math(EXPR from "${n} - ${m}")
  string(SUBSTRING "${err}" ${from} -1 tail)
  string(REGEX MATCHALL "error:" errors "${err}")
  list(LENGTH errors count)
  if(NOT tail STREQUAL want OR NOT count EQUAL 1)
    message(FATAL_ERROR "${name}: expected\n${want}got\n${err}")
  endif()
endfunction()

set(circle "kind = \"circle\"\nx_ft = 2.0\ny_ft = 3.0\nheight_ft = 1.0\n")
refused(unknown-key "${circle}radius_ft = 0.5\ncolour = \"red\"\n"
  "9:1: error: unknown key 'colour' in obstacles[0] (a circle) (expected one of: kind, name, mine, x_ft, y_ft, radius_ft, height_ft)")
refused(other-kinds-key "${circle}radius_ft = 0.5\nwidth_ft = 1.0\n"
  "9:1: error: unknown key 'width_ft' in obstacles[0] (a circle) (expected one of: kind, name, mine, x_ft, y_ft, radius_ft, height_ft)")
refused(wrong-kind "kind = \"cone\"\n"
  "4:8: error: 'obstacles[0].kind' must be \"circle\", \"box\" or \"polygon\"")
refused(negative-size "${circle}radius_ft = -0.5\n"
  "8:13: error: 'obstacles[0].radius_ft' must be greater than 0, got -0.5")
refused(zero-height "kind = \"box\"\nx_ft = 2.0\ny_ft = 3.0\nwidth_ft = 1.0\ndepth_ft = 1.0\nheight_ft = 0\n"
  "9:13: error: 'obstacles[0].height_ft' must be greater than 0, got 0")
refused(not-convex "kind = \"polygon\"\nheight_ft = 1.0\npoints_ft = [[0, 0], [2, 0], [1, 0.5], [2, 2], [0, 2]]\n"
  "6:13: error: 'obstacles[0].points_ft' is not convex: it turns the other way at point 3 (1, 0.5)")
refused(degenerate "kind = \"polygon\"\nheight_ft = 1.0\npoints_ft = [[0, 0], [1, 0], [2, 0], [1, 1]]\n"
  "6:13: error: 'obstacles[0].points_ft' is degenerate: point 2 (1, 0) repeats a point or lies on a straight line with its neighbours")
refused(crossing "kind = \"polygon\"\nheight_ft = 1.0\npoints_ft = [[0, 2], [1.2, -1.6], [-1.9, 0.6], [1.9, 0.6], [-1.2, -1.6]]\n"
  "6:13: error: 'obstacles[0].points_ft' is not convex: its edges cross (it winds round more than once)")
refused(outside "${circle}radius_ft = 5.5\n"
  "3:1: error: obstacle 1 reaches outside the 16-ft field (|x|, |y| <= 8 ft)")
# The default profile's start poses: A at (-6.5, -6.5).
refused(on-a-start "kind = \"circle\"\nx_ft = -6.0\ny_ft = -6.0\nradius_ft = 0.3\nheight_ft = 1.0\n"
  "3:1: error: obstacle 1 overlaps robot A's start pose (-6.5, -6.5) ft")

# scenarios/mines.toml runs; its trace lists the three obstacles after
# the run record and names the ones the robots touch.
run(0 match ${ICEMAN} ${FIG92} --scenario ${SCENARIOS}/mines.toml --seconds 60 --seed 1
    --json --trace ${OUT}/mines.jsonl)
file(STRINGS ${OUT}/mines.jsonl lines LIMIT_COUNT 4)
list(GET lines 1 first)
if(NOT first MATCHES "\"index\":1,\"kind\":\"circle\",\"mine\":true,\"name\":\"mine\"")
  message(FATAL_ERROR "the trace's second record is not the first mine:\n${first}")
endif()
list(GET lines 3 third)
if(NOT third MATCHES "\"kind\":\"box\",\"mine\":false,\"name\":\"mountain\",\"points_ft\":\\[")
  message(FATAL_ERROR "the trace's fourth record is not the mountain:\n${third}")
endif()
