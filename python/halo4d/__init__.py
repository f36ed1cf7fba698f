"""halo4d from Python: surfaces in 4D turned into verified 3D geometry.

>>> import halo4d
>>> built = halo4d.Scene().build()          # the default scene, as `halo4d build` makes it
>>> built.verified
True
>>> built.surfaces[0].positions.shape       # (n, 3) NumPy array, the .ply's frame
(..., 3)
>>> picture = built.render(512, 512)        # (512, 512, 3) uint8

A scene comes from a dict, a JSON string or a scene file (`halo4d.Scene(...)`), validated as
the command line validates it (`halo4d.SceneError`, whose `field` names the field at fault).
`scene.sample()` samples it in 4D once; `.build(view=...)` builds any number of 4D views of
it. The work runs with the GIL released; Ctrl-C interrupts a call at once.
"""

from ._native import (
    BuildError,
    Built,
    Curve,
    Halo,
    Sampled,
    Scene,
    SceneError,
    Surface,
    __version__,
    catalogue,
    check,
)

__all__ = [
    "BuildError",
    "Built",
    "Curve",
    "Halo",
    "Sampled",
    "Scene",
    "SceneError",
    "Surface",
    "__version__",
    "catalogue",
    "check",
]
