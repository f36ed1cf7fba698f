"""Each stage of a build at several thread counts, as docs/PERFORMANCE.md's scaling table.

    python benches/scaling/run.py --halo4d target/release/halo4d [--runs 3]
        [--threads 1,2] SCENE...

Each scene is built `runs` times at each thread count (`RAYON_NUM_THREADS`), each build in
a fresh process and a fresh folder. For every stage of `report.json`'s `timings_ms`, and
for the wall time measured around the process, it prints the median seconds at each thread
count, the parallel efficiency against one thread (speed-up over threads) and the serial
fraction that speed-up implies (Karp and Flatt: (1/S - 1/p) / (1 - 1/p)). Stages under
20 ms at one thread get no ratio. Needs only Python 3.
"""

import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time

def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--halo4d", required=True, help="the halo4d binary")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--threads", default="1,2", help="thread counts, the first the base")
    parser.add_argument("scenes", nargs="+")
    args = parser.parse_args()
    threads = [int(t) for t in args.threads.split(",")]
    for scene in args.scenes:
        medians = {t: medians_of(args.halo4d, scene, t, args.runs) for t in threads}
        # The stages in the report's order, `total` last, then the wall time.
        stages = list(medians[threads[0]])
        print(f"\n{os.path.basename(scene)}: medians of {args.runs} runs, seconds\n")
        head = ["stage"] + [f"{t} thr." for t in threads]
        head += [f"efficiency {t}" for t in threads[1:]]
        head += [f"serial fraction {t}" for t in threads[1:]]
        print("| " + " | ".join(head) + " |")
        print("| --- |" + " ---: |" * (len(head) - 1))
        for stage in stages:
            base = medians[threads[0]][stage]
            if stage not in ("total", "wall") and base < 0.0005:
                continue
            cells = [f"{medians[t][stage]:.2f}" for t in threads]
            efficiency, serial = [], []
            for t in threads[1:]:
                now = medians[t][stage]
                if base < 0.02 or now <= 0:
                    efficiency.append("-")
                    serial.append("-")
                    continue
                speedup = base / now
                efficiency.append(f"{speedup / t:.0%}")
                serial.append(f"{max(0.0, (1 / speedup - 1 / t) / (1 - 1 / t)):.0%}")
            print("| " + " | ".join([stage] + cells + efficiency + serial) + " |")


def medians_of(halo4d, scene, threads, runs):
    """Median seconds of each stage (and the wall time) over `runs` builds."""
    records = []
    for _ in range(runs):
        with tempfile.TemporaryDirectory() as out:
            env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
            start = time.monotonic()
            subprocess.run([halo4d, "build", "--quiet", "--out", out, scene], env=env,
                           check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            wall = time.monotonic() - start
            with open(os.path.join(out, "report.json")) as f:
                timings = json.load(f)["timings_ms"]
        record = {k: v / 1e3 for k, v in timings.items()}
        record["wall"] = wall
        records.append(record)
    return {k: statistics.median(r[k] for r in records) for k in records[0]}


if __name__ == "__main__":
    main()
