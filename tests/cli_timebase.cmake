# `solo --seconds` goes through the one seconds-to-ticks conversion
# (timebase/tick.h): 0.043 s * 9,216,000 = 396,288 ticks exactly, and the
# run ends there (a truncating conversion ended it at 396,287).
execute_process(COMMAND ${SIMBOT} solo ${PROGRAM} --seconds 0.043 --json
                OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "simbot solo: exit ${rc}\n${out}\n${err}")
endif()
string(JSON exited GET "${out}" exited)
if(exited)
  message(FATAL_ERROR "expected the program still running at 0.043 s:\n${out}")
endif()
# 396,288 / 9,216,000 is the double nearest 0.043, printed as "0.043"; the
# tick before it would print 0.04299989149305555. (string(JSON) reprints
# numbers with 17 digits, so the text is matched.)
if(NOT out MATCHES "\"sim_seconds\": 0\.043,")
  message(FATAL_ERROR "expected sim_seconds 0.043 (tick 396288) in:\n${out}")
endif()
# Still running at the end: cycles is the clock at the end, not the VM's
# clock after the instruction that straddles it.
string(JSON cycles GET "${out}" cycles)
if(NOT cycles EQUAL 396288)
  message(FATAL_ERROR "cycles is ${cycles}, expected 396288")
endif()
