"""Motion pictures opened by the programs their users open them in.

Usage: motion-check.py FOLDER [FOLDER...]   (each what `halo4d slice --out FOLDER` wrote)

For every still of every surface in FOLDER/motion.json: MeshLab (pymeshlab) and VTK
(vtkPLYReader) read its PLY with the points and segments motion.json counts, every point
finite; Blender (bpy) imports the surface's -motion.glb with one object per still, at its
level, and a mesh for each still with curves; the strip's PNG opens (Pillow) at the size of its panels and draws ink
in every panel that has curves; a film (an animated PNG) has the frames motion.json lists,
each with curves drawn. Fails when motion.json says the checks failed.
"""

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
from PIL import Image


def check_still(path, still):
    import pymeshlab
    import vtk
    import vtk.util.numpy_support

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


def check_glb(path, stills):
    """Blender's import, in a process of its own: bpy and the other programs' libraries
    (Embree among them) do not load into one process."""
    p = subprocess.run(
        [sys.executable, __file__, "--child-glb", str(path), json.dumps(stills)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    if p.returncode != 0:
        return [f"Blender: exit status {p.returncode}: {(p.stdout + p.stderr).strip()[-500:]}"]
    return json.loads(p.stdout.strip().splitlines()[-1])


def child_glb(path, stills):
    import bpy

    stills = json.loads(stills)

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=str(path))
    objects = {o.name: o for o in bpy.data.objects if o.name.startswith("still-")}
    problems = []
    if len(objects) != len(stills):
        problems.append(f"Blender imports {len(objects)} stills, motion.json has {len(stills)}")
    for k, still in enumerate(stills):
        o = objects.get(f"still-{k:02}")
        if o is None:
            continue
        if abs(o.get("level", math.nan) - still["level"]) > 1e-12 * max(1.0, abs(still["level"])):
            problems.append(f"still-{k:02}: level {o.get('level')} in Blender, {still['level']} in motion.json")
        if still["curves"] > 0 and (o.type != "MESH" or len(o.data.polygons) == 0):
            problems.append(f"still-{k:02}: {still['curves']} curves but no tubes in Blender")
    print(json.dumps(problems))


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
        problems += [f"{name}-motion.glb: {p}" for p in check_glb(folder / f"{name}-motion.glb", surface["stills"])]
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
        if surface.get("film"):
            film = Image.open(folder / f"{name}-film.png")
            frames = getattr(film, "n_frames", 1)
            if frames != len(surface["film"]):
                problems.append(f"{name}-film.png: Pillow reads {frames} frames, motion.json has {len(surface['film'])}")
            for k in range(frames):
                film.seek(k)
                if int((np.asarray(film.convert("L")) < 200).sum()) < 20 and surface["film"][k]["curves"] > 0:
                    problems.append(f"{name}-film.png: frame {k} draws nothing")
        print(
            f"  {folder.name}/{name}: {panels} stills, {sum(s['points'] for s in surface['stills'])} points, "
            f"{sum(s['crossings'] for s in surface['stills'])} crossings; MeshLab and VTK read every still, Blender its .glb"
        )
    return problems


def main():
    if sys.argv[1:2] == ["--child-glb"]:
        child_glb(*sys.argv[2:])
        return
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
