"""Motion pictures opened by the programs their users open them in.

Usage: motion-check.py FOLDER [FOLDER...]   (each what `halo4d slice --out FOLDER` wrote)

For every still of every surface in FOLDER/motion.json: MeshLab (pymeshlab) and VTK
(vtkPLYReader) read its PLY with the points and segments motion.json counts,
every point finite; the strip's PNG opens (Pillow) at the size of its panels and draws ink
in every panel that has curves. Fails when motion.json says the checks failed.
"""

import json
import math
import sys
from pathlib import Path

import numpy as np
import pymeshlab
import vtk
import vtk.util.numpy_support
from PIL import Image


def check_still(path, still):
    problems = []
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    m = ms.current_mesh()
    if (m.vertex_number(), m.edge_number()) != (still["points"], still["segments"]):
        problems.append(
            f"MeshLab reads {m.vertex_number()} points and {m.edge_number()} edges, "
            f"motion.json says {still['points']} and {still['segments']}"
        )
    reader = vtk.vtkPLYReader()
    reader.SetFileName(str(path))
    reader.Update()
    if reader.GetOutput().GetNumberOfPoints() != still["points"]:
        problems.append(f"VTK reads {reader.GetOutput().GetNumberOfPoints()} points")
    data = reader.GetOutput().GetPoints()
    points = vtk.util.numpy_support.vtk_to_numpy(data.GetData()) if data else np.zeros((0, 3))
    if not np.isfinite(points).all():
        problems.append("VTK reads a point that is not finite")
    return problems


def check_folder(folder):
    folder = Path(folder)
    motion = json.loads((folder / "motion.json").read_text())
    problems = []
    if not motion["verified"]:
        problems.append("motion.json: not verified")
    for surface in motion["surfaces"]:
        name = surface["name"]
        problems += [f"{name}: {f}" for f in surface["failures"]]
        for still in surface["stills"]:
            problems += [f"{still['file']}: {p}" for p in check_still(folder / still["file"], still)]
        picture = np.asarray(Image.open(folder / f"{name}-motion.png").convert("L"))
        panels = len(surface["stills"])
        columns = min(panels, 5)
        rows = math.ceil(panels / columns)
        height, width = picture.shape
        side = width // columns
        band = (height // rows - side) // 2
        for k, still in enumerate(surface["stills"]):
            x0, y0 = (k % columns) * side, (k // columns) * (side + 2 * band) + band
            inside = picture[y0 + 2 : y0 + side - 2, x0 + 2 : x0 + side - 2]
            inked = int((inside < 200).sum())
            if still["curves"] > 0 and inked < 20:
                problems.append(f"{name}: panel {k} ({still['curves']} curves) draws {inked} pixels")
        print(
            f"  {folder.name}/{name}: {panels} stills, {sum(s['points'] for s in surface['stills'])} points, "
            f"{sum(s['crossings'] for s in surface['stills'])} crossings; MeshLab and VTK read every still"
        )
    return problems


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        sys.exit(2)
    problems = []
    for folder in sys.argv[1:]:
        problems += [f"{folder}: {p}" for p in check_folder(folder)]
    for p in problems:
        print(f"FAILED {p}")
    print(f"motion pictures: {'failed' if problems else 'all passed'}")
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
