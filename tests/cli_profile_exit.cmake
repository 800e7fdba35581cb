# simbot profile of a program whose main returns: a solo run stops there,
# so the profile's total is main's return (the solo JSON's cycles) plus
# the HALT that follows it, one instruction (fewer than 100 T-states), and
# nothing idles: not the halted VM's time up to whichever horizon ended
# its last run, which depended on how long the rounds were (the build
# before gave 9,600, a character, for this program).
set(program "${WORKDIR}/returns.dc")
file(MAKE_DIRECTORY "${WORKDIR}")
file(WRITE "${program}" "int x;\nmain()\n{\n    x = 1;\n}\n")
execute_process(COMMAND ${SIMBOT} solo ${program} --seconds 1 --json
                OUTPUT_VARIABLE solo RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "simbot solo failed (${rc})")
endif()
execute_process(COMMAND ${SIMBOT} profile ${program} --seconds 1 --json
                OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "simbot profile failed (${rc})")
endif()
string(JSON returned GET "${solo}" cycles)
string(JSON total GET "${out}" cycles)
string(JSON idle GET "${out}" idle_cycles)
math(EXPR after "${total} - ${returned}")
if(after LESS_EQUAL 0 OR after GREATER_EQUAL 100)
  message(FATAL_ERROR "profile total ${total}, main returned at ${returned}: not one HALT after it")
endif()
if(NOT idle EQUAL 0)
  message(FATAL_ERROR "profile idles ${idle} T-states after main returned")
endif()
