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

def interrupt(wait: float) -> dict:
    """One run: SIGINT `wait` seconds into the build; what the interrupted process measured
    (`finished` true where the build ended first)."""
    child = subprocess.Popen([sys.executable, "-c", CHILD], stdout=subprocess.PIPE, text=True)
    _, before = child.stdout.readline().split()
    time.sleep(wait)
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=300)
    fields = out.split()
    if fields[:1] != ["interrupted"]:
        return {"finished": True, "output": out}
    stopped, cpu_after, peak, at, after = map(float, fields[1:])
    return {
        "finished": False,
        "after_signal": stopped - sent,
        "cpu_next_second": cpu_after,
        "rss_before": float(before),
        "rss_peak": peak,
        "rss_at_interrupt": at,
        "rss_after": after,
    }


if __name__ == "__main__":
    for wait in map(float, sys.argv[1:] or ["2.5", "5", "12", "20", "30"]):
        r = interrupt(wait)
        if r["finished"]:
            print(f"SIGINT at {wait:g} s: the build finished first: {r['output']}")
            continue
        print(
            f"SIGINT at {wait:g} s: KeyboardInterrupt {r['after_signal']:.3f} s later; "
            f"{r['cpu_next_second']:.3f} s of CPU in the next second; resident "
            f"{r['rss_before']:.0f} MB before, {r['rss_peak']:.0f} MB at the peak, "
            f"{r['rss_at_interrupt']:.0f} MB at the interrupt, {r['rss_after']:.0f} MB a second later"
        )
