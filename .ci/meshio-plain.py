"""Writes a halo's tetrahedra back with meshio (installed by .ci/run) as another program
would, with no halo4d field data: legacy VTK 4.2 ASCII and 5.1 binary, whole and with one
tetrahedron turned inside out. `halo4d check` must read each as tetrahedra without the halo
layout, say so and certify them as a mesh: the whole ones have no fault of their cells or
of how they meet, but the halo crosses itself where the sheets it thickens cross (what a
halo is for), so they fail on `self_intersections` alone; the inverted ones fail on
`inverted` too (exit status 1 for all).

Usage: meshio-plain.py HALO4D HALO.vtk OUT_DIR"""

import json
import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np

halo4d, source, out = sys.argv[1], sys.argv[2], Path(sys.argv[3])
out.mkdir(parents=True, exist_ok=True)
halo = meshio.read(source, file_format="vtk")
tets = np.asarray(halo.cells_dict["tetra"])
bad = 0
for version, binary in (("4.2", False), ("5.1", True)):
    for inverted in (False, True):
        cells = tets.copy()
        if inverted:
            cells[len(cells) // 2, [0, 1]] = cells[len(cells) // 2, [1, 0]]
        path = out / f"plain-{version}{'-inverted' if inverted else ''}.vtk"
        mesh = meshio.Mesh(np.asarray(halo.points), [("tetra", cells)])
        meshio.vtk.write(path, mesh, fmt_version=version, binary=binary)
        run = subprocess.run([halo4d, "check", str(path), "--json"], capture_output=True, text=True)
        report = json.loads(run.stdout) if run.stdout.startswith("{") else {}
        names = {next((w for w in f.split() if w[:1].isalpha()), f) for f in report.get("failures", [])}
        want = {"self_intersections", "inverted"} if inverted else {"self_intersections"}
        plain = "another program wrote it" in (report.get("plain") or "")
        ok = run.returncode == 1 and names == want and plain
        print(f"{path.name}: {len(cells)} tetra, exit {run.returncode}, failures {sorted(names)} (want {sorted(want)}){'' if ok else ', not as expected'}")
        if not ok:
            print(run.stdout[:2000], run.stderr)
            bad += 1
print(f"meshio {meshio.__version__}: {4 - bad} of 4 plain files checked as expected")
sys.exit(1 if bad else 0)
