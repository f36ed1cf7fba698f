"""Opens halo4d's outputs in the programs the README sends people to, all from PyPI in the
virtual environment of .ci/run: Blender (`bpy`), MeshLab (`pymeshlab`), VTK (`vtk`, what
ParaView reads files with) and pygltflib. Each Blender and MeshLab load runs in a process of
its own, so that a crash is a failure reported with its signal, not a dead CI.

  real-programs.py HALO4D DIR...   for every build folder DIR:
    - Blender imports <scene>.glb with no warning or error; every surface mesh keeps its
      vertices in order with POSITION (turned to Blender's z-up) and _W, _U, _V, _PATCH
      exactly the file's; every halo keeps its offset vertices at their indices with _T and
      _D; the curves' tubes keep _DW, _CURVE and _W; the stipples (POINTS) keep _RADIUS
      and _W;
    - MeshLab loads every file the README tells MeshLab users to open (.glb, .ply,
      -curves.ply, -stipples.ply, .obj);
    - every tetrahedron of every *-halo.vtk has positive volume under vtkMeshQuality, the
      smallest and largest equal to report.json's, and the boundary vtkDataSetSurfaceFilter
      extracts encloses positive volume, report.json's boundary volume;
    then, on the first folder: pygltflib re-saves the .glb and `halo4d check` still passes;
    Blender re-saves it (attributes, loose edges, custom properties) and `halo4d check`
    says the tetrahedra are missing, with exit status 2; and the harness itself must report
    a process that aborts as a failure.
  real-programs.py --render DIR OUT.png
    Blender (Cycles, 640 x 640) renders DIR's .glb through the scene's camera without its
    halos, as a figure would, and again without the curves. Of the curve points that the
    surfaces leave in view (at least 50), at least 75% must be dark (a pixel within 2 of
    the point's projection below luminance 0.25) with the curves, and 50 points (percent)
    more than without.

Exit status 0 when everything passes, 1 otherwise; a missing package is a failure.
"""

import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pygltflib

HERE = Path(__file__).resolve()
COMPONENT = {5126: np.float32, 5125: np.uint32, 5123: np.uint16, 5121: np.uint8}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


# -- reading the .glb as written ----------------------------------------------------------


def load_glb(path):
    g = pygltflib.GLTF2().load(str(path))
    return g, g.binary_blob()


def accessor(g, blob, i):
    """Accessor i as a numpy array (halo4d writes tightly packed views)."""
    a = g.accessors[i]
    view = g.bufferViews[a.bufferView]
    n = WIDTH[a.type]
    start = (view.byteOffset or 0) + (a.byteOffset or 0)
    values = np.frombuffer(blob, COMPONENT[a.componentType], a.count * n, start)
    return values.reshape(a.count, n) if n > 1 else values


def scene_glb(folder):
    """The scene's .glb: the one .glb of a build folder."""
    glbs = sorted(Path(folder).glob("*.glb"))
    if len(glbs) != 1:
        raise RuntimeError(f"{folder}: expected one .glb, found {[g.name for g in glbs]}")
    return glbs[0]


# -- children: each Blender or MeshLab load in its own process ------------------------------


