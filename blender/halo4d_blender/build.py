"""Building a root object's scene and putting the result into its children.

A root object (an empty) holds the scene and the 4D view in its `halo4d` settings; its
children are the surfaces (role "surface"), their halos ("halo") and the curves
("curves"), found by the custom properties `halo4d_role` and `halo4d_index`, whatever they
are renamed to. A change of a 4D angle or the translation builds the new view from the
sampling kept in `_cache`; a change of anything else the sampling depends on (the
tolerance, the halo) samples again.
"""

import json
import time
from contextlib import contextmanager

import bpy
import numpy as np

from . import geometry, scenes

# Root object's name -> Entry. A renamed root samples again on its next change.
_cache = {}

# While above 0, changes of the settings do not rebuild (the add-on setting several at once).
_suspended = 0


class Entry:
    """A root's sampling (halo4d.Sampled) with what it depends on; the halo4d.Scene of its
    settings but the view, read once (a mesh file is not read again for each view); its
    latest build with the scene it built."""

    def __init__(self, key, scene):
        self.key = key
        self.sampled = scene.sample(progress=progress())
        self.rest = None
        self.other = scene
        self.built = None
        self.scene = None


@contextmanager
def suspended():
    """Settings changed inside do not rebuild."""
    global _suspended
    _suspended += 1
    try:
        yield
    finally:
        _suspended -= 1


def package():
    """The halo4d package, or ImportError saying how to install it into Blender's Python."""
    try:
        import halo4d as module
    except ImportError as e:
        raise ImportError(
            "the halo4d Python package is not installed in Blender's Python: see the add-on's "
            f"README (pip install halo4d-*.whl with Blender's python) ({e})"
        ) from e
    return module


def message(error):
    """One line for the UI: a SceneError as `field: what is wrong`, never a traceback."""
    text = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
    field = getattr(error, "field", None)
    if field:
        # halo4d's message is `file[:line:column]: field: what`; the field leads here.
        _, sep, rest = text.partition(f"{field}: ")
        return f"{field}: {rest if sep else text}"
    return text


def root_of(obj):
    """The halo4d root object of `obj` (itself or the nearest parent that is one), or None."""
    while obj is not None:
        if getattr(obj, "halo4d", None) is not None and obj.halo4d.is_root:
            return obj
        obj = obj.parent
    return None


def _exact(setting, stored):
    """The scene's own value `stored` where the setting (single precision, as Blender's
    float properties are) still holds it, else the setting: a view the panel has not
    turned is the scene's to the last bit, and builds as `halo4d build` builds it."""
    return stored if np.float32(stored) == np.float32(setting) else float(setting)


def settings_scene(settings):
    """The scene (a dict) that a root's settings stand for."""
    stored = json.loads(settings.scene_json)
    view, _ = scenes.view_of(stored)
    angles = {plane: _exact(getattr(settings, plane), view["rotation"][plane]) for plane in scenes.ANGLES}
    translation = [_exact(s, t) for s, t in zip(settings.translation, view["translation"], strict=True)]
    kind, value = scenes.halo_width(stored)
    setting = settings.rho if settings.halo_width == "RHO" else settings.gap_px
    width = (settings.halo_width, _exact(setting, value) if settings.halo_width == kind else setting)
    tolerance = _exact(settings.tolerance, scenes.scene_tolerance(stored))
    return scenes.effective_scene(stored, angles, translation, width, tolerance)


def progress():
    """A `progress=` function for halo4d's work that moves Blender's progress indicator (the
    number on the cursor) through the steps of each task."""
    wm = bpy.context.window_manager
    tasks = []

    def hear(event):
        kind = event["kind"]
        if kind == "begin":
            tasks.append(event["steps"])
            wm.progress_begin(0, event["steps"])
        elif kind == "done" and tasks:
            wm.progress_update(event["done"])
        elif kind == "end" and tasks:
            tasks.pop()
            wm.progress_end()
            if tasks:
                wm.progress_begin(0, tasks[-1])

    return hear


def build(root):
    """Builds the root's scene in its view, re-using its sampling where the surfaces and the
    sampling are unchanged. Raises halo4d.SceneError or halo4d.BuildError."""
    h = package()
    scene = settings_scene(root.halo4d)
    key = scenes.sampling_key(scene)
    rest = json.dumps({k: v for k, v in scene.items() if k != "view"}, sort_keys=True)
    entry = _cache.get(root.name)
    if entry is None or entry.key != key:
        entry = Entry(key, h.Scene(scene))
        entry.rest = rest
        _cache[root.name] = entry
    elif entry.rest != rest:
        entry.other, entry.rest = h.Scene(scene), rest
    entry.built = entry.sampled.build(view=scene["view"], scene=entry.other, progress=progress())
    entry.scene = scene
    return entry.built


def latest(root):
    """The root's build in its current view: the latest one, or a new one."""
    entry = _cache.get(root.name)
    scene = settings_scene(root.halo4d)
    if (
        entry is None
        or entry.built is None
        or entry.key != scenes.sampling_key(scene)
        or entry.scene != scene
    ):
        return build(root)
    return entry.built


