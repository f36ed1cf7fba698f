"""Mixed meshes (hexahedra, wedges, pyramids and tetrahedra) for .ci/tetmesh-corpus.py: Gmsh
meshes them, Gmsh, VTK and PyVista write them, `halo4d check` must pass each with a second
reader (VTK for VTK's formats, Gmsh for .msh) counting the same cells of each kind and the
same volume, and name every fault planted in copies.

The meshes, all from Gmsh 4.15.2:
  - hybrid, twisted: a 2 x 2 x 1 box, its quarter [0, 1]^2 extruded hexahedra, [0, 1] x
    [1, 2] extruded prisms, [1, 2] x [0, 1] tetrahedra with pyramids on the hexahedra's
    quadrilaterals, all twisted half a radian as they rise (bent quadrilaterals);
  - hybrid, straight: the same extruded straight up (planar quadrilaterals);
  - hex-dominant annulus: an annulus meshed in unstructured quadrilaterals by Gmsh's
    recombination, extruded in layers: hexahedra of every shape the recombination makes;
  - all-hex holed block: a block with a hole, its tetrahedra subdivided into hexahedra
    (Mesh.SubdivisionAlgorithm 2), every quadrilateral bent;
and the twisted hybrid at order 2. Each is written by Gmsh (MSH 4.1 ASCII and binary, 2.2
ASCII and binary, its legacy .vtk), by VTK 9.5.2's XML writer (ASCII, inline binary with
zlib, appended with LZ4), its legacy writer (binary), its parallel writer (a .pvtu of three
pieces), by PyVista's `save`, and by meshio 5.3.5 from Gmsh's file (.vtu with zlib, .msh
2.2 binary).

The faults, planted in the twisted hybrid as VTK orders its cells: a hexahedron split into
Kuhn's six tetrahedra (its bent faces against its neighbours' whole: non-conforming; the
same in the straight hybrid conforms), a wedge mirrored, a pyramid mirrored, a hexahedron
twice, and a pyramid at the bottom removed (a hollow meeting the boundary along an edge).
"""

import contextlib
import io
from pathlib import Path

import gmsh
import meshio
import numpy as np
import pyvista
import vtk
from vtk.util.numpy_support import vtk_to_numpy

import vtk_pieces

SOLID_TYPES = (10, 12, 13, 14)  # VTK's tetrahedron, hexahedron, wedge, pyramid
NAMES = {10: "tetrahedra", 12: "hexahedra", 13: "wedges", 14: "pyramids"}
GMSH_TYPES = {10: (4, 11), 12: (5, 12, 17), 13: (6, 13, 18), 14: (7, 14, 19)}
# (name, MSH version, binary)
GMSH_FORMATS = (("4.1-ascii", 4.1, 0), ("4.1-binary", 4.1, 1), ("2.2-ascii", 2.2, 0), ("2.2-binary", 2.2, 1))


def hybrid(twist, nodes=5, layers=4):
    g = gmsh.model.geo
    corner = {(i, j): g.addPoint(i, j, 0, 0.5) for i in range(3) for j in range(3)}
    lines = {}

    def line(a, b):
        if (b, a) in lines:
            return -lines[b, a]
        lines.setdefault((a, b), g.addLine(corner[a], corner[b]))
        return lines[a, b]

    def square(i, j):
        ring = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1), (i, j)]
        return g.addPlaneSurface([g.addCurveLoop([line(a, b) for a, b in zip(ring, ring[1:])])])

    hexes, prisms, tets = square(0, 0), square(0, 1), square(1, 0)
    for c in lines.values():
        g.mesh.setTransfiniteCurve(abs(c), nodes)
    g.mesh.setTransfiniteSurface(hexes)
    g.mesh.setRecombine(2, hexes)
    g.mesh.setTransfiniteSurface(prisms)
    if twist:
        axis = (1, 1, 0, 0, 0, 1, 0, 0, 1)
        g.twist([(2, hexes), (2, prisms)], *axis, twist, numElements=[layers], recombine=True)
        g.twist([(2, tets)], *axis, twist)
    else:
        g.extrude([(2, hexes), (2, prisms)], 0, 0, 1, numElements=[layers], recombine=True)
        g.extrude([(2, tets)], 0, 0, 1)
    g.removeAllDuplicates()
    g.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
    gmsh.model.mesh.generate(3)


