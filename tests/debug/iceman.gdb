# simbot debug --batch: ICEMAN vs Figure 9.2, seed 3 (tests/debug_test.py
# checks the transcript against iceman.transcript; docs/debugging.md
# shows it). The edge handler's first entry interrupts platform()'s delay
# loop; stepping back lands on the instruction it interrupted, stepping on
# enters the handler again with the same values.
break INT1
continue
backtrace
print platform::z
info pose
reverse-step
print z
info pose
step
print platform::z
info pose
# The motor string: a watchpoint stops at each strcpy that changes it.
delete
watch buf
continue
continue
continue
info breakpoints
quit