def children(root):
    """The root's children by (role, index)."""
    return {
        (obj.get("halo4d_role"), obj.get("halo4d_index", 0)): obj
        for obj in root.children
        if obj.get("halo4d_role")
    }


def _child(root, found, role, index, name, data):
    obj = found.get((role, index))
    if obj is None:
        obj = bpy.data.objects.new(name, data)
        obj["halo4d_role"] = role
        obj["halo4d_index"] = index
        for collection in root.users_collection:
            collection.objects.link(obj)
        obj.parent = root
    return obj


def apply(root, built):
    """Puts `built` into the root's children, making those it lacks."""
    found = children(root)
    scale = geometry.w_range(built)
    for index, surface in enumerate(built.surfaces):
        obj = found.get(("surface", index))
        if obj is None:
            obj = _child(root, found, "surface", index, surface.name, bpy.data.meshes.new(surface.name))
            obj.data.materials.append(geometry.surface_material())
        geometry.fill_surface(obj.data, surface, scale)

        halo_name = f"{surface.name}-halo"
        obj = found.get(("halo", index))
        if obj is None:
            obj = _child(root, found, "halo", index, halo_name, bpy.data.meshes.new(halo_name))
            obj.data.materials.append(geometry.halo_material())
            obj.hide_viewport = True
            obj.hide_render = True
        halo = surface.halo
        if halo is None:
            geometry.fill_mesh(obj.data, [], [])
        else:
            geometry.fill_mesh(obj.data, *geometry.halo_boundary(halo.vertices, halo.tetrahedra))

    obj = found.get(("curves", 0))
    if obj is None:
        name = f"{root.name}-curves"
        data = bpy.data.curves.new(name, "CURVE")
        data.dimensions = "3D"
        data.fill_mode = "FULL"
        radius = json.loads(root.halo4d.scene_json).get("outputs", {}).get("curve_radius", 0.004)
        data.bevel_depth = radius * geometry.scene_diagonal(built)
        data.bevel_resolution = 2
        for m in geometry.ink_materials():
            data.materials.append(m)
        obj = _child(root, found, "curves", 0, name, data)
    geometry.fill_curves(obj.data, built, scale)

    settings = root.halo4d
    vertices = sum(len(s.positions) for s in built.surfaces)
    triangles = sum(len(s.triangles) for s in built.surfaces)
    tetrahedra = sum(len(s.halo.tetrahedra) for s in built.surfaces if s.halo is not None)
    with suspended():
        settings.status = (
            f"{vertices} vertices, {triangles} triangles, {len(built.curves)} curves, "
            f"{tetrahedra} halo tetrahedra"
        )
        settings.verdict = ""


def rebuild(root):
    """Builds the root's scene and puts it into its children; returns None, or the error's
    one line (also kept in the root's settings for the panel)."""
    started = time.perf_counter()
    try:
        built = build(root)
        apply(root, built)
    except Exception as e:  # noqa: BLE001 - every error becomes a line in the panel
        line = message(e)
        with suspended():
            root.halo4d.error = line
        print(f"halo4d: {root.name}: {line}")
        return line
    with suspended():
        root.halo4d.error = ""
        root.halo4d.status += f", built in {time.perf_counter() - started:.2f} s"
    return None


def on_change(settings):
    """The settings' `update`: rebuild, unless the add-on is setting them."""
    if _suspended or not settings.is_root:
        return
    rebuild(settings.id_data)


def create(context, scene):
    """A root object holding `scene` (a dict: validated by halo4d, raising SceneError) with
    its surfaces, curves and halos under it in a new collection. Returns (root, a note for
    the user or None)."""
    h = package()
    stored = h.Scene(scene).to_dict()
    view, auto = scenes.view_of(stored)
    note = None
    if auto:
        # `"view": "auto"`: the view search, as `halo4d build` runs it (about 16 s for the
        # default scene on two cores); the scene then keeps the view found.
        stored = h.Scene(stored).build().scene.to_dict()
        view, _ = scenes.view_of(stored)
        note = "view: searched the view that shows the most of the curves"
    collection = bpy.data.collections.new(stored["name"])
    context.scene.collection.children.link(collection)
    root = bpy.data.objects.new(stored["name"], None)
    root.empty_display_type = "PLAIN_AXES"
    collection.objects.link(root)
    settings = root.halo4d
    with suspended():
        settings.is_root = True
        settings.scene_json = json.dumps(stored)
        for plane in scenes.ANGLES:
            setattr(settings, plane, view["rotation"][plane])
        settings.translation = view["translation"]
        kind, value = scenes.halo_width(stored)
        settings.halo_width = kind
        if kind == "RHO":
            settings.rho = value
        else:
            settings.gap_px = value
        settings.tolerance = scenes.scene_tolerance(stored)
    _cache.pop(root.name, None)
    try:
        apply(root, build(root))
    except Exception:
        _cache.pop(root.name, None)
        for obj in list(root.children) + [root]:
            bpy.data.objects.remove(obj)
        bpy.data.collections.remove(collection)
        raise
    return root, note
