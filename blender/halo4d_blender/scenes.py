"""Scenes as the add-on builds them: where a new object's scene comes from, and the scene a
root object's settings stand for.

No bpy here: these are dicts of a scene file's JSON (docs/SCENES.md), which halo4d
validates. The add-on never checks a limit itself; halo4d's `SceneError` names the field.
"""

import json
import os

ANGLES = ("xy", "xz", "xw", "yz", "yw", "zw")

# A view that shows most surfaces of one's own crossing themselves (that of
# fixtures/scenes/formula-turning-torus.json); the panel turns it from there.
OWN_SURFACE_VIEW = {
    "rotation": {"xy": 0.0, "xz": 0.0, "xw": 40.0, "yz": 25.0, "yw": 0.0, "zw": 0.0},
    "translation": [0.0, 0.0, 0.0, 0.0],
    "projection": {"type": "orthographic"},
}

# What a build in Blender needs of the outputs: the halos and their verification run for
# the glb; nothing else (the picture, the SVG) is made, and Verify writes only these.
OUTPUTS = {
    "glb": True,
    "ply": False,
    "obj": False,
    "vtk": False,
    "report": True,
    "png": False,
    "svg": False,
    "stipples": False,
}


class SourceError(ValueError):
    """Input the add-on reads before halo4d does (a formula's parameters), with its field."""

    def __init__(self, field, message):
        super().__init__(f"{field}: {message}")
        self.field = field


def catalogue_settings():
    """Each catalogue surface's view and camera, as its scene in fixtures/scenes/ has them
    (the camera sets what a halo's `gap_px` is)."""
    path = os.path.join(os.path.dirname(__file__), "catalogue_scenes.json")
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def catalogue_scene(surface_type):
    """A scene of one catalogue surface with its parameters' defaults, in its fixture's view
    and camera."""
    scene = {
        "name": surface_type.replace("_", "-"),
        "surfaces": [{"surface": {"type": surface_type}}],
        "view": OWN_SURFACE_VIEW,
    }
    settings = catalogue_settings().get(surface_type, {})
    scene.update({key: settings[key] for key in ("view", "camera") if key in settings})
    return scene


def _bound(text):
    """A formula's range end: a number where it is one, else the expression (`2*pi`)."""
    try:
        return float(text)
    except ValueError:
        return text.strip()


def formula_scene(name, x, y, z, w, u, v, sides, parameters):
    """A scene of one formula surface. `u` and `v` are (start, end) texts, `sides` the
    rules of the u and v sides, `parameters` a JSON object of numbers."""
    try:
        params = json.loads(parameters) if parameters.strip() else {}
    except json.JSONDecodeError as e:
        raise SourceError("parameters", f"not a JSON object ({e.msg} at character {e.pos + 1})") from None
    if not isinstance(params, dict):
        raise SourceError("parameters", 'not a JSON object such as {"R": 1, "r": 0.45}')
    surface = {
        "type": "formula",
        "x": x,
        "y": y,
        "z": z,
        "w": w,
        "u": [_bound(u[0]), _bound(u[1])],
        "v": [_bound(v[0]), _bound(v[1])],
        "sides": {"u": sides[0], "v": sides[1]},
        "parameters": params,
    }
    return {"name": name, "surfaces": [{"name": name, "surface": surface}], "view": OWN_SURFACE_VIEW}


def mesh_scene(path):
    """A scene of one 4D mesh file (OFF, OBJ or PLY with a fourth coordinate)."""
    path = os.path.abspath(path)
    stem = os.path.splitext(os.path.basename(path))[0] or "mesh"
    return {
        "name": stem[:64],
        "surfaces": [{"surface": {"type": "mesh", "path": path}}],
        "view": OWN_SURFACE_VIEW,
    }


def with_absolute_mesh_paths(scene, folder):
    """`scene` with its mesh surfaces' paths made absolute against `folder`, the folder of
    the scene file they were relative to (a scene kept as JSON no longer knows it)."""
    for entry in scene.get("surfaces", []):
        surface = entry.get("surface", {})
        if surface.get("type") == "mesh" and not os.path.isabs(surface.get("path", "")):
            surface["path"] = os.path.normpath(os.path.join(folder, surface["path"]))
    return scene


def view_of(scene):
    """The view of a scene dict (`to_dict()`'s), and whether it asked for the view search."""
    view = dict(scene["view"])
    auto = bool(view.pop("auto", False))
    return view, auto


def _samplings(scene):
    yield scene.get("sampling")
    for entry in scene.get("surfaces", []):
        yield entry.get("sampling")


def scene_tolerance(scene):
    """The tolerance the panel shows: the scene's `sampling.tolerance`, else a surface's."""
    for sampling in _samplings(scene):
        if sampling and sampling.get("method", "adaptive") == "adaptive" and "tolerance" in sampling:
            return float(sampling["tolerance"])
    return 1e-3


def halo_width(scene):
    """("RHO", rho) or ("GAP_PX", pixels): the halo's half-width as the scene gives it."""
    halo = scene.get("halo", {})
    if "rho" in halo:
        return "RHO", float(halo["rho"])
    return "GAP_PX", float(halo.get("gap_px", 8.0))


def effective_scene(stored, angles, translation, width, tolerance):
    """The scene a root object's settings stand for: its stored scene (`to_dict()`) in the
    view of `angles` (degrees by plane) and `translation`, with the halo's half-width
    `width` (("GAP_PX", px) or ("RHO", share)) and the adaptive samplings that had the
    scene's tolerance at `tolerance` (a surface with a tolerance of its own keeps it)."""
    scene = json.loads(json.dumps(stored))
    view, _ = view_of(scene)
    view["rotation"] = {plane: float(angles[plane]) for plane in ANGLES}
    view["translation"] = [float(t) for t in translation]
    scene["view"] = view
    halo = scene.setdefault("halo", {})
    halo.pop("rho", None)
    halo.pop("gap_px", None)
    halo["rho" if width[0] == "RHO" else "gap_px"] = float(width[1])
    stored_tolerance = scene_tolerance(stored)
    for sampling in _samplings(scene):
        if (
            sampling
            and sampling.get("method", "adaptive") == "adaptive"
            and sampling.get("tolerance") == stored_tolerance
        ):
            sampling["tolerance"] = float(tolerance)
    scene["outputs"] = {**scene.get("outputs", {}), **OUTPUTS}
    return scene


def sampling_key(scene):
    """What a sampling depends on: the surfaces and the sampling (a change of view, halo or
    anything else builds from the same sampling, `Sampled.build(view=..., scene=...)`)."""
    rest = {k: scene.get(k) for k in ("surfaces", "sampling")}
    return json.dumps(rest, sort_keys=True)