def annulus():
    occ = gmsh.model.occ
    outer, inner = occ.addDisk(0, 0, 0, 1, 1), occ.addDisk(0, 0, 0, 0.4, 0.4)
    ring, _ = occ.cut([(2, outer)], [(2, inner)])
    occ.extrude(ring, 0, 0, 0.5, numElements=[3], recombine=True)
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.15)
    gmsh.option.setNumber("Mesh.RecombineAll", 1)
    gmsh.option.setNumber("Mesh.Algorithm", 8)
    gmsh.model.mesh.generate(3)


def holed_block():
    occ = gmsh.model.occ
    box = occ.addBox(0, 0, 0, 2, 1, 1)
    hole = occ.addCylinder(1, 0.5, -0.1, 0, 0, 1.2, 0.25)
    occ.cut([(3, box)], [(3, hole)])
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
    gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", 2)
    gmsh.model.mesh.generate(3)


MESHES = (
    ("hybrid-twisted", lambda: hybrid(0.5)),
    ("hybrid-straight", lambda: hybrid(0.0)),
    ("annulus-hex-dominant", annulus),
    ("holed-block-all-hex", holed_block),
)


def solids(path):
    """The grid of `path` with its solid cells only, as VTK reads it (VTK's corner order)."""
    grid = pyvista.read(str(path))
    return grid.extract_cells(np.flatnonzero(np.isin(grid.celltypes, SOLID_TYPES))).cast_to_unstructured_grid()


