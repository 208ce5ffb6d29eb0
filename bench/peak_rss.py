#!/usr/bin/env python3
"""Runs a command and appends its wall time and peak resident memory (children included) to a log:
    bench/peak_rss.py LOG COMMAND [ARGS...]
For machines without /usr/bin/time (the GPU hosts); `time -v` reports the same peak."""
import resource
import subprocess
import sys
import time

if len(sys.argv) < 3:
    sys.exit("usage: peak_rss.py LOG COMMAND [ARGS...]")
start = time.time()
with open(sys.argv[1], "w") as log:
    status = subprocess.call(sys.argv[2:], stdout=log, stderr=subprocess.STDOUT)
wall = time.time() - start
peak_kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
with open(sys.argv[1], "a") as log:
    log.write("\nMEASURE rc=%d wall_s=%.3f peak_rss_mb=%.1f\n" % (status, wall, peak_kb / 1024.0))
sys.exit(status)
