"""Add › Mesh › 4D Surface (`mesh.halo4d_add`) and Verify (`object.halo4d_verify`)."""

import os
import tempfile

import bpy
from bpy.props import EnumProperty, StringProperty

from . import build, scenes

SIDES = [
    (rule, rule, f"The side is glued by the `{rule}` rule")
    for rule in ("open", "periodic", "flip", "pole", "half_turn")
]


def _catalogue():
    """The catalogue's surfaces for the enum, read once when the add-on loads."""
    try:
        entries = build.package().catalogue()
    except ImportError:
        entries = [{"type": "spun_trefoil", "description": "Artin-spun trefoil"}]
    return [(e["type"], e["type"].replace("_", " "), e["description"]) for e in entries]


CATALOGUE = _catalogue()


class MESH_OT_halo4d_add(bpy.types.Operator):
    """Add a surface from 4D, projected by halo4d: its mesh coloured by w, its
    self-intersection curves and its halos"""

    bl_idname = "mesh.halo4d_add"
    bl_label = "4D Surface"
    bl_options = {"REGISTER", "UNDO"}

    source: EnumProperty(
        name="Source",
        items=[
            ("DEFAULT", "Default scene", "halo4d's default scene: the spun trefoil, verified"),
            ("CATALOGUE", "Catalogue", "A surface of halo4d's catalogue in the view of its scene"),
            ("FORMULA", "Formula", "Four formulas in u and v"),
            ("MESH", "4D mesh file", "A 4D mesh: OFF (4OFF), OBJ with `v x y z w`, PLY with x y z w"),
            ("SCENE", "Scene file", "A halo4d scene file (JSON)"),
        ],
        default="DEFAULT",
    )
    surface_type: EnumProperty(
        name="Surface",
        items=CATALOGUE,
        default="spun_trefoil" if any(e[0] == "spun_trefoil" for e in CATALOGUE) else CATALOGUE[0][0],
    )
    formula_name: StringProperty(name="Name", default="formula", description="The scene's and surface's name")
    x: StringProperty(name="x", default="(R + r*cos(v))*cos(u)")
    y: StringProperty(name="y", default="(R + r*cos(v))*sin(u)")
    z: StringProperty(name="z", default="r*sin(v)*cos(n*u)")
    w: StringProperty(name="w", default="r*sin(v)*sin(n*u)")
    u_start: StringProperty(name="u from", default="0")
    u_end: StringProperty(name="u to", default="2*pi")
    v_start: StringProperty(name="v from", default="0")
    v_end: StringProperty(name="v to", default="2*pi")
    u_sides: EnumProperty(name="u sides", items=SIDES, default="periodic")
    v_sides: EnumProperty(name="v sides", items=SIDES, default="periodic")
    parameters: StringProperty(
        name="Parameters", default='{"R": 1, "r": 0.45, "n": 2}', description="A JSON object of numbers"
    )
    scene_path: StringProperty(name="Scene file", subtype="FILE_PATH")
    mesh_path: StringProperty(name="Mesh file", subtype="FILE_PATH")

    def scene(self):
        """The scene (a dict) the settings describe."""
        if self.source == "DEFAULT":
            return build.package().Scene().to_dict()
        if self.source == "CATALOGUE":
            return scenes.catalogue_scene(self.surface_type)
        if self.source == "FORMULA":
            return scenes.formula_scene(
                self.formula_name,
                self.x,
                self.y,
                self.z,
                self.w,
                (self.u_start, self.u_end),
                (self.v_start, self.v_end),
                (self.u_sides, self.v_sides),
                self.parameters,
            )
        if self.source == "MESH":
            if not self.mesh_path:
                raise scenes.SourceError("mesh file", "choose a 4D mesh file")
            return scenes.mesh_scene(bpy.path.abspath(self.mesh_path))
        if not self.scene_path:
            raise scenes.SourceError("scene file", "choose a scene file")
        path = os.path.abspath(bpy.path.abspath(self.scene_path))
        scene = build.package().Scene(path).to_dict()
        return scenes.with_absolute_mesh_paths(scene, os.path.dirname(path))

    def execute(self, context):
        try:
            root, note = build.create(context, self.scene())
        except Exception as e:  # noqa: BLE001 - reported as one line, never a traceback
            self.report({"ERROR"}, f"halo4d: {build.message(e)}")
            return {"CANCELLED"}
        if note:
            self.report({"INFO"}, f"halo4d: {note}")
        for obj in context.view_layer.objects:
            obj.select_set(False)
        context.view_layer.objects.active = root
        root.select_set(True)
        self.report({"INFO"}, f"halo4d: {root.name}: {root.halo4d.status}")
        return {"FINISHED"}

    def invoke(self, context, event):
        return context.window_manager.invoke_props_dialog(self, width=420)

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "source")
        if self.source == "CATALOGUE":
            layout.prop(self, "surface_type")
        elif self.source == "FORMULA":
            layout.prop(self, "formula_name")
            for field in ("x", "y", "z", "w"):
                layout.prop(self, field)
            for side in ("u", "v"):
                row = layout.row(align=True)
                row.prop(self, f"{side}_start")
                row.prop(self, f"{side}_end")
                row.prop(self, f"{side}_sides", text="")
            layout.prop(self, "parameters")
        elif self.source == "MESH":
            layout.prop(self, "mesh_path")
        elif self.source == "SCENE":
            layout.prop(self, "scene_path")


class OBJECT_OT_halo4d_verify(bpy.types.Operator):
    """Verify the current view: the build's own verdict, then halo4d's independent checker
    on the .glb it writes (every halo conforms and agrees with the curves)"""

    bl_idname = "object.halo4d_verify"
    bl_label = "Verify"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        return build.root_of(context.active_object) is not None

    def execute(self, context):
        root = build.root_of(context.active_object)
        try:
            built = build.latest(root)
            with tempfile.TemporaryDirectory(prefix="halo4d-verify-") as folder:
                built.write(folder)
                checked = build.package().check(folder)
        except Exception as e:  # noqa: BLE001 - reported as one line, never a traceback
            line = build.message(e)
            with build.suspended():
                root.halo4d.verdict = f"error: {line}"
            self.report({"ERROR"}, f"halo4d: {line}")
            return {"CANCELLED"}
        failures = list(built.failures) + [f"check: {f}" for f in checked["failures"]]
        verdict = "verified" if not failures else "not verified: " + "; ".join(failures)
        with build.suspended():
            root.halo4d.verdict = verdict
        if failures:
            self.report({"WARNING"}, f"halo4d: {root.name}: {verdict}")
        else:
            self.report(
                {"INFO"}, f"halo4d: {root.name}: verified ({checked['text'].strip().splitlines()[-1]})"
            )
        return {"FINISHED"}


def menu(self, context):
    self.layout.operator(MESH_OT_halo4d_add.bl_idname, text="4D Surface", icon="OUTLINER_OB_SURFACE")


classes = (MESH_OT_halo4d_add, OBJECT_OT_halo4d_verify)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.VIEW3D_MT_mesh_add.append(menu)


def unregister():
    bpy.types.VIEW3D_MT_mesh_add.remove(menu)
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
