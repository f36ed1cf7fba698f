"""Writes a halo's tetrahedra back with meshio (installed by .ci/run) as another program
would, with no halo4d field data: legacy VTK 4.2 ASCII and 5.1 binary, whole and with one
tetrahedron turned inside out. `halo4d check` must read each as tetrahedra without the halo
layout, say so, pass the whole ones (exit status 0) and fail the inverted one, naming it
(exit status 1).

Usage: meshio-plain.py HALO4D HALO.vtk OUT_DIR"""

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
        run = subprocess.run([halo4d, "check", str(path)], capture_output=True, text=True)
        want = 1 if inverted else 0
        words = ["not a halo: ", "another program wrote it"]
        words += ["FAILED", "1 inverted"] if inverted else ["ok: no inverted, flat or repeated tetrahedron"]
        missing = [w for w in words if w not in run.stdout]
        ok = run.returncode == want and not missing
        print(f"{path.name}: {len(cells)} tetra, exit {run.returncode} (want {want}){'' if ok else f', missing {missing}'}")
        if not ok:
            print(run.stdout, run.stderr)
            bad += 1
print(f"meshio {meshio.__version__}: {4 - bad} of 4 plain files checked as expected")
sys.exit(1 if bad else 0)