def write_vtk_formats(folder, stem, grid):
    """The grid as VTK's writers and PyVista's save write it: the paths."""
    out = []

    def xml(name, mode, compressor=None):
        w = vtk.vtkXMLUnstructuredGridWriter()
        w.SetInputData(grid)
        w.SetFileName(str(folder / name))
        {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary, "appended": w.SetDataModeToAppended}[mode]()
        if compressor == "lz4":
            w.SetCompressorTypeToLZ4()
        elif compressor == "zlib":
            w.SetCompressorTypeToZLib()
        else:
            w.SetCompressorTypeToNone()
        assert w.Write() == 1, name
        out.append(folder / name)

    xml(f"{stem}-vtk9-ascii.vtu", "ascii")
    xml(f"{stem}-vtk9-binary-zlib.vtu", "binary", "zlib")
    xml(f"{stem}-vtk9-appended-lz4.vtu", "appended", "lz4")
    legacy = vtk.vtkUnstructuredGridWriter()
    legacy.SetInputData(grid)
    legacy.SetFileName(str(folder / f"{stem}-vtk9-binary.vtk"))
    legacy.SetFileTypeToBinary()
    assert legacy.Write() == 1
    out.append(folder / f"{stem}-vtk9-binary.vtk")
    # Three pieces by the cells' order, each with the points it uses.
    n = grid.GetNumberOfCells()

    def piece(k):
        return grid.extract_cells(np.arange(k * n // 3, (k + 1) * n // 3)).cast_to_unstructured_grid()

    vtk_pieces.write_pvtu(folder / f"{stem}-vtk9.pvtu", piece, 3)
    out.append(folder / f"{stem}-vtk9.pvtu")
    grid.save(str(folder / f"{stem}-pyvista.vtu"))
    out.append(folder / f"{stem}-pyvista.vtu")
    return out


def make_clean(folder):
    """Every mesh in every format: [(name, [paths])], and the twisted and straight hybrids'
    solid grids (VTK order) for the faults."""
    groups, grids = [], {}
    gmsh.initialize(["gmsh", "-v", "0"], interruptible=False)
    try:
        for name, make in MESHES:
            gmsh.clear()
            gmsh.option.restoreDefaults()
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.model.add(name)
            make()
            files = []
            for label, version, binary in GMSH_FORMATS:
                gmsh.option.setNumber("Mesh.MshFileVersion", version)
                gmsh.option.setNumber("Mesh.Binary", binary)
                files.append(folder / f"{name}-gmsh-{label}.msh")
                gmsh.write(str(files[-1]))
            gmsh.option.setNumber("Mesh.Binary", 0)
            files.append(folder / f"{name}-gmsh.vtk")
            gmsh.write(str(files[-1]))
            grids[name] = solids(files[-1])
            files += write_vtk_formats(folder, name, grids[name])
            # meshio's conversion of Gmsh's file, as people convert meshes: its .vtu (VTK's
            # wedge order) and its .msh 2.2 binary (Gmsh's again).
            with contextlib.redirect_stderr(io.StringIO()):
                converted = meshio.read(folder / f"{name}-gmsh-4.1-binary.msh")
                converted = meshio.Mesh(converted.points, [c for c in converted.cells if c.dim == 3])
                files.append(folder / f"{name}-meshio.vtu")
                meshio.vtu.write(files[-1], converted, binary=True, compression="zlib")
                files.append(folder / f"{name}-meshio-2.2-binary.msh")
                meshio.gmsh.write(files[-1], converted, fmt_version="2.2", binary=True)
            if name == "hybrid-twisted":
                gmsh.model.mesh.setOrder(2)
                gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
                files.append(folder / f"{name}-gmsh-order2.msh")
                gmsh.write(str(files[-1]))
            groups.append((name, files))
    finally:
        gmsh.finalize()
    return groups, grids


def second_reader(path):
    """({VTK type: count}, volume, reader) as VTK (VTK's formats) or Gmsh (.msh) reads the
    file: the volume VTK's vtkCellSizeFilter or Gmsh's element volumes give."""
    path = Path(path)
    if path.suffix == ".msh":
        gmsh.initialize(["gmsh", "-v", "0"], interruptible=False)
        try:
            gmsh.open(str(path))
            counts, volume = {}, 0.0
            for t, kinds in GMSH_TYPES.items():
                tags = np.concatenate([gmsh.model.mesh.getElementsByType(k)[0] for k in kinds])
                counts[t] = len(tags)
                if len(tags):
                    volume += float(np.abs(gmsh.model.mesh.getElementQualities(tags, "volume")).sum())
        finally:
            gmsh.finalize()
        return counts, volume, f"Gmsh {gmsh.__version__}"
    reader = {".vtu": vtk.vtkXMLUnstructuredGridReader, ".vtk": vtk.vtkUnstructuredGridReader,
              ".pvtu": vtk.vtkXMLPUnstructuredGridReader}[path.suffix]()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    types = vtk_to_numpy(grid.GetCellTypesArray())
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputData(grid)
    sizes.ComputeVolumeOn()
    sizes.Update()
    v = vtk_to_numpy(sizes.GetOutput().GetCellData().GetArray("Volume"))
    counts = {t: int(np.count_nonzero(types == t)) for t in SOLID_TYPES}
    return counts, float(np.abs(v[np.isin(types, SOLID_TYPES)]).sum()), f"VTK {vtk.vtkVersion.GetVTKVersion()}"


def agrees(run, path):
    """None when the second reader counts the cells halo4d counts, of each kind, and the
    same volume (to 1e-9 where every quadrilateral is planar; to 2% where some are bent, the
    readers splitting them apart); else what differs."""
    try:
        counts, volume, who = second_reader(path)
    except Exception as e:  # noqa: BLE001 - a reader that cannot read the file is a finding
        return f"the second reader could not read it: {type(e).__name__}: {str(e)[:80]}"
    mesh = run["report"]["meshes"][0]
    cells = mesh["certificate"].get("cells")
    ours = {10: mesh["stats"]["tets"], 12: 0, 13: 0, 14: 0} if cells is None else \
        {10: cells["tetrahedra"], 12: cells["hexahedra"], 13: cells["wedges"], 14: cells["pyramids"]}
    tolerance = 1e-9 if cells is None or cells["nonplanar_quads"] == 0 else 2e-2
    if counts != ours or not abs(mesh["stats"]["volume"] - volume) <= tolerance * volume:
        said = lambda c: ", ".join(f"{c[t]} {NAMES[t]}" for t in SOLID_TYPES)
        return f"{who} reads {said(counts)} of volume {volume:.12g}, halo4d {said(ours)} of {mesh['stats']['volume']:.12g}"
    return None


def kuhn(points, h):
    """Kuhn's six tetrahedra of hexahedron `h` (VTK order) around its diagonal 0-6."""
    paths = ([0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6])
    tets = np.array([h[p] for p in paths])
    for t in tets:
        a, b, c, d = points[t]
        assert np.linalg.det(np.array([b - a, c - a, d - a])) > 0
    return tets


def split_hex(grid):
    """The hexahedron with the most side faces shared with other hexahedra, split."""
    cells = {t: c.copy() for t, c in grid.cells_dict.items()}
    hexes = cells[12]
    sides = ([0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7])
    uses = {}
    for h in hexes:
        for s in sides:
            uses[tuple(sorted(h[s]))] = uses.get(tuple(sorted(h[s])), 0) + 1
    k = int(np.argmax([sum(uses[tuple(sorted(h[s]))] == 2 for s in sides) for h in hexes]))
    cells[10] = np.vstack([cells[10], kuhn(grid.points, hexes[k])])
    cells[12] = np.delete(hexes, k, axis=0)
    return cells


def changed(grid, kind, change):
    cells = {t: c.copy() for t, c in grid.cells_dict.items()}
    cells[kind] = change(cells[kind])
    return cells


def bottom_pyramid(grid):
    """The index of a pyramid with a base edge on the bottom of the box: removed, it leaves a
    hollow that meets the boundary along that edge."""
    z = grid.points[:, 2]
    for k, p in enumerate(grid.cells_dict[14]):
        if np.count_nonzero(z[p[:4]] == z.min()) == 2:
            return k
    raise ValueError("no pyramid at the bottom")


def fault_cases(grids):
    """[(name, cells by VTK type, points, failure names that must come (none: passes), what)]."""
    twisted, straight = grids["hybrid-twisted"], grids["hybrid-straight"]
    mirror = {13: [0, 2, 1, 3, 5, 4], 14: [0, 3, 2, 1, 4]}
    k = bottom_pyramid(twisted)
    return [
        ("mixed-split-hex", split_hex(twisted), twisted.points, ("nonconforming_quads",),
         "a hexahedron of bent faces split into Kuhn's six tetrahedra"),
        ("mixed-straight-split-hex", split_hex(straight), straight.points, (),
         "the same in the straight hybrid, its faces planar: conforming"),
        ("mixed-mirrored-wedge", changed(twisted, 13, lambda c: np.vstack([c[:1, mirror[13]], c[1:]])), twisted.points,
         ("inverted",), "one wedge's corners mirrored"),
        ("mixed-mirrored-pyramid", changed(twisted, 14, lambda c: np.vstack([c[:1, mirror[14]], c[1:]])), twisted.points,
         ("inverted",), "one pyramid's base reversed"),
        ("mixed-duplicate-hex", changed(twisted, 12, lambda c: np.vstack([c, c[:1]])), twisted.points,
         ("overshared_faces",), "one hexahedron twice"),
        ("mixed-gap", changed(twisted, 14, lambda c: np.delete(c, k, axis=0)), twisted.points,
         ("nonmanifold_edges",), "a pyramid at the bottom removed: a hollow meeting the boundary along an edge"),
    ]


def write_cells(path, cells, points):
    pyvista.UnstructuredGrid({t: c for t, c in cells.items() if len(c)}, np.asarray(points, dtype=np.float64)).save(str(path))


# The same changes as tetmesh-corpus.py's TRANSFORMS, on mixed meshes.
TRANSFORMS = (
    ("moved by 1e6 sizes", lambda p: p + 1e6 * max(np.abs(p).max(), 1e-300), False),
    ("scaled by 2^100", lambda p: p * 2.0**100, True),
    ("scaled by 2^-100", lambda p: p * 2.0**-100, True),
    ("an unused vertex at 1e308", lambda p: np.vstack([p, [[1e308, -1e308, 1e308]]]), True),
)


def corpus(binary, out, run_halo4d, judge, ms):
    """Every mixed mesh and fault, checked: (table rows, failures, files). `run_halo4d`,
    `judge` and `ms` are tetmesh-corpus.py's."""
    clean, faults, moved = out / "mixed", out / "mixed-faults", out / "mixed-transformed"
    for d in (clean, faults, moved):
        d.mkdir(parents=True, exist_ok=True)
    rows, failed, files = [], [], 0
    print("== mixed meshes from Gmsh, as Gmsh, VTK and PyVista write them")
    with contextlib.redirect_stdout(io.StringIO()):
        groups, grids = make_clean(clean)
    originals = []  # (name, cells, points, run, planted)

    class Passes:
        names, extra = (), None

    for name, paths in groups:
        runs = [run_halo4d(binary, p) for p in paths]
        bad = []
        for p, run in zip(paths, runs):
            ok, cell = judge(run, Passes)
            if ok:
                differs = agrees(run, p)
                if differs:
                    ok, cell = False, f"DISAGREES: {differs}"
            print(f"{p.name}: {cell}")
            if not ok:
                bad.append(p.name)
                failed.append(f"{p.name}: {cell}")
        files += len(paths)
        report = runs[0]["report"]
        cells = report["meshes"][0]["certificate"].get("cells", {}) if report else {}
        what = ", ".join(f"{cells.get(k, '?')} {k}" for k in ("hexahedra", "wedges", "pyramids", "tetrahedra"))
        bent = f"{cells.get('nonplanar_quads', '?')} of {cells.get('quads', '?')} quadrilaterals bent"
        times = f"{ms(min(r['ms'] for r in runs))}-{ms(max(r['ms'] for r in runs))}"
        cell = f"FAILED {len(bad)}/{len(paths)} ({', '.join(bad[:3])})" if bad else f"passed {len(paths)}/{len(paths)} files, {times}"
        rows.append((f"clean mixed {name} ({what}; {bent}; {len(paths)} files)", "passes, a second reader agreeing",
                     cell, "", "", "", ""))
        if name in grids:
            originals.append((name, grids[name].cells_dict, grids[name].points, runs[0], ()))

    print("== mixed meshes with planted faults")
    for name, cells, points, names, what in fault_cases(grids):
        path = faults / f"{name}.vtu"
        write_cells(path, cells, points)
        run = run_halo4d(binary, path)

        class Case:
            pass

        Case.names, Case.extra = names, None
        ok, cell = judge(run, Case)
        print(f"{path.name}: {cell}")
        if not ok:
            failed.append(f"{path.name}: {cell}")
        files += 1
        originals.append((name, cells, points, run, names))
        rows.append((f"{path.name}: {what}", "fails: " + ", ".join(names) if names else "passes", cell, "", "", "", ""))

    print("== every mixed mesh again: moved far away, scaled by powers of two, with an unused vertex at 1e308")
    for label, change, exact in TRANSFORMS:
        same, t, t0 = 0, 0.0, 0.0
        for name, cells, points, before, planted in originals:
            path = moved / f"{name}-{label.replace(' ', '-').replace('^', '')}.vtu"
            write_cells(path, cells, change(np.asarray(points, dtype=np.float64)))
            run = run_halo4d(binary, path)
            want = (before["status"], sorted(set(before["names"])))
            got = (run["status"], sorted(set(run["names"])))
            t += run["ms"]
            t0 += before["ms"]
            if got == want or (not exact and got[0] == want[0] and set(planted) <= set(got[1])):
                same += 1
            else:
                failed.append(f"{path.name}: exit {got[0]} {got[1]}, the original exit {want[0]} {want[1]}")
                print(failed[-1])
        files += len(originals)
        rows.append((f"every mixed mesh above {label} ({len(originals)} files)", "the original's verdict",
                     f"{'same' if same == len(originals) else 'DIFFERENT'} verdict {same}/{len(originals)}, "
                     f"{ms(t)} in all (originals {ms(t0)})", "", "", "", ""))
    return rows, failed, files
