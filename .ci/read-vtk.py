"""Reads every halo .vtk given on the command line with meshio (installed by .ci/run) and
checks the halo layout: tetrahedra only, point data t and d_orig with one value per point,
field data surface_vertices (n) and layers (2) with 3n <= points, t 0 on the first n points
(the negative offsets), 1 on the next n (positive) unless 0.5 (collapsed), 0.5 on the next
n (the surface), and within [0, 1] on the inserted points after them.
Exits non-zero when any file fails or none is given."""

import sys

import meshio
import numpy as np

bad = 0
files = sys.argv[1:]
for path in files:
    try:
        mesh = meshio.read(path, file_format="vtk")
        types = [block.type for block in mesh.cells]
        assert types == ["tetra"], f"cell blocks {types}, expected only tetra"
        points = len(mesh.points)
        tets = len(mesh.cells[0].data)
        for name in ("t", "d_orig"):
            assert name in mesh.point_data, f"no point data `{name}`"
            values = np.asarray(mesh.point_data[name]).ravel()
            assert values.size == points, f"{name}: {values.size} values for {points} points"
            assert np.isfinite(values).all(), f"{name} has non-finite values"
        for name in ("surface_vertices", "layers"):
            assert name in mesh.field_data, f"no field data `{name}`"
        n = int(np.asarray(mesh.field_data["surface_vertices"]).ravel()[0])
        layers = int(np.asarray(mesh.field_data["layers"]).ravel()[0])
        assert layers == 2, f"layers {layers}, expected 2"
        assert 3 * n <= points, f"surface_vertices {n} but {points} points"
        t = np.asarray(mesh.point_data["t"]).ravel()
        collapsed = t[:n] == 0.5
        assert (t[:n][~collapsed] == 0.0).all(), "t of a negative offset is not 0"
        assert (t[n : 2 * n][~collapsed] == 1.0).all(), "t of a positive offset is not 1"
        assert (t[n : 2 * n][collapsed] == 0.5).all(), "t of a collapsed offset is not 0.5"
        assert (t[2 * n : 3 * n] == 0.5).all(), "t of a surface vertex is not 0.5"
        assert ((t[3 * n :] >= 0.0) & (t[3 * n :] <= 1.0)).all(), "t of an inserted vertex outside [0, 1]"
        print(f"{path}: {points} points, {tets} tetra, point data t and d_orig, surface_vertices {n}, layers 2")
    except Exception as e:  # report every file, then fail
        print(f"{path}: {type(e).__name__}: {e}")
        bad += 1
if not files:
    print("no .vtk files given")
    bad += 1
print(f"meshio {meshio.__version__}: {len(files) - min(bad, len(files))} passed, {bad} failed")
sys.exit(1 if bad else 0)