def child(*args, timeout=900):
    """Runs this script with `args` in a new process: (ok, output, what went wrong)."""
    p = subprocess.run(
        [sys.executable, str(HERE), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    out = p.stdout + p.stderr
    if p.returncode < 0:
        return False, out, f"crashed with signal {-p.returncode}"
    if p.returncode != 0:
        return False, out, f"exit status {p.returncode}"
    return True, out, ""


def blender_reset():
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy


def blender_import(path):
    """Imports a .glb into an empty Blender scene; returns bpy."""
    bpy = blender_reset()
    result = bpy.ops.import_scene.gltf(filepath=str(path))
    if result != {"FINISHED"}:
        raise RuntimeError(f"import_scene.gltf returned {result}")
    return bpy


def mesh_attribute(mesh, name):
    a = mesh.attributes.get(name)
    if a is None or a.domain != "POINT" or a.data_type != "FLOAT":
        return None
    values = np.empty(len(mesh.vertices), np.float32)
    a.data.foreach_get("value", values)
    return values


def blender_positions(mesh):
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    # glTF is y-up, Blender z-up: the importer maps (x, y, z) to (x, -z, y).
    co = co.reshape(-1, 3)
    return np.stack([co[:, 0], co[:, 2], -co[:, 1]], axis=1)


def child_blender_import(path):
    g, blob = load_glb(path)
    bpy = blender_import(path)
    problems = []
    objects = {o.data.name: o for o in bpy.data.objects if o.type == "MESH"}
    for m in g.meshes:
        extras = m.extras or {}
        prim = m.primitives[0]
        attrs = prim.attributes
        positions = accessor(g, blob, attrs.POSITION)
        obj = objects.get(m.name)
        if obj is None:
            problems.append(f"mesh {m.name}: not imported")
            continue
        mesh = obj.data
        if "halo" in extras:
            kind, names = "halo", ["_T", "_D", "_PATCH"]
            # Every vertex a triangle uses is kept, in order; the others may only be surface
            # or inserted vertices (inside the halo, after the 2n offsets, though the surface
            # vertices of an open edge are on its side wall), which Blender drops.
            used = np.unique(accessor(g, blob, prim.indices))
            tets = accessor(g, blob, extras["halo"]["tetrahedra"])
            n = extras["halo"]["surface_vertices"]
            unused = np.setdiff1d(np.arange(len(positions)), used)
            if unused.size and unused.min() < 2 * n:
                problems.append(f"{m.name}: offset vertex {unused.min()} is on no triangle")
            # A collapsed surface vertex v has its three vertices v, n + v and 2n + v at one
            # point, and the tetrahedra name it by v: its 2n + v is on neither.
            loose = np.setdiff1d(unused, tets)
            collapsed = (loose >= 2 * n) & (loose < 3 * n)
            collapsed[collapsed] = (positions[loose[collapsed]] == positions[loose[collapsed] - 2 * n]).all(axis=1)
            if (~collapsed).any():
                problems.append(f"{m.name}: vertices on neither a triangle nor a tetrahedron, the first {loose[~collapsed][0]}")
            kept = used
        elif "surface" in extras:
            kind, names, kept = "surface", ["_W", "_U", "_V", "_PATCH"], np.arange(len(positions))
        elif "curves" in extras:
            kind, names, kept = "curves", ["_DW", "_CURVE", "_W"], np.arange(len(positions))
        elif "stipples" in extras:
            # A mesh of POINTS: vertices only.
            kind, names, kept = "stipples", ["_RADIUS", "_W"], np.arange(len(positions))
        else:
            problems.append(f"mesh {m.name}: neither surface, halo, curves nor stipples")
            continue
        keep = len(kept)
        if len(mesh.vertices) != keep:
            problems.append(
                f"{kind} {m.name}: Blender has {len(mesh.vertices)} vertices, expected {keep}"
            )
            continue
        if not np.array_equal(blender_positions(mesh), positions[kept]):
            problems.append(f"{kind} {m.name}: Blender's positions differ from the file's")
        for name in names:
            values = mesh_attribute(mesh, name)
            if values is None:
                problems.append(f"{kind} {m.name}: Blender has no float point attribute {name}")
            elif not np.array_equal(values, accessor(g, blob, attrs.__dict__[name])[kept]):
                problems.append(f"{kind} {m.name}: {name} differs from the file's")
        faces = 0 if prim.indices is None else len(accessor(g, blob, prim.indices)) // 3
        if len(mesh.polygons) != faces:
            problems.append(f"{kind} {m.name}: Blender has {len(mesh.polygons)} faces")
        print(f"  Blender {kind} {m.name}: {keep} vertices, {len(mesh.polygons)} faces, {', '.join(names)} exact")
    for p in problems:
        print(f"  PROBLEM {p}")
    sys.exit(1 if problems else 0)


def child_meshlab(path):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    vertices = sum(ms.mesh(i).vertex_number() for i in range(ms.mesh_number()))
    faces = sum(ms.mesh(i).face_number() for i in range(ms.mesh_number()))
    edges = sum(ms.mesh(i).edge_number() for i in range(ms.mesh_number()))
    print(f"  MeshLab {Path(path).name}: {ms.mesh_number()} meshes, {vertices} vertices, {faces} faces, {edges} edges")
    if vertices == 0:
        sys.exit(1)


def child_blender_resave(src, dst):
    bpy = blender_import(src)
    bpy.ops.export_scene.gltf(
        filepath=str(dst),
        export_format="GLB",
        export_attributes=True,
        export_extras=True,
        use_mesh_edges=True,
    )


def child_abort():
    os.abort()


# -- VTK --------------------------------------------------------------------------------


def vtk_halo(path, report):
    """Problems of one halo .vtk under VTK's own filters."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    reader = vtk.vtkUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    halo_name = reader.GetHeader().split(":")[0]
    surfaces = {s["name"] + "-halo": s for s in report["surfaces"]}
    if halo_name not in surfaces:
        return [f"{path.name}: title names `{halo_name}`, not a halo of report.json"]
    expected = surfaces[halo_name]["halo"]["check"]
    problems = []
    if grid.GetNumberOfCells() != expected["tets"]:
        problems.append(f"{path.name}: {grid.GetNumberOfCells()} cells, report.json says {expected['tets']}")
    quality = vtk.vtkMeshQuality()
    quality.SetInputData(grid)
    quality.SetTetQualityMeasureToVolume()
    quality.Update()
    volumes = vtk_to_numpy(quality.GetOutput().GetCellData().GetArray("Quality"))
    if (volumes <= 0).any():
        problems.append(f"{path.name}: {(volumes <= 0).sum()} of {volumes.size} tetrahedra have volume <= 0 in vtkMeshQuality")
    for what, got in (("min_volume", volumes.min()), ("max_volume", volumes.max())):
        if not np.isclose(got, expected[what], rtol=1e-9, atol=0):
            problems.append(f"{path.name}: VTK's {what} {got!r}, report.json's {expected[what]!r}")
    surface = vtk.vtkDataSetSurfaceFilter()
    surface.SetInputData(grid)
    triangles = vtk.vtkTriangleFilter()
    triangles.SetInputConnection(surface.GetOutputPort())
    triangles.Update()
    poly = triangles.GetOutput()
    points = vtk_to_numpy(poly.GetPoints().GetData()).astype(np.float64)
    faces = vtk_to_numpy(poly.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    a, b, c = (points[faces[:, k]] for k in range(3))
    enclosed = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    if not enclosed > 0:
        problems.append(f"{path.name}: the boundary from vtkDataSetSurfaceFilter encloses {enclosed} (inward faces)")
    elif not np.isclose(enclosed, expected["boundary_volume"], rtol=1e-6):
        problems.append(f"{path.name}: the boundary encloses {enclosed}, report.json says {expected['boundary_volume']}")
    print(
        f"  VTK {path.name}: {volumes.size} tetrahedra, volumes {volumes.min():.6g} to {volumes.max():.6g}, "
        f"boundary of {faces.shape[0]} triangles enclosing {enclosed:.6g}"
    )
    return problems


# -- the checks over build folders ----------------------------------------------------------


def check_folder(folder):
    folder = Path(folder)
    print(f"{folder}:")
    problems = []
    glb = scene_glb(folder)
    ok, out, why = child("--child-blender-import", glb)
    print(out.rstrip())
    # The importer logs `HH:MM:SS | LEVEL: message`; Python warnings say `Warning`.
    noise = [l for l in out.splitlines() if re.search(r"\| (WARNING|ERROR|CRITICAL)|Warning|Traceback", l)]
    if not ok:
        problems.append(f"Blender import of {glb.name}: {why}")
    if noise:
        problems.append(f"Blender import of {glb.name} warns: {noise[0]}")
    meshlab = [glb] + sorted(folder.glob("*.ply")) + sorted(folder.glob("*.obj"))
    for f in meshlab:
        ok, out, why = child("--child-meshlab", f)
        print(out.rstrip())
        if not ok:
            problems.append(f"MeshLab load of {f.name}: {why}")
    report = json.loads((folder / "report.json").read_text())
    vtks = sorted(folder.glob("*-halo.vtk"))
    if not vtks:
        problems.append("no *-halo.vtk")
    for f in vtks:
        problems += vtk_halo(f, report)
    return problems


def check_resaves(folder, halo4d):
    problems = []
    glb = scene_glb(folder)
    with tempfile.TemporaryDirectory() as tmp:
        again = Path(tmp) / "pygltflib.glb"
        g = pygltflib.GLTF2().load(str(glb))
        g.save(str(again))
        p = subprocess.run([halo4d, "check", again], capture_output=True, text=True)
        print(f"pygltflib re-save of {glb.name}: halo4d check exit {p.returncode}: {p.stdout.strip().splitlines()[-1:]}")
        if p.returncode != 0:
            problems.append(f"halo4d check fails on {glb.name} re-saved by pygltflib: {p.stdout[-300:]}{p.stderr}")
        blender = Path(tmp) / "blender.glb"
        ok, out, why = child("--child-blender-resave", glb, blender)
        if not ok:
            problems.append(f"Blender could not re-save {glb.name}: {why}\n{out[-2000:]}")
        else:
            p = subprocess.run([halo4d, "check", blender], capture_output=True, text=True)
            print(f"Blender re-save of {glb.name}: halo4d check exit {p.returncode}: {p.stderr.strip()}")
            if p.returncode != 2 or "has no tetrahedra for" not in p.stderr:
                problems.append(
                    f"halo4d check on {glb.name} re-saved by Blender: exit {p.returncode}, expected 2 with `has no tetrahedra for`: {p.stdout[-300:]}{p.stderr}"
                )
    ok, _, why = child("--child-abort")
    print(f"a child that aborts: {why or 'passed'}")
    if ok or "signal" not in why:
        problems.append("the harness did not report a child that aborts as a crash")
    return problems


# -- the render -------------------------------------------------------------------------


def place_camera(settings, corners, aspect=1.0, margin=0.05):
    """The eye and the point it looks at of halo4d's perspective camera
    (src/render/camera.rs, Placement): `distance` half-diagonals from the centre of the
    vertices' box, or, without one, fitted: moved across the view so that the vertices are
    centred and as near as every vertex allows with `margin` of the picture free on each
    side."""
    if settings.get("projection", "perspective") != "perspective":
        sys.exit("the render check takes a perspective camera")
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    centre, radius = (lo + hi) / 2, max(np.linalg.norm(hi - lo) / 2, 1e-300)
    az, el = np.radians(settings["azimuth"]), np.radians(settings["elevation"])
    towards_eye = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    if settings.get("distance") is not None:
        return centre + towards_eye * settings["distance"] * radius, centre
    forward = -towards_eye
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right = right / np.linalg.norm(right) if np.linalg.norm(right) > 0 else np.array([0.0, 1.0, 0.0])
    up = np.cross(right, forward)
    t = np.tan(np.radians(settings["fov"]) / 2) * (1 - 2 * margin)
    k = (t * aspect, t)
    v = corners - centre
    a, b, c = v @ right, v @ up, v @ forward
    shift = [kk * (np.max(x / kk - c) - np.max(-x / kk - c)) / 2 for x, kk in ((a, k[0]), (b, k[1]))]
    target = centre + right * shift[0] + up * shift[1]
    v = corners - target
    a, b, c = v @ right, v @ up, v @ forward
    d = max(np.max(np.abs(a) / k[0] - c), np.max(np.abs(b) / k[1] - c))
    d = max(d, 1.01 * radius + np.linalg.norm(target - centre))
    return target + towards_eye * d, target


def child_render(folder, out_png):
    """Renders the folder's .glb in Cycles through the scene's camera, with and without the
    curves; prints the shares of visible curve points that are dark as JSON."""
    glb = scene_glb(folder)
    g, blob = load_glb(glb)
    bpy = blender_import(glb)
    from mathutils import Vector  # after bpy, which provides it
    from mathutils.bvhtree import BVHTree

    scene = bpy.context.scene
    objects = {o.data.name: o for o in scene.objects if o.type == "MESH"}
    kinds = {m.name: next((k for k in ("surface", "halo", "curves") if k in (m.extras or {})), None) for m in g.meshes}
    surfaces = [objects[n] for n, k in kinds.items() if k == "surface"]
    curves = objects["curves"]
    for n, k in kinds.items():
        if k == "halo":
            objects[n].hide_render = True

    # halo4d's camera (src/render/camera.rs) from the scene recorded in the file: Blender's
    # frame is halo4d's (z up), since the .glb is y-up as glTF wants.
    settings = g.asset.extras["halo4d"]["scene"]["camera"]
    world_triangles = []
    points = []
    for o in surfaces:
        base = len(points)
        points += [o.matrix_world @ v.co for v in o.data.vertices]
        world_triangles += [[base + i for i in p.vertices] for p in o.data.polygons]
    corners = np.array([tuple(p) for p in points])
    eye, target = place_camera(settings, corners)
    eye = Vector(eye)
    cam_data = bpy.data.cameras.new("camera")
    cam_data.sensor_fit = "VERTICAL"
    cam_data.angle = np.radians(settings["fov"])
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    cam.location = eye
    cam.rotation_euler = (Vector(target) - eye).to_track_quat("-Z", "Y").to_euler()
    scene.camera = cam
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 2.5
    sun.rotation_euler = cam.rotation_euler
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6
    scene.world = world
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 16
    scene.cycles.use_denoising = False
    scene.render.resolution_x = scene.render.resolution_y = 640
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "PNG"
    bpy.context.view_layer.update()

    # The curves' exact points, from the polylines the .glb carries, and which of them the
    # surfaces leave in view (a ray from the eye reaches them within two tube radii).
    extras = g.meshes[[m.name for m in g.meshes].index("curves")].extras["curves"]
    tube = extras["radius"]
    p = accessor(g, blob, extras["polylines"]["POSITION"]).astype(np.float64)
    tree = BVHTree.FromPolygons(points, world_triangles)
    visible = []
    for x, y, z in p:
        q = Vector((x, -z, y))
        d = (q - eye).length
        hit, _, _, at = tree.ray_cast(eye, (q - eye) / d, d + tube)
        if hit is None or at >= d - 2 * tube:
            visible.append(q)
    from bpy_extras.object_utils import world_to_camera_view

    def luminance(path):
        image = bpy.data.images.load(str(path))
        w, h = image.size
        px = np.array(image.pixels[:], dtype=np.float32).reshape(h, w, 4)
        return px[..., :3] @ np.array([0.2126, 0.7152, 0.0722], np.float32)

    def dark_share(lum):
        h, w = lum.shape
        dark = seen = 0
        for q in visible:
            x, y, depth = world_to_camera_view(scene, cam, q)
            i, j = int(y * h), int(x * w)
            if depth <= 0 or not (2 <= i < h - 2 and 2 <= j < w - 2):
                continue
            seen += 1
            dark += lum[i - 2 : i + 3, j - 2 : j + 3].min() < 0.25
        return dark / max(seen, 1), seen

    shares = {"points": len(p)}
    for label, show in (("with", True), ("without", False)):
        curves.hide_render = not show
        path = Path(out_png) if show else Path(out_png).with_name("without-curves.png")
        scene.render.filepath = str(path)
        bpy.ops.render.render(write_still=True)
        lum = luminance(path)
        share, seen = dark_share(lum)
        shares[label] = {"dark_on_curves": share, "points_in_view": seen, "dark_anywhere": float((lum < 0.25).mean())}
    print("RESULT " + json.dumps(shares))


def check_render(folder, out_png):
    ok, out, why = child("--child-render", folder, out_png)
    line = next((l for l in out.splitlines() if l.startswith("RESULT ")), None)
    if not ok or line is None:
        return [f"Blender render of {folder}: {why or 'no result'}\n{out[-3000:]}"]
    r = json.loads(line[len("RESULT ") :])
    w, wo = r["with"], r["without"]
    print(
        f"Blender (Cycles) render of {scene_glb(folder).name}: {w['points_in_view']} of {r['points']} curve points in view, "
        f"dark at {w['dark_on_curves']:.1%} of them with the curves, {wo['dark_on_curves']:.1%} without; "
        f"dark pixels overall {w['dark_anywhere']:.1%} and {wo['dark_anywhere']:.1%}; picture {out_png}"
    )
    problems = []
    if w["points_in_view"] < 50:
        problems.append(f"only {w['points_in_view']} curve points in view")
    if not (w["dark_on_curves"] >= 0.75 and w["dark_on_curves"] - wo["dark_on_curves"] >= 0.5):
        problems.append("the curves do not show in Blender's render")
    return problems


def main():
    args = sys.argv[1:]
    children = {
        "--child-blender-import": child_blender_import,
        "--child-meshlab": child_meshlab,
        "--child-blender-resave": child_blender_resave,
        "--child-render": child_render,
        "--child-abort": child_abort,
    }
    if args and args[0] in children:
        children[args[0]](*args[1:])
        return
    # Fail at once, not per file, when a program is missing.
    import bpy  # noqa: F401
    import pymeshlab  # noqa: F401
    import vtk  # noqa: F401

    if args[:1] == ["--render"] and len(args) == 3:
        problems = check_render(args[1], args[2])
    elif len(args) >= 2 and not args[0].startswith("--"):
        halo4d, folders = args[0], args[1:]
        problems = []
        for f in folders:
            problems += [f"{f}: {p}" for p in check_folder(f)]
        problems += check_resaves(folders[0], halo4d)
    else:
        print(__doc__)
        sys.exit(2)
    for p in problems:
        print(f"FAILED {p}")
    print(f"real programs: {'failed' if problems else 'all passed'}")
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
