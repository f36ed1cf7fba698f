"""How soon Ctrl-C stops a long build, and what it leaves running and resident.

    python python/bench/interrupt.py [SECONDS ...]

For each SECONDS (2.5 5 12 20 30 by default), starts a Python process that builds the default
scene sampled uniformly to 3M triangles (1500 x 1000 cells, about 75 s on two cores), sends it
SIGINT after SECONDS, and prints, as measured inside that process: the time from the signal
to `KeyboardInterrupt`, the CPU time it used in the second after it (`os.times()`: nothing
of the build should still run), and its resident memory before the build, at its peak
(sampled every 50 ms), at the interrupt and a second later (`/proc/self/statm`).
"""

import signal
import subprocess
import sys
import time
from pathlib import Path

DEFAULT = Path(__file__).resolve().parents[2] / "fixtures" / "scenes" / "default.json"

CHILD = f"""
import json, os, threading, time, halo4d
import signal
# Ctrl-C raises KeyboardInterrupt even where the parent ignores SIGINT (a background job).
signal.signal(signal.SIGINT, signal.default_int_handler)
def rss():
    return int(open("/proc/self/statm").read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 1e6
def cpu():
    t = os.times()
    return t.user + t.system
d = json.load(open({str(DEFAULT)!r}))
d["surfaces"][0]["sampling"] = {{"method": "uniform", "u": 1500, "v": 1000}}
scene = halo4d.Scene(d)
print("ready", rss(), flush=True)
peak = [0.0]
def watch():
    while True:
        peak[0] = max(peak[0], rss())
        time.sleep(0.05)
threading.Thread(target=watch, daemon=True).start()
try:
    scene.build()
    print("finished", flush=True)
except KeyboardInterrupt:
    stopped = time.monotonic()
    used, at = cpu(), rss()
    time.sleep(1.0)
    print("interrupted", stopped, cpu() - used, peak[0], at, rss(), flush=True)
"""

for wait in map(float, sys.argv[1:] or ["2.5", "5", "12", "20", "30"]):
    child = subprocess.Popen([sys.executable, "-c", CHILD], stdout=subprocess.PIPE, text=True)
    _, before = child.stdout.readline().split()
    time.sleep(wait)
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=300)
    fields = out.split()
    if fields[0] != "interrupted":
        print(f"SIGINT at {wait:g} s: the build {fields[0]} first")
        continue
    stopped, cpu_after, peak, at, after = map(float, fields[1:])
    print(
        f"SIGINT at {wait:g} s: KeyboardInterrupt {stopped - sent:.3f} s later; "
        f"{cpu_after:.3f} s of CPU in the next second; resident {float(before):.0f} MB before, "
        f"{peak:.0f} MB at the peak, {at:.0f} MB at the interrupt, {after:.0f} MB a second later"
    )
