#!/usr/bin/env python3
"""How long simbot debug takes to answer each command, and its peak memory.

Usage: bench/debug_answer_times.py build/bin/simbot debug PROGRAMS... --batch FILE

Runs the session line-buffered and prints, for each echoed command, the
wall time and the CPU time (utime+stime from /proc) until the next
command's echo: the command's answer time. Then the peak RSS."""
import os, resource, subprocess, sys, time
tck = os.sysconf("SC_CLK_TCK")
p = subprocess.Popen(["stdbuf", "-oL"] + sys.argv[1:], stdout=subprocess.PIPE, text=True, bufsize=1)
def cpu():
    try:
        f = open(f"/proc/{p.pid}/stat").read().rsplit(")", 1)[1].split()
        return (int(f[11]) + int(f[12])) / tck
    except OSError:
        return float("nan")
last, lastcpu, name = time.monotonic(), 0.0, "(start)"
for line in p.stdout:
    if line.startswith("(simbot) "):
        now, c = time.monotonic(), cpu()
        print(f"{now - last:7.3f} s wall {c - lastcpu:7.2f} s cpu  {name}")
        last, lastcpu, name = now, c, line.strip()
c = cpu(); now = time.monotonic()
p.wait()
print(f"{now - last:7.3f} s wall {c - lastcpu:7.2f} s cpu  {name}")
print(f"peak RSS {resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss} KB")
