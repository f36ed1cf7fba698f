"""Reads every halo .vtk given on the command line with meshio (installed by .ci/run) and
checks the halo layout: tetrahedra only, point data t and d_orig with one value per point,
t in {0, 0.5, 1}, and field data surface_vertices with 2 * surface_vertices <= points.
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
        t = np.asarray(mesh.point_data["t"]).ravel()
        assert np.isin(t, [0.0, 0.5, 1.0]).all(), "t outside {0, 0.5, 1}"
        assert "surface_vertices" in mesh.field_data, "no field data `surface_vertices`"
        n = int(np.asarray(mesh.field_data["surface_vertices"]).ravel()[0])
        assert 2 * n <= points, f"surface_vertices {n} but {points} points"
        print(f"{path}: {points} points, {tets} tetra, point data t and d_orig, surface_vertices {n}")
    except Exception as e:  # report every file, then fail
        print(f"{path}: {type(e).__name__}: {e}")
        bad += 1
if not files:
    print("no .vtk files given")
    bad += 1
print(f"meshio {meshio.__version__}: {len(files) - min(bad, len(files))} passed, {bad} failed")
sys.exit(1 if bad else 0)
