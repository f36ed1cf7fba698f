"""The settings a root object keeps (`Object.halo4d`): its scene, its 4D view, the halo's
half-width and the sampling tolerance. Changing one rebuilds the objects under the root.

Limits are halo4d's: a value it refuses is a `SceneError` naming the field, shown in the
panel, so no bound here can disagree with it.
"""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty, StringProperty


def _changed(self, context):
    from . import build

    build.on_change(self)


def _angle(plane):
    first, second = plane
    return FloatProperty(
        name=plane,
        description=f"Degrees in the {plane} plane of R^4, turning {first} towards {second} "
        "(applied in the order xy, xz, xw, yz, yw, zw)",
        step=100,
        precision=2,
        update=_changed,
    )


class Halo4DSettings(bpy.types.PropertyGroup):
    is_root: BoolProperty(name="halo4d root", description="This object holds a halo4d scene")
    scene_json: StringProperty(name="Scene", description="The scene as halo4d read it (a scene file's JSON)")
    xy: _angle("xy")
    xz: _angle("xz")
    xw: _angle("xw")
    yz: _angle("yz")
    yw: _angle("yw")
    zw: _angle("zw")
    translation: FloatVectorProperty(
        name="Translation",
        description="Moves the surfaces in R^4 after the rotation (x, y, z, w)",
        size=4,
        update=_changed,
    )
    halo_width: EnumProperty(
        name="Halo width",
        description="How the halo's half-width is given",
        items=[
            ("GAP_PX", "Gap (px)", "Pixels of the scene's picture: the gap cut into the sheet passing under"),
            ("RHO", "Rho", "A share of the projected scene's diagonal"),
        ],
        update=_changed,
    )
    gap_px: FloatProperty(
        name="Gap (px)",
        description="The halo's half-width in pixels of the scene's picture (halo.gap_px)",
        default=8.0,
        soft_min=1.0,
        soft_max=50.0,
        update=_changed,
    )
    rho: FloatProperty(
        name="Rho",
        description="The halo's half-width as a share of the projected scene's diagonal (halo.rho)",
        default=0.01,
        soft_min=1e-4,
        soft_max=0.1,
        precision=4,
        step=0.1,
        update=_changed,
    )
    tolerance: FloatProperty(
        name="Tolerance",
        description="Sampling tolerance, a share of the 4D bounding box's diagonal "
        "(sampling.tolerance): changing it samples again",
        default=1e-3,
        soft_min=1e-5,
        soft_max=1e-2,
        precision=5,
        step=0.01,
        update=_changed,
    )
    status: StringProperty(name="Status", description="What the latest build made")
    error: StringProperty(name="Error", description="Why the latest build failed")
    verdict: StringProperty(
        name="Verdict", description="The verdict of Verify for the current view: verified, or why not"
    )


classes = (Halo4DSettings,)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Object.halo4d = bpy.props.PointerProperty(type=Halo4DSettings)


def unregister():
    del bpy.types.Object.halo4d
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
