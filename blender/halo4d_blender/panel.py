"""The sidebar panel (View3D › Sidebar › halo4d) of the active object's halo4d root."""

import bpy

from . import build, scenes


class VIEW3D_PT_halo4d(bpy.types.Panel):
    bl_label = "halo4d"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "halo4d"

    def draw(self, context):
        layout = self.layout
        root = build.root_of(context.active_object)
        if root is None:
            layout.label(text="Add › Mesh › 4D Surface makes one")
            return
        settings = root.halo4d
        layout.label(text=root.name, icon="OUTLINER_OB_EMPTY")

        box = layout.box()
        box.label(text="Rotation in R^4 (degrees)")
        grid = box.grid_flow(columns=2, align=True)
        for plane in scenes.ANGLES:
            grid.prop(settings, plane)
        box.label(text="Translation (x, y, z, w)")
        box.row(align=True).prop(settings, "translation", text="")

        box = layout.box()
        box.prop(settings, "halo_width")
        box.prop(settings, "rho" if settings.halo_width == "RHO" else "gap_px")
        box.prop(settings, "tolerance")

        if settings.error:
            layout.label(text=settings.error, icon="ERROR")
        elif settings.status:
            layout.label(text=settings.status, icon="INFO")

        row = layout.row()
        row.operator("object.halo4d_verify", icon="CHECKMARK")
        if settings.verdict:
            icon = "CHECKMARK" if settings.verdict == "verified" else "ERROR"
            layout.label(text=settings.verdict, icon=icon)
        else:
            layout.label(text="not verified in this view yet")


classes = (VIEW3D_PT_halo4d,)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
