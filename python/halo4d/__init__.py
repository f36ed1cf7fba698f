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
it. The work runs with the GIL released; Ctrl-C stops it within a fraction of a second (its
memory freed, nothing written) and raises KeyboardInterrupt. halo4d prints nothing: pass
`progress=` a function to hear what it does, or `halo4d.tqdm_progress()` for tqdm bars:

>>> built = halo4d.Scene().build(progress=halo4d.tqdm_progress())

`halo4d.check` certifies any tetrahedral mesh, from a file or from memory:

>>> import pyvista, halo4d
>>> grid = pyvista.read("ball.vtu")             # or a meshio.Mesh, or (points, cells)
>>> result = halo4d.check(grid)
>>> grid.cell_data["fault"] = result["cell_faults"]   # threshold on it in PyVista
"""

import os
from typing import Any, Callable

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
)
from ._native import certify_arrays as _certify
from ._native import check as _check_path

# VTK's cell types whose first four points are a tetrahedron's corners: linear, quadratic,
# Lagrange and Bezier tetrahedra (VTK_TETRA, VTK_QUADRATIC_TETRA, VTK_LAGRANGE_TETRAHEDRON,
# VTK_BEZIER_TETRAHEDRON).
_VTK_TETRAHEDRA = (10, 24, 71, 78)
# VTK's hexahedra, wedges and pyramids, linear and quadratic: the VTK type halo4d reads them
# as (12, 13, 14) and where their corners are, in VTK's order (a voxel's turned into a
# hexahedron's).
_VTK_MIXED = {11: (12, [0, 1, 3, 2, 4, 5, 7, 6]), 12: (12, range(8)), 25: (12, range(8)), 29: (12, range(8)),
              33: (12, range(8)), 13: (13, range(6)), 26: (13, range(6)), 31: (13, range(6)),
              32: (13, range(6)), 14: (14, range(5)), 27: (14, range(5)), 37: (14, range(5))}
# VTK's other cell types of dimension 3, which halo4d does not read.
_VTK_OTHER_SOLIDS = {15: "pentagonal prism", 16: "hexagonal prism", 42: "polyhedron", 72: "Lagrange hexahedron",
                     73: "Lagrange wedge", 74: "Lagrange pyramid", 79: "Bezier hexahedron", 80: "Bezier wedge",
                     81: "Bezier pyramid"}
# meshio's cell types: tetrahedra (their first four nodes the corners), hexahedra, wedges and
# pyramids (meshio keeps a wedge in Gmsh's order, its first triangle turned towards the
# opposite one: corners 1 and 2, 4 and 5 swapped into VTK's), and other solids.
_MESHIO_TETRAHEDRA = ("tetra", "tetra10", "tetra20", "tetra35", "tetra56", "tetra84", "tetra120", "tetra165",
                      "tetra220", "tetra286")
_MESHIO_MIXED = {"hexahedron": (12, range(8)), "hexahedron20": (12, range(8)), "hexahedron24": (12, range(8)),
                 "hexahedron27": (12, range(8)), "wedge": (13, [0, 2, 1, 3, 5, 4]),
                 "wedge12": (13, [0, 2, 1, 3, 5, 4]), "wedge15": (13, [0, 2, 1, 3, 5, 4]),
                 "wedge18": (13, [0, 2, 1, 3, 5, 4]), "pyramid": (14, range(5)), "pyramid13": (14, range(5)),
                 "pyramid14": (14, range(5))}
_MESHIO_SOLIDS = ("hexahedron", "wedge", "pyramid", "polyhedron")


def _solid_rows(kind, ids, corners):
    """Rows of (VTK type, the cell's number, 8 corners padded with 0) for halo4d's reader."""
    import numpy as np

    rows = np.zeros((len(ids), 10), dtype=np.int64)
    rows[:, 0], rows[:, 1] = kind, ids
    rows[:, 2:2 + corners.shape[1]] = corners
    return rows


def _refuse_solids(found: dict) -> None:
    if found:
        listed = ", ".join(f"{n} {kind}" for kind, n in found.items())
        raise ValueError(f"the mesh has {listed} besides its tetrahedra, hexahedra, wedges and pyramids: halo4d "
                         "checks meshes of these four kinds of cell only; split the other cells into them first")


def check(source: Any) -> dict[str, Any]:
    """`halo4d check` on a file or folder (str or os.PathLike), or the certificate of a
    mesh in memory, without writing a file: a PyVista `UnstructuredGrid` or a meshio `Mesh`
    (tetrahedra, hexahedra, wedges and pyramids, linear or quadratic), or `(points, cells)`
    NumPy arrays of tetrahedra ((n, 3) and (m, 4), in VTK's and Gmsh's convention: a, b, c, d
    positive when det[b - a, c - a, d - a] > 0).

    Gives a dict: `verified`, `failures`, `halos` (each mesh's statistics), `plain`,
    `format`, `text` (what the command prints), `certificate` (for another program's mesh:
    `convention`, `boundary`, `quality`, for a mixed mesh `cells`, and `faults`, each cell's
    fault bits as a NumPy uint32 array, its tetrahedra first), for a folder `curves` and
    `verification`, and for a mesh in
    memory `cell_faults`: the fault bits of each of its cells (0 for the lower-dimensional
    cells it skips), to set as cell data, the way PyVista's own `validate_mesh` gives a
    status per cell. A file that cannot be read raises `OSError`; a mesh with other solids
    (polyhedra, hexagonal prisms, ...), indices out of range or non-finite points,
    `ValueError`.
    """
    if isinstance(source, (str, os.PathLike)):
        return _check_path(source)
    import numpy as np

    solids, solid_at = [], []  # rows for halo4d's reader, and the cells they are
    if hasattr(source, "celltypes") and hasattr(source, "cell_connectivity"):
        # A PyVista UnstructuredGrid.
        types = np.asarray(source.celltypes)
        # PyVista 0.49 names the cells' starts `cell_offsets` (`offset` before).
        offsets = np.asarray(source.cell_offsets if hasattr(source, "cell_offsets") else source.offset,
                             dtype=np.int64)
        conn = np.asarray(source.cell_connectivity, dtype=np.int64)
        _refuse_solids({name: int(np.count_nonzero(types == t)) for t, name in _VTK_OTHER_SOLIDS.items()
                        if np.any(types == t)})
        which = np.flatnonzero(np.isin(types, _VTK_TETRAHEDRA))
        tets = conn[offsets[which][:, None] + np.arange(4)] if len(which) else np.zeros((0, 4), np.int64)
        for t, (kind, order) in _VTK_MIXED.items():
            at = np.flatnonzero(types == t)
            if len(at):
                solids.append(_solid_rows(kind, at, conn[offsets[at][:, None] + np.asarray(list(order))]))
                solid_at.append(at)
        points, n_cells, fmt = np.asarray(source.points, dtype=np.float64), len(types), "a PyVista UnstructuredGrid"
    elif hasattr(source, "points") and hasattr(source, "cells"):
        # A meshio Mesh: its cell blocks one after the other.
        blocks, which, start = [], [], 0
        _refuse_solids({b.type: len(b.data) for b in source.cells
                        if b.type.startswith(_MESHIO_SOLIDS) and b.type not in _MESHIO_MIXED})
        for b in source.cells:
            data = np.asarray(b.data, dtype=np.int64)
            at = np.arange(start, start + len(data))
            if b.type in _MESHIO_TETRAHEDRA:
                blocks.append(data[:, :4])
                which.append(at)
            elif b.type in _MESHIO_MIXED and len(data):
                kind, order = _MESHIO_MIXED[b.type]
                solids.append(_solid_rows(kind, at, data[:, list(order)]))
                solid_at.append(at)
            start += len(data)
        tets = np.vstack(blocks) if blocks else np.zeros((0, 4), np.int64)
        which = np.concatenate(which) if which else np.zeros(0, np.int64)
        points, n_cells, fmt = np.asarray(source.points, dtype=np.float64), start, "a meshio Mesh"
    elif isinstance(source, tuple) and len(source) == 2:
        points = np.asarray(source[0], dtype=np.float64)
        tets = np.asarray(source[1], dtype=np.int64)
        n_cells, which, fmt = len(tets), np.arange(len(tets)), "(points, cells) arrays"
    else:
        raise TypeError(f"halo4d.check takes a path, a PyVista UnstructuredGrid, a meshio Mesh or "
                        f"(points, cells) arrays, not {type(source).__name__}")
    if points.ndim != 2 or points.shape[1] != 3 or tets.ndim != 2 or tets.shape[1] != 4:
        raise ValueError(f"points must be (n, 3) and cells (m, 4); got {points.shape} and {tets.shape}")
    solids = np.vstack(solids) if solids else np.zeros((0, 10), np.int64)
    result = _certify(np.ascontiguousarray(points), np.ascontiguousarray(tets), np.ascontiguousarray(solids),
                      "mesh", fmt)
    # The certificate's faults: the tetrahedra's, then the other cells' in the rows' order.
    faults = result["certificate"]["faults"]
    cell_faults = np.zeros(n_cells, dtype=np.uint32)
    cell_faults[which] = faults[:len(which)]
    if solid_at:
        cell_faults[np.concatenate(solid_at)] = faults[len(which):]
    result["cell_faults"] = cell_faults
    return result


def tqdm_progress(**options: Any) -> Callable[[dict[str, Any]], None]:
    """A `progress=` function that draws each task of halo4d's work (a build, its sampling,
    a view search) as a tqdm bar (`tqdm.auto`: a widget in a notebook, text in a terminal),
    what it is doing as the bar's postfix, its notes with `tqdm.write` and its warnings with
    `warnings.warn`. `options` go to each `tqdm` (`file=`, `disable=`, ...)."""
    import warnings

    from tqdm.auto import tqdm

    bars: list = []

    def progress(event: dict[str, Any]) -> None:
        kind = event["kind"]
        if kind == "begin":
            bars.append(tqdm(total=event["steps"], desc=event["task"], leave=False, **options))
        elif kind == "doing" and bars:
            bars[-1].set_postfix_str(event["text"])
        elif kind == "done" and bars:
            bars[-1].update(event["done"] - bars[-1].n)
        elif kind == "end" and bars:
            bars.pop().close()
        elif kind == "note":
            tqdm.write(event["text"], file=options.get("file"))
        elif kind == "warning":
            warnings.warn(event["text"], stacklevel=2)

    return progress


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
    "tqdm_progress",
]
