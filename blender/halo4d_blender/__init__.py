"""halo4d in Blender: Add › Mesh › 4D Surface builds a surface from R^4 with halo4d (its
mesh coloured by w, its self-intersection curves, its halos), and the sidebar's halo4d tab
turns it in 4D and verifies the view.

It needs the `halo4d` Python package in Blender's Python (see README.md). Installed as an
extension (Blender 4.2 or later, `blender_manifest.toml`) or registered directly:

    import halo4d_blender
    halo4d_blender.register()
"""

import bpy

from . import build, operators, panel, props

_modules = (props, operators, panel)


@bpy.app.handlers.persistent
def _forget_samplings(*_):
    """A file loaded: the samplings kept belong to the objects of the one before."""
    build._cache.clear()


def register():
    for module in _modules:
        module.register()
    bpy.app.handlers.load_post.append(_forget_samplings)


def unregister():
    if _forget_samplings in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_forget_samplings)
    for module in reversed(_modules):
        module.unregister()
    build._cache.clear()
