"""How long a build's arrays take to reach Python, against the build itself.

    python python/bench/arrays.py [TRIANGLES]

Builds the default scene sampled uniformly to about TRIANGLES triangles (1,000,000 by
default), then reads every array of the build (the surface's 4D and projected vertices, w,
normals, triangles; the halo's vertices, tetrahedra, t and d_orig; every curve's points, w,
sheets and over) three times, and prints the build's time, the best read's and their ratio.
"""

import math
import sys
import time

import halo4d

target = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000
scene = halo4d.Scene().to_dict()
# A uniform grid of u x v cells has 2 u v triangles; the spun sphere's patch is about twice
# as long in u as in v.
v = max(4, round(math.sqrt(target / 4)))
scene["surfaces"][0]["sampling"] = {"method": "uniform", "u": 2 * v, "v": v}
start = time.perf_counter()
built = halo4d.Scene(scene).build()
build_s = time.perf_counter() - start


def read_all():
    total = 0
    for s in built.surfaces:
        for a in (s.vertices4d, s.positions, s.w, s.normals, s.triangles):
            total += a.nbytes
        h = s.halo
        if h is not None:
            for a in (h.vertices, h.tetrahedra, h.t, h.d_orig):
                total += a.nbytes
    for c in built.curves:
        for a in (c.points, c.w, c.sheets, c.over):
            total += a.nbytes
    return total


reads = []
for _ in range(3):
    start = time.perf_counter()
    nbytes = read_all()
    reads.append(time.perf_counter() - start)
read_s = min(reads)
triangles = sum(len(s.triangles) for s in built.surfaces)
tets = sum(len(s.halo.tetrahedra) for s in built.surfaces if s.halo is not None)
print(
    f"{triangles} triangles, {tets} tetrahedra, {len(built.curves)} curves: "
    f"build {build_s:.2f} s; every array ({nbytes / 1e6:.0f} MB) in {read_s * 1e3:.0f} ms "
    f"(best of 3), {100 * read_s / build_s:.2f}% of the build"
)
