"""The Blender add-on's check, in a Python with the `bpy` module, halo4d and NumPy:

    python blender/check_addon.py

It registers blender/halo4d_blender and adds the default scene with Add › Mesh › 4D
Surface; its meshes must be those of the `.glb` that halo4d's build of the same view writes,
imported by Blender's glTF importer (vertices to the bit, in the same order, triangles, w,
the halo's boundary). Turning xw by 20 degrees must rebuild them from the same sampling as
halo4d builds that view, Verify must find the view verified, a new tolerance must sample
again. Every source kind (each catalogue surface, a formula, a 4D mesh, a scene file) must
build as halo4d builds it, bad input must be a report naming its field, and blender/pack.py
must make a zip that Blender's extension tool validates and installs. Exits 1 at the first
failure, saying what failed. Runs in a process of its own (bpy clashes with vtk and
pymeshlab in one process).
"""

import json
import os
import re
import subprocess
import sys
import tempfile
import time
import traceback
import zipfile

import bpy
import halo4d
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
done = []  # one line per check passed, for the summary


def check(condition, message):
    if not condition:
        raise AssertionError(message)


def mesh_arrays(obj):
    """(vertices (n, 3) float32, triangles (m, 3)) of a mesh object, in Blender's order."""
    mesh = obj.data
    co = np.empty(3 * len(mesh.vertices), dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    sizes = np.empty(len(mesh.polygons), dtype=np.int32)
    mesh.polygons.foreach_get("loop_total", sizes)
    check(np.all(sizes == 3), f"{obj.name}: not every face is a triangle")
    tris = np.empty(3 * len(mesh.polygons), dtype=np.int32)
    mesh.polygons.foreach_get("vertices", tris)
    return co.reshape(-1, 3), tris.reshape(-1, 3)


def point_attribute(obj, name):
    attribute = obj.data.attributes.get(name)
    check(attribute is not None, f"{obj.name}: no attribute `{name}`")
    check(attribute.domain == "POINT", f"{obj.name}: `{name}` is on {attribute.domain}, not POINT")
    values = np.empty(
        len(attribute.data) * (4 if attribute.data_type == "FLOAT_COLOR" else 1), dtype=np.float32
    )
    attribute.data.foreach_get("color" if attribute.data_type == "FLOAT_COLOR" else "value", values)
    return values


def import_glb(path):
    """The objects Blender's glTF importer makes of `path`, by name without `.001`."""
    before = set(bpy.data.objects)
    result = bpy.ops.import_scene.gltf(filepath=path)
    check(result == {"FINISHED"}, f"importing {path}: {result}")
    new = [o for o in bpy.data.objects if o not in before]
    return {re.sub(r"\.\d{3}$", "", o.name): o for o in new}


def remove(objects):
    for obj in objects:
        data = obj.data
        bpy.data.objects.remove(obj)
        if isinstance(data, bpy.types.Mesh) and data.users == 0:
            bpy.data.meshes.remove(data)


def same_as_glb(built, children, label):
    """The add-on's surfaces equal the `.glb` that `built.write` makes: vertices (to the bit
    of float32, in the same order), triangles, w; the halo's boundary is the glb's halo."""
    with tempfile.TemporaryDirectory(prefix="halo4d-check-addon-") as folder:
        built.write(folder)
        glb = os.path.join(folder, f"{built.scene.name}.glb")
        imported = import_glb(glb)
    try:
        for index, surface in enumerate(built.surfaces):
            ours = children[("surface", index)]
            check(
                surface.name in imported,
                f"{label}: the .glb has no mesh `{surface.name}` (has {sorted(imported)})",
            )
            theirs = imported[surface.name]
            check(
                np.array_equal(theirs.matrix_world, ours.matrix_world),
                f"{label}: {surface.name}: the objects' transforms differ",
            )
            co, tris = mesh_arrays(ours)
            glb_co, glb_tris = mesh_arrays(theirs)
            check(
                co.shape == glb_co.shape,
                f"{label}: {surface.name}: {len(co)} vertices, the .glb {len(glb_co)}",
            )
            diff = float(np.abs(co - glb_co).max()) if len(co) else 0.0
            check(
                np.array_equal(co, glb_co),
                f"{label}: {surface.name}: vertices differ from the .glb's by up to {diff:.3g}",
            )
            check(
                np.array_equal(tris, glb_tris), f"{label}: {surface.name}: triangles differ from the .glb's"
            )
            check(
                np.array_equal(point_attribute(ours, "w"), point_attribute(theirs, "_W")),
                f"{label}: {surface.name}: attribute w differs from the .glb's _W",
            )
            halo = children[("halo", index)]
            glb_halo = imported.get(f"{surface.name}-halo")
            check(glb_halo is not None, f"{label}: the .glb has no `{surface.name}-halo`")
            halo_co, halo_tris = mesh_arrays(halo)
            glb_halo_co, _ = mesh_arrays(glb_halo)
            check(
                np.array_equal(np.unique(halo_co, axis=0), np.unique(glb_halo_co, axis=0)),
                f"{label}: {surface.name}-halo: the boundary's {len(halo_co)} vertices are not the .glb halo's {len(glb_halo_co)}",
            )
            done.append(
                f"{label}: {surface.name}: {len(co)} vertices and {len(tris)} triangles equal the .glb's "
                f"(max difference {diff}), w equals _W; halo boundary {len(halo_tris)} triangles on the .glb halo's {len(glb_halo_co)} vertices"
            )
    finally:
        remove(imported.values())


def same_as_build(built, children, label):
    """The add-on's surfaces are `built`'s surfaces: positions, triangles, counts."""
    for index, surface in enumerate(built.surfaces):
        co, tris = mesh_arrays(children[("surface", index)])
        check(
            co.shape == surface.positions.shape,
            f"{label}: {surface.name}: {len(co)} vertices, halo4d {len(surface.positions)}",
        )
        check(
            tris.shape == surface.triangles.shape,
            f"{label}: {surface.name}: {len(tris)} triangles, halo4d {len(surface.triangles)}",
        )
        check(
            np.array_equal(co, surface.positions.astype(np.float32)),
            f"{label}: {surface.name}: vertices differ from halo4d's positions by up to "
            f"{np.abs(co - surface.positions).max():.3g}",
        )
        check(
            np.array_equal(tris, surface.triangles.astype(np.int32)),
            f"{label}: {surface.name}: triangles differ from halo4d's",
        )
    return co


def check_curves(built, children, label):
    obj = children[("curves", 0)]
    curve = obj.data
    points = np.concatenate([c.points for c in built.curves]).astype(np.float32)
    splines = []
    for spline in curve.splines:
        check(spline.type == "POLY", f"{label}: a curve spline is {spline.type}, not POLY")
        co = np.empty(4 * len(spline.points), dtype=np.float32)
        spline.points.foreach_get("co", co)
        splines.append(co.reshape(-1, 4)[:, :3])
    ours = np.concatenate(splines)
    in_splines = {row.tobytes() for row in ours}
    missing = sum(row.tobytes() not in in_splines for row in points)
    check(
        len(curve.splines) >= len(built.curves),
        f"{label}: {len(curve.splines)} splines for {len(built.curves)} curves",
    )
    check(missing == 0, f"{label}: {missing} of the {len(points)} curve points are in no spline")
    check(curve.bevel_depth > 0, f"{label}: the curves have no bevel")
    check(len(curve.materials) == 12 and all(curve.materials), f"{label}: the curves lack their 12 inks")
    bands = {s.material_index for s in curve.splines}
    done.append(
        f"{label}: {len(built.curves)} curves, {len(points)} points, as {len(curve.splines)} poly splines "
        f"in {len(bands)} inks, bevel depth {curve.bevel_depth:.4f}"
    )


class Layout:
    """A stand-in for a UI layout that records labels and checks that every property and
    operator drawn exists, so that the panel and the dialog can be drawn without a window."""

    def __init__(self, labels=None):
        self.labels = [] if labels is None else labels

    def label(self, text="", **_):
        self.labels.append(text)

    def prop(self, data, name, **_):
        check(name in data.bl_rna.properties, f"the UI draws a property `{name}` that {data} lacks")

    def operator(self, idname, **_):
        group, name = idname.split(".")
        check(
            hasattr(getattr(bpy.ops, group), name),
            f"the UI draws an operator `{idname}` that is not registered",
        )

    def box(self, **_):
        return self

    row = column = grid_flow = box


def draw_panel(root):
    """The labels the sidebar panel draws for `root`."""
    from types import SimpleNamespace

    from halo4d_blender import panel

    layout = Layout()
    panel.VIEW3D_PT_halo4d.draw(SimpleNamespace(layout=layout), SimpleNamespace(active_object=root))
    return layout.labels


def draw_dialog():
    """The Add dialog, drawn for every source kind."""
    from types import SimpleNamespace

    from halo4d_blender import operators

    rna = bpy.ops.mesh.halo4d_add.get_rna_type()
    kinds = [item.identifier for item in rna.properties["source"].enum_items]
    for kind in kinds:
        fake = SimpleNamespace(layout=Layout(), source=kind)
        fake.layout.prop = lambda data, name, **_: check(
            name in rna.properties, f"the dialog draws `{name}`, no property of the operator"
        )
        operators.MESH_OT_halo4d_add.draw(fake, bpy.context)
    return kinds


def catalogue_scenes_are_the_fixtures():
    with open(os.path.join(HERE, "halo4d_blender", "catalogue_scenes.json"), encoding="utf-8") as f:
        settings = json.load(f)
    types = {entry["type"] for entry in halo4d.catalogue()}
    check(
        set(settings) == types, f"catalogue_scenes.json has {sorted(settings)}, the catalogue {sorted(types)}"
    )
    for name, entry in settings.items():
        fixture = halo4d.Scene(os.path.join(REPO, entry["fixture"])).to_dict()
        for key in ("view", "camera"):
            check(
                fixture[key] == entry[key],
                f"catalogue_scenes.json: {name}: the {key} is not that of {entry['fixture']}; copy it from there",
            )
    done.append(
        f"catalogue_scenes.json: the views and cameras of {len(settings)} catalogue surfaces equal their fixtures'"
    )


def run():
    import halo4d_blender
    from halo4d_blender import build, operators

    # 1. Register.
    halo4d_blender.register()
    check(hasattr(bpy.types.Object, "halo4d"), "register() did not add Object.halo4d")
    check(
        operators.menu in bpy.types.VIEW3D_MT_mesh_add._dyn_ui_initialize(), "4D Surface is not in Add › Mesh"
    )
    check(hasattr(bpy.types, "VIEW3D_PT_halo4d"), "the sidebar panel is not registered")
    catalogue_scenes_are_the_fixtures()

    # 2. The default scene, against halo4d's build and its .glb.
    started = time.perf_counter()
    check(bpy.ops.mesh.halo4d_add() == {"FINISHED"}, "mesh.halo4d_add did not finish")
    seconds = time.perf_counter() - started
    root = bpy.context.view_layer.objects.active
    check(root is not None and root.halo4d.is_root, "the added object is not a halo4d root")
    check(root.halo4d.error == "", f"the build failed: {root.halo4d.error}")
    children = build.children(root)
    expected = halo4d.Scene().build()
    for index, surface in enumerate(expected.surfaces):
        check(("surface", index) in children, f"no mesh object for surface {index}")
        obj = children[("surface", index)]
        check(obj.name == surface.name, f"surface {index} is named {obj.name}, not {surface.name}")
        halo = children[("halo", index)]
        check(halo.name == f"{surface.name}-halo", f"the halo is named {halo.name}")
        check(halo.hide_viewport and halo.hide_render, f"{halo.name} is not hidden")
        check(
            obj.data.color_attributes.get("w_colour") is not None, f"{obj.name}: no colour attribute w_colour"
        )
        check(
            obj.active_material and obj.active_material.name == "halo4d w",
            f"{obj.name}: not the material `halo4d w`",
        )
        nodes = obj.active_material.node_tree.nodes
        attribute = [n for n in nodes if n.type == "ATTRIBUTE"]
        check(
            attribute
            and attribute[0].attribute_name == "w_colour"
            and attribute[0].outputs["Color"].is_linked,
            f"{obj.name}: the material does not read w_colour",
        )
    first = same_as_build(expected, children, "default view")
    same_as_glb(expected, children, "default view")
    check_curves(expected, children, "default view")
    done.append(
        f"mesh.halo4d_add: the default scene in {seconds:.2f} s, {len(children)} objects under `{root.name}`"
    )

    # 3. Turn the view: rebuilt from the cached sampling, equal to halo4d's build of that view.
    sampled = build._cache[root.name].sampled
    before = root.halo4d.xw
    started = time.perf_counter()
    root.halo4d.xw += 20
    seconds = time.perf_counter() - started
    check(root.halo4d.error == "", f"the rebuild failed: {root.halo4d.error}")
    check(build._cache[root.name].sampled is sampled, "turning the view sampled again")
    scene = halo4d.Scene().to_dict()
    scene["view"]["rotation"]["xw"] = root.halo4d.xw  # the panel's value: single precision
    turned = halo4d.Scene(scene).build()
    children = build.children(root)
    moved = same_as_build(turned, children, "xw + 20")
    change = float(np.abs(moved - first).max())
    check(change > 1e-2, f"turning xw by 20 degrees moved no vertex more than {change:.3g}")
    same_as_glb(turned, children, "xw + 20")
    check_curves(turned, children, "xw + 20")
    done.append(
        f"xw {before:.2f} -> {root.halo4d.xw:.2f}: rebuilt in {seconds:.2f} s from the same sampling, "
        f"vertices moved up to {change:.3f}, equal to halo4d.Scene(that view).build()"
    )

    # 4. Verify (with the root active, as the panel shows it).
    bpy.context.view_layer.objects.active = root
    started = time.perf_counter()
    check(bpy.ops.object.halo4d_verify() == {"FINISHED"}, "object.halo4d_verify did not finish")
    check(root.halo4d.verdict == "verified", f"Verify: {root.halo4d.verdict!r}")
    done.append(f"object.halo4d_verify: {root.halo4d.verdict!r} in {time.perf_counter() - started:.2f} s")
    labels = draw_panel(root)
    check("verified" in labels and root.halo4d.status in labels, f"the panel shows {labels}")
    done.append(f"the panel draws {labels}; the Add dialog draws for {', '.join(draw_dialog())}")

    # A wider halo builds from the same sampling: its boundary is that of halo4d's build.
    from halo4d_blender import geometry

    root.halo4d.gap_px = 12.0
    check(root.halo4d.error == "", f"the halo's rebuild failed: {root.halo4d.error}")
    check(build._cache[root.name].sampled is sampled, "a new halo width sampled again")
    wide = json.loads(json.dumps(scene))
    wide["halo"]["gap_px"] = 12.0
    wide_halo = halo4d.Scene(wide).build().surfaces[0].halo
    expected_co, _ = geometry.halo_boundary(wide_halo.vertices, wide_halo.tetrahedra)
    halo_co, _ = mesh_arrays(build.children(root)[("halo", 0)])
    check(
        np.array_equal(halo_co, np.asarray(expected_co, dtype=np.float32)),
        "gap 12 px: the halo's boundary is not that of halo4d's build",
    )
    narrow_co, _ = geometry.halo_boundary(
        turned.surfaces[0].halo.vertices, turned.surfaces[0].halo.tetrahedra
    )
    check(
        not np.array_equal(halo_co, np.asarray(narrow_co, dtype=np.float32)),
        "gap 12 px: the halo did not change",
    )
    root.halo4d.gap_px = 8.0
    same_as_build(turned, build.children(root), "gap back to 8 px")
    done.append(
        f"gap 8 -> 12 px: the halo rebuilt from the same sampling, its {len(halo_co)} boundary "
        "vertices equal to halo4d's build with that gap"
    )

    # A tolerance samples again, and back to the scene's samples as the scene does.
    root.halo4d.tolerance = 4e-3
    check(root.halo4d.error == "", f"the tolerance's rebuild failed: {root.halo4d.error}")
    check(build._cache[root.name].sampled is not sampled, "a new tolerance did not sample again")
    coarse = json.loads(json.dumps(scene))
    for sampling in [coarse["sampling"]] + [s["sampling"] for s in coarse["surfaces"] if "sampling" in s]:
        sampling["tolerance"] = root.halo4d.tolerance
    coarse_built = halo4d.Scene(coarse).build()
    same_as_build(coarse_built, build.children(root), "tolerance 4e-3")
    check(root.halo4d.verdict == "", "a rebuild kept the previous view's verdict")
    root.halo4d.tolerance = 1e-3
    same_as_build(turned, build.children(root), "tolerance back to 1e-3")
    done.append(
        f"tolerance 4e-3: sampled again, {len(coarse_built.surfaces[0].triangles)} triangles "
        f"(1e-3: {len(turned.surfaces[0].triangles)}), each equal to halo4d's"
    )

    # 5. Bad input: a report naming the field, not an exception out of the add-on.
    objects = len(bpy.data.objects)
    for kwargs, field in [
        ({"source": "FORMULA", "x": "sin(u"}, "surfaces[0].surface.x"),
        ({"source": "FORMULA", "parameters": "{R: 1}"}, "parameters"),
        (
            {
                "source": "SCENE",
                "scene_path": os.path.join(REPO, "fixtures", "broken", "fermat-n-out-of-range.json"),
            },
            "surfaces[0].surface.n",
        ),
    ]:
        try:
            result = bpy.ops.mesh.halo4d_add(**kwargs)
        except RuntimeError as e:  # bpy raises an operator's ERROR report
            report = str(e)
        else:
            raise AssertionError(f"mesh.halo4d_add({kwargs}) gave {result}, no error report")
        check(report.startswith("Error: halo4d: "), f"{kwargs}: not the add-on's report: {report}")
        check(field in report, f"{kwargs}: the report does not name `{field}`: {report}")
        check("Traceback" not in report, f"{kwargs}: a traceback reached the report: {report}")
        done.append(f"bad input {kwargs}: report {report.strip()!r}")
    check(len(bpy.data.objects) == objects, "a failed add left objects behind")
    root.halo4d.tolerance = 0.0
    check(
        root.halo4d.error.startswith("sampling.tolerance"),
        f"tolerance 0: the panel's error is {root.halo4d.error!r}",
    )
    done.append(f"tolerance 0 in the panel: error {root.halo4d.error!r}, the objects kept")
    root.halo4d.tolerance = 1e-3
    check(root.halo4d.error == "", f"back to 1e-3: {root.halo4d.error}")

    # Every source kind: each catalogue surface in its fixture's view, a formula, a 4D mesh
    # file, a scene file naming a mesh relative to itself; each as halo4d builds it.
    from halo4d_blender import scenes

    clifford = os.path.join(REPO, "fixtures", "meshes", "clifford-torus.4off")
    scene_file = os.path.join(REPO, "fixtures", "scenes", "mesh-clifford-torus.json")
    kinds = [
        ({"source": "CATALOGUE", "surface_type": e["type"]}, scenes.catalogue_scene(e["type"]))
        for e in halo4d.catalogue()
    ]
    kinds += [
        (
            {"source": "FORMULA"},
            scenes.formula_scene(
                "formula",
                "(R + r*cos(v))*cos(u)",
                "(R + r*cos(v))*sin(u)",
                "r*sin(v)*cos(n*u)",
                "r*sin(v)*sin(n*u)",
                ("0", "2*pi"),
                ("0", "2*pi"),
                ("periodic", "periodic"),
                '{"R": 1, "r": 0.45, "n": 2}',
            ),
        ),
        ({"source": "MESH", "mesh_path": clifford}, scenes.mesh_scene(clifford)),
        ({"source": "SCENE", "scene_path": scene_file}, scene_file),
    ]
    made = []
    for kwargs, scene in kinds:
        check(bpy.ops.mesh.halo4d_add(**kwargs) == {"FINISHED"}, f"mesh.halo4d_add({kwargs}) did not finish")
        added = bpy.context.view_layer.objects.active
        check(added.halo4d.error == "", f"{kwargs}: {added.halo4d.error}")
        built = halo4d.Scene(scene).build()
        same_as_build(built, build.children(added), f"{kwargs}")
        made.append(
            f"{added.name} ({sum(len(s.positions) for s in built.surfaces)} vertices, {len(built.curves)} curves)"
        )
    done.append(f"sources: {len(made)} scenes, each equal to halo4d's build: {', '.join(made)}")

    # 6. The zip.
    with tempfile.TemporaryDirectory(prefix="halo4d-pack-") as folder:
        out = os.path.join(folder, "halo4d_blender.zip")
        subprocess.run(
            [sys.executable, os.path.join(HERE, "pack.py"), out], check=True, stdout=subprocess.DEVNULL
        )
        with zipfile.ZipFile(out) as archive:
            names = archive.namelist()
            manifest = (
                archive.read("blender_manifest.toml").decode("utf-8")
                if "blender_manifest.toml" in names
                else ""
            )
        for name in ("blender_manifest.toml", "__init__.py"):
            check(name in names, f"the zip has no {name} at its top level: {names}")
        check(
            not any("__pycache__" in n or n.endswith(".pyc") for n in names), f"the zip holds caches: {names}"
        )
        check(
            'id = "halo4d"' in manifest and 'schema_version = "1.0.0"' in manifest,
            "the manifest lacks its id or schema",
        )
        tool = os.path.join(
            bpy.utils.system_resource("SCRIPTS"), "addons_core", "bl_pkg", "cli", "blender_ext.py"
        )
        check(os.path.isfile(tool), f"Blender's extension tool is not at {tool}")
        validated = subprocess.run([sys.executable, tool, "validate", out], capture_output=True, text=True)
        check(validated.returncode == 0, f"blender_ext validate: {validated.stdout}{validated.stderr}")
        done.append(
            f"pack.py: {len(names)} files, the manifest and __init__.py at the top; blender_ext validate: {validated.stdout.strip()}"
        )

        # Installed from the zip as Blender's Install from Disk installs it, in a user
        # folder of its own and a process of its own.
        resources = os.path.join(folder, "user")
        installed = subprocess.run(
            [sys.executable, os.path.abspath(__file__), "--install", out],
            capture_output=True,
            text=True,
            env={**os.environ, "BLENDER_USER_RESOURCES": resources},
            timeout=300,
        )
        lines = [line for line in installed.stdout.splitlines() if line.startswith("installed: ")]
        check(
            installed.returncode == 0 and lines,
            f"installing the zip as an extension failed:\n{installed.stdout[-3000:]}{installed.stderr[-3000:]}",
        )
        done.append(lines[-1])


def install(archive):
    """In a fresh user folder (BLENDER_USER_RESOURCES): installs `archive` as an extension,
    enabled, and adds the default scene with it."""
    check(
        os.environ.get("BLENDER_USER_RESOURCES"),
        "--install needs BLENDER_USER_RESOURCES, a folder to install into",
    )
    result = bpy.ops.extensions.package_install_files(
        filepath=archive, repo="user_default", enable_on_install=True
    )
    check(result == {"FINISHED"}, f"package_install_files: {result}")
    module = "bl_ext.user_default.halo4d"
    check(module in sys.modules, f"the extension is not loaded as {module}")
    check(bpy.ops.mesh.halo4d_add() == {"FINISHED"}, "the installed mesh.halo4d_add did not finish")
    root = bpy.context.view_layer.objects.active
    surfaces = [o for o in root.children if o.get("halo4d_role") == "surface"]
    expected = len(halo4d.Scene().build().surfaces[0].positions)
    check(
        len(surfaces) == 1 and len(surfaces[0].data.vertices) == expected,
        "the installed add-on's mesh is not the default scene's",
    )
    import addon_utils

    addon_utils.disable(module)
    print(f"installed: the zip as extension {module}, its 4D Surface made {expected} vertices; disabled")


def main():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if sys.argv[1:2] == ["--install"]:
        try:
            install(sys.argv[2])
            status = 0
        except Exception:  # noqa: BLE001
            traceback.print_exc()
            status = 1
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    sys.path.insert(0, HERE)
    status = 0
    try:
        run()
        print("check_addon: ok")
        for line in done:
            print(f"  {line}")
    except Exception:  # noqa: BLE001 - any failure fails the check, saying what
        traceback.print_exc()
        print(f"check_addon: FAILED after {len(done)} checks", file=sys.stderr)
        status = 1
    finally:
        if hasattr(bpy.types.Object, "halo4d"):
            try:
                sys.modules["halo4d_blender"].unregister()
            except Exception:  # noqa: BLE001
                traceback.print_exc()
                status = 1
    sys.stdout.flush()
    sys.stderr.flush()
    # The bpy module (4.5) hangs at exit while an operator, panel or menu entry of Python's
    # is registered; unregistered above, and leaving at once besides, so a failed check
    # exits too.
    os._exit(status)


if __name__ == "__main__":
    main()
