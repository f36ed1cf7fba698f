"""`halo4d check` on tetrahedral meshes from the real mesh generators, and on copies of them
with planted faults, beside what VTK, meshio and TetGen make of the same files. Gmsh (the
SDK wheel), TetGen (the `tetgen` wheel), meshio and VTK come from the venv of .ci/run.

  tetmesh-corpus.py --halo4d HALO4D --out DIR [--table FILE.md]
    - Gmsh meshes a cube, a torus, an L-shaped block and a block with a hole through it;
      TetGen meshes the same four from Gmsh's surface triangles. Each mesh is written by
      Gmsh itself (.msh 4.1 ASCII and binary, .msh 2.2, Medit .mesh) and by meshio (legacy
      .vtk binary and ASCII, .vtu binary with zlib, .msh 2.2 binary, .mesh, TetGen
      .node/.ele), by VTK's own writers (vtkXMLUnstructuredGridWriter in ASCII, inline
      binary and appended modes, uncompressed and with zlib, LZ4 and LZMA, UInt32 and
      UInt64 headers, with point, cell and field data, a string array among them;
      vtkUnstructuredGridWriter ASCII and binary; vtkXMLPUnstructuredGridWriter's .pvtu of
      four pieces) and by PyVista's `save`; Gmsh's cube also with a physical group, as 2.2
      binary, with parametric nodes and at order 2. `halo4d check FILE --json` must pass
      every one (exit status 0), and a second reader (VTK for VTK's formats, meshio for the
      others) must count the same tetrahedra of the same volume.
    - Every clean mesh and planted fault again, moved by 1e6 times its size, scaled by
      2^100 and 2^-100, and with one vertex no cell uses at 1e308: the same verdict as the
      original (moved, which rounds the coordinates: the same exit status and planted
      faults named), the times side by side.
    - Faults planted with numpy in copies of the Gmsh cube, and meshes built to be wrong
      (see CASES below): each must fail (exit status 1) with the expected name among the
      JSON `failures`; the cube with an interior tetrahedron removed, the cube scaled by
      1e150 and 1e-150, and a mesh with a 1e-9 sliver must pass, the cavity counted and
      the sliver named the worst tetrahedron.
    - On the same files, timed: vtkCellValidator (a cell is flagged when its State is not
      Valid), vtkMeshQuality (flagged when the volume is not positive or the radius ratio is
      not finite or Verdict's 1e30 for a degenerate cell), meshio.read, and TetGen's own check (-C), which the wrapper runs on the
      meshes TetGen makes and on nothing else. A Markdown table, one row a mesh or fault,
      one column a tool, goes to stdout and to FILE.md.
    Exit status 0 when halo4d passes every clean file and names every planted fault, 1
    otherwise; what the other tools miss is reported, never a failure.

  tetmesh-corpus.py --fixtures DIR
    Writes the small clean and faulty meshes as legacy ASCII .vtk (meshio) into DIR, with
    a README.md naming what `halo4d check` must say of each: the Rust tests' fixtures.
    Deterministic (one thread, fixed choices), so that a rerun rewrites the same bytes.
"""

import argparse
import contextlib
import io
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import gmsh
import meshio
import numpy as np
import pyvista
import tetgen
import vtk
from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray, vtk_to_numpy

import mixed_corpus
import vtk_pieces

# Gmsh's target edge length per shape: a few hundred to two thousand tetrahedra each.
SHAPES = {"cube": 0.2, "torus": 0.2, "l-block": 0.3, "holed-block": 0.25}
# The cube the faults are planted in: coarse enough that its ASCII .vtk stays under 50 KB.
FAULT_BASE_SIZE = 0.25
# TetGen's switches: a PLC (p), quality bound 1.5 on the radius-edge ratio (q), a volume
# bound (a), quiet (Q).
TETGEN_SWITCHES = "pq1.5a0.01Q"
SLIVER_HEIGHT = 1e-9
SLIVER_INDEX = 2
FAILURE_NAMES = {
    "inverted", "flat", "undecidable", "degenerate", "duplicate_tets", "overshared_faces",
    "folded_faces", "volume_defect", "open_edges", "nonmanifold_edges", "misoriented_edges",
    "nonmanifold_vertices", "hanging_vertices", "self_intersections", "wrong_winding",
}


# -- geometry -----------------------------------------------------------------------------


def volumes(points, tets):
    """Six times each tetrahedron's signed volume, positive when (a, b, c) turns
    counterclockwise seen from d (VTK's and Gmsh's convention)."""
    a, b, c, d = (points[tets[:, i]] for i in range(4))
    return np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))


def oriented(points, tets):
    """The tetrahedra with the first two vertices of each negative one swapped."""
    tets = np.array(tets, dtype=np.int64).reshape(-1, 4)
    negative = volumes(points, tets) < 0
    tets[negative, 0], tets[negative, 1] = tets[negative, 1].copy(), tets[negative, 0].copy()
    return tets


def faces_of(tets):
    """Each tetrahedron's four faces as sorted vertex triples: (faces, tet, opposite)."""
    tri = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
    faces = np.sort(tets[:, tri].reshape(-1, 3), axis=1)
    owner = np.repeat(np.arange(len(tets)), 4)
    opposite = tets.reshape(-1)
    return faces, owner, opposite


def boundary_vertices(tets):
    faces, _, _ = faces_of(tets)
    unique, counts = np.unique(faces, axis=0, return_counts=True)
    return set(unique[counts == 1].reshape(-1).tolist())


def interior_faces(tets):
    """{sorted face: [(tet, opposite vertex), ...]} of the faces two tetrahedra share."""
    faces, owner, opposite = faces_of(tets)
    shared = {}
    for f, t, o in zip(map(tuple, faces.tolist()), owner.tolist(), opposite.tolist()):
        shared.setdefault(f, []).append((t, o))
    return {f: v for f, v in shared.items() if len(v) == 2}


# -- the generators -----------------------------------------------------------------------


class Gmsh:
    """One Gmsh session, single-threaded so that its meshes repeat exactly."""

    def __enter__(self):
        gmsh.initialize(interruptible=False)
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.option.setNumber("Mesh.MaxNumThreads3D", 1)
        return self

    def __exit__(self, *exc):
        gmsh.finalize()

    def mesh(self, shape, size):
        """Meshes `shape` (a name of SHAPES or "ball", "small-ball"); the model stays
        loaded for write(). Returns (points, tets, boundary triangles), compacted to the
        vertices the tetrahedra use, 0-based."""
        gmsh.clear()
        gmsh.model.add(shape)
        occ = gmsh.model.occ
        if shape == "cube":
            occ.addBox(0, 0, 0, 1, 1, 1)
        elif shape == "torus":
            occ.addTorus(0, 0, 0, 1, 0.35)
        elif shape == "l-block":
            occ.cut([(3, occ.addBox(0, 0, 0, 2, 2, 1))], [(3, occ.addBox(1, 1, -1, 2, 2, 3))])
        elif shape == "holed-block":
            occ.cut([(3, occ.addBox(0, 0, 0, 2, 1, 1))], [(3, occ.addCylinder(1, 0.5, -1, 0, 0, 3, 0.25))])
        elif shape == "ball":
            occ.addSphere(0, 0, 0, 1)
        elif shape == "small-ball":
            occ.addSphere(0, 0, 0, 0.5)
        else:
            raise ValueError(shape)
        occ.synchronize()
        # A physical group, as most users' models have: Gmsh then writes its elements only.
        gmsh.model.addPhysicalGroup(3, [t for _, t in gmsh.model.getEntities(3)], name="solid")
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.option.setNumber("Mesh.MeshSizeMin", size / 2)
        gmsh.model.mesh.generate(3)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        index = np.full(int(tags.max()) + 1, -1)
        index[tags.astype(np.int64)] = np.arange(len(tags))
        points = coords.reshape(-1, 3)
        _, tet_nodes = gmsh.model.mesh.getElementsByType(4)
        _, tri_nodes = gmsh.model.mesh.getElementsByType(2)
        tets = index[tet_nodes.astype(np.int64)].reshape(-1, 4)
        tris = index[tri_nodes.astype(np.int64)].reshape(-1, 3)
        used, inverse = np.unique(tets, return_inverse=True)
        remap = np.full(len(points), -1)
        remap[used] = np.arange(len(used))
        return points[used], inverse.reshape(-1, 4), remap[tris]

    @staticmethod
    def load(points, tets):
        """Loads a mesh made elsewhere (TetGen's) as one discrete volume, for write()."""
        gmsh.clear()
        gmsh.model.add("imported")
        gmsh.model.addDiscreteEntity(3, 1)
        gmsh.model.mesh.addNodes(3, 1, np.arange(1, len(points) + 1), points.reshape(-1))
        gmsh.model.mesh.addElementsByType(1, 4, [], (tets + 1).reshape(-1))

    @staticmethod
    def write(path, version, binary, parametric=False):
        gmsh.option.setNumber("Mesh.MshFileVersion", version)
        gmsh.option.setNumber("Mesh.Binary", int(binary))
        gmsh.option.setNumber("Mesh.SaveParametric", int(parametric))
        gmsh.write(str(path))
        gmsh.option.setNumber("Mesh.SaveParametric", 0)


def captured(fn):
    """Calls fn with the process's stdout (file descriptor 1, where TetGen's C++ prints)
    caught; returns (fn's result, the text)."""
    sys.stdout.flush()
    saved = os.dup(1)
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 1)
        try:
            result = fn()
        finally:
            sys.stdout.flush()
            os.dup2(saved, 1)
            os.close(saved)
        tmp.seek(0)
        return result, tmp.read().decode(errors="replace")


def tetgen_mesh(points, tris):
    """TetGen's tetrahedralization of a closed triangle surface, and the verdict of its
    own consistency check (-C) on that output."""
    (nodes, elem, *_), _ = captured(lambda: tetgen.TetGen(points, tris).tetrahedralize(switches=TETGEN_SWITCHES))
    t0 = time.perf_counter()
    (nodes_c, elem_c, *_), log = captured(
        lambda: tetgen.TetGen(points, tris).tetrahedralize(switches=TETGEN_SWITCHES.replace("Q", "C"))
    )
    checked = (time.perf_counter() - t0) * 1000
    consistent = "the mesh appears to be consistent" in log and "Mesh boundaries connected correctly" in log
    same = np.array_equal(nodes, nodes_c) and np.array_equal(elem, elem_c)
    verdict = {
        "consistent": consistent and same,
        "text": f"{'consistent' if consistent else 'INCONSISTENT'} (-C on the mesh it made"
        + ("" if same else ", not the one written")
        + f"; meshing and check {ms(checked)})",
    }
    return np.asarray(nodes, dtype=np.float64), np.asarray(elem, dtype=np.int64), verdict


# -- writing ------------------------------------------------------------------------------


def tet_mesh(points, tets):
    return meshio.Mesh(np.asarray(points, dtype=np.float64), [("tetra", np.asarray(tets, dtype=np.int64))])


def write_meshio(path, points, tets):
    """Writes by the suffix: .vtk (legacy 5.1 binary; `-ascii.vtk`: 4.2 ASCII), .vtu
    (binary, zlib), .msh (2.2 binary), .mesh, .ele (TetGen's .node and .ele)."""
    # meshio's warnings here are expected (ASCII VTK "for debugging", no Gmsh physical tags).
    with contextlib.redirect_stderr(io.StringIO()):
        _write_meshio(Path(path), tet_mesh(points, tets))


def _write_meshio(path, mesh):
    if path.suffix == ".vtk":
        ascii_ = path.stem.endswith("-ascii")
        meshio.vtk.write(path, mesh, fmt_version="4.2" if ascii_ else "5.1", binary=not ascii_)
    elif path.suffix == ".vtu":
        meshio.vtu.write(path, mesh, binary=True, compression="zlib")
    elif path.suffix == ".msh":
        meshio.gmsh.write(path, mesh, fmt_version="2.2", binary=True)
    elif path.suffix == ".mesh":
        meshio.medit.write(path, mesh)
    elif path.suffix == ".ele":
        meshio.tetgen.write(path.with_suffix(".node"), mesh)
    else:
        raise ValueError(path)


GMSH_FORMATS = (("msh41", 4.1, False, False), ("msh41-binary", 4.1, True, False), ("msh22", 2.2, False, False))
# What Gmsh writes of a model it meshed itself (nodes on its curves and surfaces have
# parameters to save).
GMSH_MODEL_FORMATS = GMSH_FORMATS + (("msh22-binary", 2.2, True, False), ("msh41-parametric", 4.1, False, True),
                                     ("msh41-parametric-binary", 4.1, True, True), ("msh22-parametric", 2.2, False, True))


def write_all_formats(folder, stem, formats=GMSH_FORMATS):
    """Every format of one mesh loaded in Gmsh: Gmsh's own writers, then meshio's, VTK's
    and PyVista's from the arrays. Returns a function of (points, tets) that writes the
    others, and the Gmsh files' paths."""
    written = []
    for name, version, binary, parametric in formats:
        written.append(folder / f"{stem}-gmsh-{name}.msh")
        Gmsh.write(written[-1], version, binary, parametric)
    written.append(folder / f"{stem}-gmsh.mesh")
    gmsh.write(str(written[-1]))

    def other_formats(points, tets):
        paths = [folder / f"{stem}{suffix}" for suffix in
                 (".vtk", "-ascii.vtk", ".vtu", "-meshio-msh22-binary.msh", "-meshio.mesh", ".ele")]
        for p in paths:
            write_meshio(p, points, tets)
        return paths + write_vtk_formats(folder, stem, points, tets)

    return written, other_formats


# -- VTK's own writers --------------------------------------------------------------------

# (file name's end, data mode, compressor, UInt64 headers): what vtkXMLUnstructuredGridWriter
# writes (PyVista, the `tetgen` package and pytetwild write through it too).
VTU_MODES = (
    ("ascii", "Ascii", "None", False),
    ("binary", "Binary", "None", False),
    ("binary-zlib", "Binary", "ZLib", False),
    ("binary-lz4", "Binary", "LZ4", False),
    ("binary-lzma", "Binary", "LZMA", False),
    ("appended", "Appended", "None", False),
    ("appended-zlib", "Appended", "ZLib", False),
    ("appended-lz4-uint64", "Appended", "LZ4", True),
    ("appended-lzma", "Appended", "LZMA", False),
    ("appended-base64-zlib", "Appended", "ZLib", False),
)
PIECES = 4


def vtk_grid(points, tets):
    """A vtkUnstructuredGrid of the tetrahedra (double points) with what a simulation's
    file carries: point data (a scalar with its ranges computed, which VTK 9 writes as
    InformationKey elements inside the DataArray, an Int32 id, a vector), cell data and
    field data with a string array."""
    grid = vtk.vtkUnstructuredGrid()
    p = vtk.vtkPoints()
    p.SetDataTypeToDouble()
    p.SetData(numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float64), deep=True))
    grid.SetPoints(p)
    cells = vtk.vtkCellArray()
    offsets = np.arange(0, 4 * len(tets) + 1, 4, dtype=np.int64)
    cells.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True),
                  numpy_to_vtkIdTypeArray(np.ascontiguousarray(tets, dtype=np.int64).reshape(-1), deep=True))
    grid.SetCells(vtk.VTK_TETRA, cells)
    arrays = []
    for data, name, values in ((grid.GetPointData(), "distance", np.linalg.norm(points, axis=1)),
                               (grid.GetPointData(), "id", np.arange(len(points), dtype=np.int32)),
                               (grid.GetPointData(), "velocity", np.ascontiguousarray(points[:, ::-1])),
                               (grid.GetCellData(), "volume", volumes(points, tets) / 6)):
        a = numpy_to_vtk(np.ascontiguousarray(values), deep=True)
        a.SetName(name)
        a.GetRange(-1)
        data.AddArray(a)
        arrays.append(a)
    notes = vtk.vtkStringArray()
    notes.SetName("notes")
    for text in ("made by .ci/tetmesh-corpus.py", "a second string"):
        notes.InsertNextValue(text)
    grid.GetFieldData().AddArray(notes)
    grid.GetPoints().GetData().GetRange(-1)
    return grid


def write_pvtu(path, points, tets, pieces=PIECES, shift=None):
    """A .pvtu of `pieces` pieces as vtkXMLPUnstructuredGridWriter writes them: the
    tetrahedra split by their centroid's x into slabs of equal count, each piece with the
    points its tetrahedra use (the points on a cut are in both pieces); `shift` moves the
    second piece's points (all of them) by that vector."""
    x = points[tets].mean(axis=1)[:, 0]
    parts = np.array_split(np.argsort(x, kind="stable"), pieces)

    def make(k):
        used, local = np.unique(tets[np.sort(parts[k])], return_inverse=True)
        moved = points[used] + (np.asarray(shift) if shift is not None and k == 1 else 0.0)
        return vtk_grid(moved, local.reshape(-1, 4))

    vtk_pieces.write_pvtu(path, make, pieces)


def write_vtk_formats(folder, stem, points, tets):
    """The mesh as VTK's writers and PyVista's `save` write it; their paths."""
    points, tets = np.asarray(points, dtype=np.float64), np.asarray(tets, dtype=np.int64)
    grid = vtk_grid(points, tets)
    paths = []
    for end, mode, compressor, uint64 in VTU_MODES:
        paths.append(folder / f"{stem}-vtk-{end}.vtu")
        w = vtk.vtkXMLUnstructuredGridWriter()
        w.SetInputData(grid)
        w.SetFileName(str(paths[-1]))
        getattr(w, f"SetDataModeTo{mode}")()
        getattr(w, f"SetCompressorTypeTo{compressor}")()
        w.SetEncodeAppendedData(int("base64" in end))
        if uint64:
            w.SetHeaderTypeToUInt64()
        if w.Write() != 1:
            raise RuntimeError(f"VTK could not write {paths[-1]}")
    for end, binary in (("ascii", False), ("binary", True)):
        paths.append(folder / f"{stem}-vtk-legacy-{end}.vtk")
        w = vtk.vtkUnstructuredGridWriter()
        w.SetInputData(grid)
        w.SetFileName(str(paths[-1]))
        if binary:
            w.SetFileTypeToBinary()
        if w.Write() != 1:
            raise RuntimeError(f"VTK could not write {paths[-1]}")
    paths.append(folder / f"{stem}-vtk-pieces.pvtu")
    write_pvtu(paths[-1], points, tets)
    for suffix in (".vtu", ".vtk"):
        paths.append(folder / f"{stem}-pyvista{suffix}")
        pyvista.wrap(grid).save(paths[-1])
    return paths


def second_reader(path):
    """(tetrahedra, their total volume, reader) as another program reads the file: VTK's
    readers for VTK's formats, Gmsh's for .msh (the corners of quadratic and higher-order
    tetrahedra), meshio for the others."""
    path = Path(path)
    if path.suffix in (".vtu", ".vtk", ".pvtu"):
        reader = {".vtu": vtk.vtkXMLUnstructuredGridReader, ".vtk": vtk.vtkUnstructuredGridReader,
                  ".pvtu": vtk.vtkXMLPUnstructuredGridReader}[path.suffix]()
        reader.SetFileName(str(path))
        reader.Update()
        grid = reader.GetOutput()
        points = vtk_to_numpy(grid.GetPoints().GetData()).astype(np.float64)
        cells = grid.GetCells()
        conn = vtk_to_numpy(cells.GetConnectivityArray())
        offsets = vtk_to_numpy(cells.GetOffsetsArray())
        types = vtk_to_numpy(grid.GetCellTypesArray())
        tet = np.isin(types, (vtk.VTK_TETRA, vtk.VTK_QUADRATIC_TETRA, vtk.VTK_LAGRANGE_TETRAHEDRON,
                              vtk.VTK_BEZIER_TETRAHEDRON))
        starts = offsets[:-1][tet]
        tets = conn[starts[:, None] + np.arange(4)]
        who = f"VTK {vtk.vtkVersion.GetVTKVersion()}"
    elif path.suffix == ".msh":
        gmsh.initialize(interruptible=False)
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.open(str(path))
            tags, coords, _ = gmsh.model.mesh.getNodes()
            index = np.full(int(tags.max()) + 1, -1)
            index[tags.astype(np.int64)] = np.arange(len(tags))
            points = coords.reshape(-1, 3)
            blocks = []
            for kind in (4, 11, 29, 30, 31):  # tetrahedra of order 1 to 5
                _, nodes = gmsh.model.mesh.getElementsByType(kind)
                if len(nodes):
                    blocks.append(index[nodes.astype(np.int64)].reshape(len(nodes) // gmsh.model.mesh.getElementProperties(kind)[3], -1)[:, :4])
            tets = np.vstack(blocks) if blocks else np.zeros((0, 4), dtype=np.int64)
        finally:
            gmsh.finalize()
        who = f"Gmsh {gmsh.__version__}"
    else:
        with contextlib.redirect_stderr(io.StringIO()):
            mesh = meshio.read(path)
        points = np.asarray(mesh.points, dtype=np.float64)
        blocks = [c.data[:, :4] for c in mesh.cells if c.type.startswith("tetra")]
        tets = np.vstack(blocks) if blocks else np.zeros((0, 4), dtype=np.int64)
        who = f"meshio {meshio.__version__}"
    return len(tets), float(np.abs(volumes(points, tets)).sum() / 6) if len(tets) else 0.0, who


def agrees(run, path):
    """None when the second reader counts as many tetrahedra as halo4d, of the same volume;
    else what differs."""
    try:
        count, volume, who = second_reader(path)
    except Exception as e:  # noqa: BLE001 - a reader that cannot read the file is a finding
        return f"the second reader could not read it: {type(e).__name__}: {str(e)[:80]}"
    stats = run["report"]["meshes"][0]["stats"]
    if stats["tets"] != count or not abs(stats["volume"] - volume) <= 1e-9 * max(volume, 1e-300):
        return f"{who} reads {count} tetrahedra of volume {volume:.12g}, halo4d {stats['tets']} of {stats['volume']:.12g}"
    return None


# -- the same meshes moved, scaled, and with a vertex far away ------------------------------

# (name, the change, whether it is exact): scaling by a power of two and adding a vertex
# change no coordinate's value relative to another, so the verdict must be the original's
# to the last name; moving by 1e6 sizes rounds away the coordinates' last 20 bits, a slightly
# different mesh, so only the exit status and the planted faults' names must be the same
# (a degenerate construction, such as a ray through an edge, may then come out otherwise).
TRANSFORMS = (
    ("moved by 1e6 sizes", lambda p: p + 1e6 * max(np.abs(p).max(), 1e-300), False),
    ("scaled by 2^100", lambda p: p * 2.0**100, True),
    ("scaled by 2^-100", lambda p: p * 2.0**-100, True),
    ("an unused vertex at 1e308", lambda p: np.vstack([p, [[1e308, -1e308, 1e308]]]), True),
)


def transformed_runs(binary, folder, meshes):
    """halo4d check on each (name, points, tets, original run, planted fault names) written
    again by meshio (.vtu, zlib) under each of TRANSFORMS: (table rows, failures)."""
    folder.mkdir(parents=True, exist_ok=True)
    rows, failed = [], []
    for label, change, exact in TRANSFORMS:
        same, times, original = 0, 0.0, 0.0
        for name, points, tets, before, planted in meshes:
            path = folder / f"{name}-{label.replace(' ', '-').replace('^', '')}.vtu"
            write_meshio(path, change(np.asarray(points, dtype=np.float64)), tets)
            run = run_halo4d(binary, path)
            want = (before["status"], sorted(set(before["names"])))
            got = (run["status"], sorted(set(run["names"])))
            times += run["ms"]
            original += before["ms"]
            if got == want:
                same += 1
            elif not exact and got[0] == want[0] and set(planted) <= set(got[1]):
                same += 1
                print(f"{path.name}: exit {got[0]} {got[1]}, the original {want[1]}: the planted faults named in both")
            else:
                failed.append(f"{path.name}: exit {got[0]} {got[1]}, the original exit {want[0]} {want[1]}")
                print(failed[-1])
        rows.append((f"every mesh above {label} ({len(meshes)} files)", "the original's verdict",
                     f"{'same' if same == len(meshes) else 'DIFFERENT'} verdict {same}/{len(meshes)}, "
                     f"{ms(times)} in all (originals {ms(original)})", "", "", "", ""))
    return rows, failed


# -- the planted faults -------------------------------------------------------------------


class Case:
    """A mesh and what halo4d check must say of it: `names`, the failure names that must
    be among its failures (none: it must pass), and `extra`, a test of the JSON report
    with its description."""

    def __init__(self, name, points, tets, names=(), extra=None, suffix=".vtu", what="", writer=None):
        self.name, self.points, self.tets = name, np.asarray(points, dtype=np.float64), np.asarray(tets)
        self.names, self.extra, self.suffix, self.what = tuple(names), extra, suffix, what
        # How the file is written (meshio's writer by the suffix unless said otherwise).
        self.writer = writer or write_meshio

    @property
    def expect(self):
        if self.names:
            return "fails: " + ", ".join(self.names)
        return "passes" + (f", {self.extra[0]}" if self.extra else "")


def flip_one(tets):
    tets = tets.copy()
    i = len(tets) // 2
    tets[i, [0, 1]] = tets[i, [1, 0]]
    return tets


def interior_tet(points, tets, rng):
    """A tetrahedron none of whose vertices is on the boundary."""
    boundary = boundary_vertices(tets)
    inner = [i for i, t in enumerate(tets.tolist()) if not boundary.intersection(t)]
    if not inner:
        raise RuntimeError("no tetrahedron away from the boundary; mesh finer")
    return inner[rng.integers(len(inner))]


def overlapping(points, tets, rng):
    """Mirrors o2, the apex of T2 across an interior face (a, b, c) from T1, through the
    plane of (a, b, c) onto o1's side, then turns every tetrahedron that became negative
    positive again: each face still pairs up, but T1 and T2 overlap."""
    boundary = boundary_vertices(tets)
    shared = interior_faces(tets)
    keys = sorted(shared)
    scale = np.median(np.abs(volumes(points, tets)))
    for k in rng.permutation(len(keys)):
        face = keys[k]
        (t1, o1), (t2, o2) = shared[face]
        if o2 in boundary:
            continue
        a, b, c = points[list(face)]
        n = np.cross(b - a, c - a)
        n /= np.linalg.norm(n)
        moved = points.copy()
        moved[o2] = points[o2] - 2 * np.dot(points[o2] - a, n) * n
        fixed = oriented(moved, tets)
        star = np.any(tets == o2, axis=1)
        # Far from flat, so that the fault is a fold and not a near-degenerate tetrahedron.
        if np.min(np.abs(volumes(moved, fixed[star]))) < 0.05 * scale:
            continue
        return moved, fixed
    raise RuntimeError("no interior face to fold")


def hanging(points, tets, rng):
    """Splits an interior tetrahedron (a, b, c, d) at h = (a + b + 2c) / 4, a point of the
    face (a, b, c), into (a, b, h, d), (b, c, h, d), (c, a, h, d); the neighbour across
    (a, b, c) keeps the whole face, so h hangs in it. The coordinates are rounded to
    multiples of 2^-20 first, so that h is computed exactly and lies exactly on the face:
    a point a rounding off it would make a thin cavity or overlap instead, which is what
    an exact check must then say."""
    points = np.round(points * 2.0**20) / 2.0**20
    i = interior_tet(points, tets, rng)
    a, b, c, d = tets[i].tolist()
    h = len(points)
    points = np.vstack([points, (points[a] + points[b] + 2 * points[c]) / 4])
    split = oriented(points, [[a, b, h, d], [b, c, h, d], [c, a, h, d]])
    return points, np.vstack([np.delete(tets, i, axis=0), split])


def nonmanifold(points, tets, size):
    """One tetrahedron outside the mesh touching it only at its boundary vertex farthest
    along (1, 1, 1)."""
    v = int(np.argmax(points.sum(axis=1)))
    s = size / 2
    extra = points[v] + s * np.array([[3.0, 1, 1], [1, 3, 1], [1, 1, 3]])
    n = len(points)
    points = np.vstack([points, extra])
    return points, np.vstack([tets, oriented(points, [[v, n, n + 1, n + 2]])])


def wrapped(k, turns):
    """An axis edge from (0, 0, -1) to (0, 0, 1) and a ring of turns * k vertices at
    angles 2 pi j / k, each with its own id (positions repeat after k); the tetrahedra
    (bottom, top, r_j, r_j+1) around the ring, cyclic, wind `turns` times around the
    axis."""
    m = turns * k
    angles = 2 * np.pi * np.arange(m) / k
    ring = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(m)])
    points = np.vstack([[[0, 0, -1], [0, 0, 1]], ring])
    tets = [[0, 1, 2 + j, 2 + (j + 1) % m] for j in range(m)]
    return points, oriented(points, tets)


def sliver():
    """Two square pyramids on a near-flat square a b c d (d SLIVER_HEIGHT above the
    plane of a b c): the sliver (a, b, c, d) between the square's two triangulations,
    the top apex over the upper one, the bottom apex under the lower one."""
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, SLIVER_HEIGHT], [0.5, 0.5, 1], [0.5, 0.5, -1]])
    a, b, c, d, t, u = range(6)
    tets = [[a, b, d, t], [b, c, d, t], [a, b, c, d], [a, b, c, u], [a, c, d, u]]
    assert tets[SLIVER_INDEX] == [a, b, c, d]
    return points, oriented(points, tets)


def cases(session):
    """The clean meshes and planted faults that are small enough to be fixtures too, in
    the order of the table."""
    rng = np.random.default_rng(20240611)
    cube_p, cube_t, _ = session.mesh("cube", FAULT_BASE_SIZE)
    cube_t = oriented(cube_p, cube_t)
    ball_p, ball_t, _ = session.mesh("ball", 0.4)
    small_p, small_t, _ = session.mesh("small-ball", 0.4)
    ball_t, small_t = oriented(ball_p, ball_t), oriented(small_p, small_t)

    cavity = np.delete(cube_t, interior_tet(cube_p, cube_t, rng), axis=0)
    sliver_p, sliver_t = sliver()
    out = [
        Case("cube", cube_p, cube_t, suffix=".vtu", what="Gmsh's cube, the mesh the faults below are planted in"),
        Case("cube-inverted", cube_p, flip_one(cube_t), ["inverted"], what="one tetrahedron with two vertices swapped"),
        Case("cube-duplicate", cube_p, np.vstack([cube_t, cube_t[len(cube_t) // 3]]), ["duplicate_tets"],
             suffix=".vtk", what="one tetrahedron twice"),
        Case("cube-cavity", cube_p, cavity, extra=("1 cavity", lambda r: r["meshes"][0]["certificate"]["boundary"]["cavities"] == 1),
             what="one tetrahedron with no vertex on the boundary removed: a cavity, not a fault"),
        Case("cube-overlapping", *overlapping(cube_p, cube_t, rng), ["folded_faces"],
             what="the apex of one tetrahedron mirrored through a face onto the other's side, the star reoriented: faces pair up, tetrahedra overlap"),
        Case("cube-hanging-vertex", *hanging(cube_p, cube_t, rng), ["hanging_vertices"], suffix=".vtk",
             what="an interior tetrahedron split at a point exactly on a face its neighbour keeps whole"),
        Case("cube-nonmanifold-vertex", *nonmanifold(cube_p, cube_t, FAULT_BASE_SIZE), ["nonmanifold_vertices"],
             what="a tetrahedron outside touching the cube at one boundary vertex"),
        Case("cube-1e150", cube_p * 1e150, cube_t, what="the cube scaled by 1e150"),
        Case("cube-1e150-inverted", cube_p * 1e150, flip_one(cube_t), ["inverted"], suffix=".vtk",
             what="scaled by 1e150, one tetrahedron flipped"),
        Case("cube-1e-150", cube_p * 1e-150, cube_t, what="the cube scaled by 1e-150"),
        Case("cube-1e-150-inverted", cube_p * 1e-150, flip_one(cube_t), ["inverted"], suffix=".vtk",
             what="scaled by 1e-150, one tetrahedron flipped"),
        Case("wrap-once", *wrapped(6, 1), suffix=".vtk", what="six tetrahedra around an axis edge, once round"),
        Case("wrap-twice", *wrapped(6, 2), ["wrong_winding"], suffix=".vtk",
             what="twelve tetrahedra around an axis edge, twice round (ring positions repeat, ids do not)"),
        Case("ball", ball_p, ball_t, what="Gmsh's ball of radius 1"),
        Case("nested-balls", np.vstack([ball_p, small_p]), np.vstack([ball_t, small_t + len(ball_p)]), ["wrong_winding"],
             what="Gmsh's balls of radius 1 and 0.5, meshed apart, in one file: the inner one is covered twice"),
        Case("cube-pieces-overlap", cube_p, cube_t, ["self_intersections"], suffix=".pvtu",
             writer=lambda path, p, t: write_pvtu(path, p, t, shift=(-0.3 * FAULT_BASE_SIZE, 0, 0)),
             what="the cube as a .pvtu of four slabs, the second moved into the first by 0.3 cells: the pieces overlap"),
        Case("sliver", sliver_p, sliver_t, extra=(f"worst tet {SLIVER_INDEX}",
             lambda r: r["meshes"][0]["certificate"]["quality"]["worst"][0]["tet"] == SLIVER_INDEX),
             suffix=".vtk", what=f"five tetrahedra, tetrahedron {SLIVER_INDEX} a sliver {SLIVER_HEIGHT:g} thick: quality is reported, not judged"),
    ]
    return out


# -- the tools ----------------------------------------------------------------------------


def timed(fn):
    t0 = time.perf_counter()
    result = fn()
    return result, (time.perf_counter() - t0) * 1000


def ms(t):
    return f"{t:.0f} ms" if t >= 1 else f"{t:.1f} ms"


def run_halo4d(binary, path):
    """halo4d check FILE --json: the exit status, the report (None when stdout is not one
    JSON object) and the failure names."""
    try:
        proc, t = timed(lambda: subprocess.run([binary, "check", str(path), "--json"],
                                               capture_output=True, text=True, timeout=120))
    except subprocess.TimeoutExpired:
        return {"status": None, "report": None, "names": [], "ms": 120000.0, "note": "timed out after 120 s"}
    try:
        report = json.loads(proc.stdout)
        if not isinstance(report, dict):
            raise ValueError("not an object")
    except ValueError:
        report = None
    names = []
    if report is not None:
        for failure in report.get("failures") or []:
            # "<count> <name> (...)", or "volume_defect <value> (...)": the first word that
            # is a name.
            words = str(failure).split()
            names.append(next((w for w in words if w[:1].isalpha()), str(failure)))
    note = ""
    if report is None:
        # The first line halo4d wrote, for a report that did not come.
        note = next((line.strip() for line in (proc.stderr + proc.stdout).splitlines() if line.strip()), "")[:120]
    return {"status": proc.returncode, "report": report, "names": names, "ms": t, "note": note}


def check_marks(binary, path, case, out):
    """halo4d check FILE --mark OUT.vtu, then OUT.vtu read by meshio, by VTK's XML reader and by
    halo4d check itself: the `fault` cell field the same in both readers, a tetrahedron
    marked exactly when the case has a fault (a cavity's bit, 2048, alone on a clean mesh),
    and the marked file, the same tetrahedra, the same verdict. What went wrong, or None."""
    marked = out / f"{path.stem}-marked.vtu"
    proc = subprocess.run([binary, "check", str(path), "--mark", str(marked)], capture_output=True, text=True, timeout=120)
    if proc.returncode not in (0, 1) or not marked.exists():
        return f"--mark exited {proc.returncode}: {proc.stderr.strip()[:120]}"
    by_meshio = np.asarray(meshio.read(marked).cell_data["fault"][0])
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(marked))
    reader.Update()
    grid = reader.GetOutput()
    by_vtk = np.array([grid.GetCellData().GetArray("fault").GetValue(i) for i in range(grid.GetNumberOfCells())])
    if len(by_meshio) != len(case.tets) or not np.array_equal(by_meshio, by_vtk):
        return f"meshio and VTK read {len(by_meshio)} and {len(by_vtk)} faults for {len(case.tets)} tetrahedra, or differ"
    faults = int(np.count_nonzero(by_meshio.astype(np.int64) & ~2048))
    if bool(case.names) != (faults > 0):
        return f"{faults} tetrahedra marked with a fault"
    again = run_halo4d(binary, marked)
    if again["status"] != proc.returncode:
        return f"the marked .vtu checks with exit {again['status']}, the file with {proc.returncode}"
    return None


def judge_halo4d(run, case):
    """(ok, table cell) of a halo4d run against the case's expectation."""
    t = ms(run["ms"])
    if run["report"] is None:
        return False, f"unknown (no JSON report, exit {run['status']}) {t}"
    names = sorted(set(run["names"]), key=run["names"].index)
    if case.names:
        missing = [n for n in case.names if n not in names]
        if run["status"] == 1 and not missing:
            return True, f"caught ({', '.join(names)}) {t}"
        if run["status"] == 1:
            return False, f"MISNAMED ({', '.join(names) or 'no names'}; want {', '.join(missing)}) {t}"
        return False, f"MISSED (exit {run['status']}) {t}"
    if run["status"] != 0 or run["report"].get("passes") is not True:
        return False, f"FAILED (exit {run['status']}: {', '.join(names) or 'no names'}) {t}"
    if case.extra:
        try:
            good = case.extra[1](run["report"])
        except (KeyError, IndexError, TypeError):
            good = False
        if not good:
            return False, f"passed, but not {case.extra[0]} {t}"
        return True, f"passed, {case.extra[0]} {t}"
    return True, f"passed {t}"


# What Verdict (vtkMeshQuality's library) returns for a cell it finds degenerate.
VERDICT_DEGENERATE = 1e30
VTK_STATES = {1: "WrongNumberOfPoints", 2: "IntersectingEdges", 4: "IntersectingFaces",
              8: "NoncontiguousEdges", 16: "Nonconvex", 32: "FacesAreOrientedIncorrectly"}


def vtk_read(path):
    path = Path(path)
    if path.suffix == ".vtu":
        reader = vtk.vtkXMLUnstructuredGridReader()
    elif path.suffix == ".vtk":
        reader = vtk.vtkUnstructuredGridReader()
    else:
        return None
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def run_cell_validator(path):
    """(flagged, detail, ms): cells whose vtkCellValidator State is not Valid."""
    def go():
        grid = vtk_read(path)
        if grid is None:
            return None
        validator = vtk.vtkCellValidator()
        validator.SetInputData(grid)
        validator.Update()
        return vtk_to_numpy(validator.GetOutput().GetCellData().GetArray("ValidityState"))

    state, t = timed(go)
    if state is None:
        return None, f"n/a ({Path(path).suffix})", t
    bad = state[state != 0]
    if len(bad) == 0:
        return False, "", t
    kinds = [name for bit, name in VTK_STATES.items() if np.any(bad & bit)]
    return True, f"{len(bad)}/{len(state)} cells {', '.join(kinds)}", t


def run_mesh_quality(path):
    """(flagged, detail, ms): cells whose vtkMeshQuality volume is not positive (<= 0 or
    NaN) or whose radius ratio is infinite, NaN or Verdict's 1e30 for a degenerate cell."""
    def go():
        grid = vtk_read(path)
        if grid is None:
            return None
        found = {}
        for measure, test in (("Volume", lambda q: ~(q > 0)), ("RadiusRatio", lambda q: ~(q < VERDICT_DEGENERATE))):
            quality = vtk.vtkMeshQuality()
            quality.SetInputData(grid)
            getattr(quality, f"SetTetQualityMeasureTo{measure}")()
            quality.Update()
            q = vtk_to_numpy(quality.GetOutput().GetCellData().GetArray("Quality"))
            found[measure] = int(np.count_nonzero(test(q)))
        found["cells"] = len(q)
        return found

    found, t = timed(go)
    if found is None:
        return None, f"n/a ({Path(path).suffix})", t
    parts = []
    if found["Volume"]:
        parts.append(f"{found['Volume']}/{found['cells']} volume <= 0 or NaN")
    if found["RadiusRatio"]:
        parts.append(f"{found['RadiusRatio']}/{found['cells']} radius ratio degenerate")
    return bool(parts), "; ".join(parts), t


def run_meshio(path):
    """(read, detail, ms): meshio.read, which checks the syntax and nothing of the mesh."""
    def go():
        try:
            # meshio prints why it cannot read a file; the table says it.
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
                mesh = meshio.read(path)
            return True, f"{sum(len(c.data) for c in mesh.cells if c.type == 'tetra')} tetra"
        # meshio ends the process (SystemExit) where no reader of the extension takes the file.
        except (Exception, SystemExit) as e:  # noqa: BLE001 - whatever meshio raises is its verdict
            return False, f"{type(e).__name__}: {str(e)[:60]}"

    (ok, detail), t = timed(go)
    return ok, detail, t


def other_cell(flagged, detail, t, should_fail):
    """A table cell for a tool other than halo4d."""
    if flagged is None:
        return detail
    if should_fail:
        return f"caught ({detail}) {ms(t)}" if flagged else f"missed {ms(t)}"
    return f"false alarm ({detail}) {ms(t)}" if flagged else f"passed {ms(t)}"


# -- the run ------------------------------------------------------------------------------


def corpus(binary, out, table_path):
    start = time.perf_counter()
    out.mkdir(parents=True, exist_ok=True)
    clean_dir, fault_dir = out / "clean", out / "faults"
    clean_dir.mkdir(exist_ok=True)
    fault_dir.mkdir(exist_ok=True)
    rows = []  # (row name, expectation, halo4d cell, validator, quality, meshio, tetgen)
    failed = []

    with Gmsh() as session:
        print("== clean meshes from Gmsh and TetGen, every format")
        groups = []
        for shape, size in SHAPES.items():
            points, tets, tris = session.mesh(shape, size)
            gmsh_files, other_formats = write_all_formats(clean_dir, f"{shape}-gmsh", GMSH_MODEL_FORMATS)
            files = gmsh_files + other_formats(points, tets)
            groups.append((f"{shape}, Gmsh", (points, tets), files, "not exposed (Gmsh made it)"))
            tg_points, tg_tets, verdict = tetgen_mesh(points, tris)
            if not verdict["consistent"]:
                print(f"{shape}: TetGen's -C check: {verdict['text']}")
            Gmsh.load(tg_points, tg_tets)
            gmsh_files, other_formats = write_all_formats(clean_dir, f"{shape}-tetgen")
            files = gmsh_files + other_formats(tg_points, tg_tets)
            groups.append((f"{shape}, TetGen", (tg_points, tg_tets), files, verdict["text"]))
        # Gmsh's cube at order 2: ten nodes a tetrahedron, the corners first.
        points, tets, _ = session.mesh("cube", 0.2)
        gmsh.model.mesh.setOrder(2)
        order2 = []
        for name, version, in_binary, parametric in GMSH_MODEL_FORMATS:
            order2.append(clean_dir / f"cube-order2-gmsh-{name}.msh")
            Gmsh.write(order2[-1], version, in_binary, parametric)
        groups.append(("cube at order 2, Gmsh", (points, tets), order2, "not exposed (Gmsh made it)"))
        fault_cases = cases(session)

    originals = []  # (name, points, tets, halo4d's run) for the transformed copies
    for label, (points, tets), files, tetgen_cell in groups:
        count = len(tets)
        case = Case(label, [], [])
        runs = [run_halo4d(binary, f) for f in files]
        originals.append((files[0].stem, points, tets, runs[0], ()))
        bad = []
        for f, run in zip(files, runs):
            ok, cell = judge_halo4d(run, case)
            if ok:
                differs = agrees(run, f)
                if differs:
                    ok, cell = False, f"DISAGREES: {differs}"
            print(f"{f.name}: {cell}" + ("" if ok or not run["note"] else f" ({run['note']})"))
            if not ok:
                bad.append(f.name)
                failed.append(f"{f.name}: {cell}")
        times = f"{ms(min(r['ms'] for r in runs))}-{ms(max(r['ms'] for r in runs))}"
        if all(r["report"] is None for r in runs):
            halo_cell = f"unknown (no JSON report) {times}"
        elif bad:
            halo_cell = f"FAILED {len(bad)}/{len(files)} ({', '.join(bad[:3])}{'...' if len(bad) > 3 else ''})"
        else:
            halo_cell = f"passed {len(files)}/{len(files)} files, {times}"
        reads = [run_meshio(f) for f in files]
        vtu = next((f for f in files if f.suffix == ".vtu"), None)
        meshio_ok = sum(r[0] for r in reads)
        meshio_cell = (f"read {meshio_ok}/{len(files)} files (no checks), {ms(min(r[2] for r in reads))}-{ms(max(r[2] for r in reads))}"
                       + ("" if meshio_ok == len(files) else
                          ": could not read " + ", ".join(f.name for f, r in zip(files, reads) if not r[0])))
        no_vtu = (None, "n/a (no .vtu)", 0)
        rows.append((f"clean {label} ({count} tets, {len(files)} files)", "passes, a second reader agreeing", halo_cell,
                     other_cell(*(run_cell_validator(vtu) if vtu else no_vtu), False),
                     other_cell(*(run_mesh_quality(vtu) if vtu else no_vtu), False),
                     meshio_cell, tetgen_cell))

    print("== planted faults")
    for case in fault_cases:
        path = fault_dir / f"{case.name}{case.suffix}"
        case.writer(path, case.points, case.tets)
        run = run_halo4d(binary, path)
        if case.writer is write_meshio:  # the file is the case's points and tetrahedra
            originals.append((case.name, case.points, case.tets, run, case.names))
        ok, cell = judge_halo4d(run, case)
        print(f"{path.name}: {cell}" + ("" if ok or not run["note"] else f" ({run['note']})"))
        if not ok:
            failed.append(f"{path.name}: {cell}")
        marks = check_marks(binary, path, case, fault_dir)
        if marks:
            print(f"{path.name}: --mark: {marks}")
            failed.append(f"{path.name}: --mark: {marks}")
        should_fail = bool(case.names)
        read, detail, t = run_meshio(path)
        meshio_cell = (f"missed (read, no checks) {ms(t)}" if should_fail else f"passed (read) {ms(t)}") if read \
            else f"could not read ({detail}) {ms(t)}"
        rows.append((f"{case.name}{case.suffix}: {case.what}", case.expect, cell,
                     other_cell(*run_cell_validator(path), should_fail), other_cell(*run_mesh_quality(path), should_fail),
                     meshio_cell, "not exposed"))

    print("== every mesh again: moved far away, scaled by powers of two, with an unused vertex at 1e308")
    more_rows, more_failed = transformed_runs(binary, out / "transformed", originals)
    rows += more_rows
    failed += more_failed
    mixed_rows, mixed_failed, mixed_files = mixed_corpus.corpus(binary, out, run_halo4d, judge_halo4d, ms)
    rows += mixed_rows
    failed += mixed_failed

    header = ("mesh", "halo4d must", "halo4d", "vtkCellValidator", "vtkMeshQuality", "meshio", "TetGen")
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(c.replace("|", "/") for c in row) + " |" for row in rows]
    table = "\n".join(lines) + "\n"
    files = sum(len(g[2]) for g in groups) + len(fault_cases) + len(TRANSFORMS) * len(originals) + mixed_files
    print(f"{files} files")
    note = (f"\n{files} files. halo4d: {binary}; Gmsh {gmsh.__version__}, TetGen (tetgen {tetgen.__version__}), "
            f"meshio {meshio.__version__}, VTK {vtk.vtkVersion.GetVTKVersion()}, PyVista {pyvista.__version__}. TetGen's check (-C) runs "
            "inside tetrahedralize() on the mesh it has just made; the wrapper takes tetrahedra in only as "
            "a background sizing mesh, never to check them: \"not exposed\".\n")
    print()
    print(table + note)
    if table_path:
        Path(table_path).parent.mkdir(parents=True, exist_ok=True)
        Path(table_path).write_text(table + note)
    print(f"{len(rows)} rows in {time.perf_counter() - start:.1f} s")
    if failed:
        print(f"FAILED halo4d check on {len(failed)} files:")
        for f in failed[:20]:
            print(f"  {f}")
        if len(failed) > 20:
            print(f"  and {len(failed) - 20} more above")
        return 1
    print("halo4d check passed every clean file and named every planted fault")
    return 0


def fixtures(folder):
    folder.mkdir(parents=True, exist_ok=True)
    with Gmsh() as session:
        fault_cases = cases(session)
    lines = [
        "# Tetrahedral meshes, clean and with planted faults",
        "",
        "Written by `.ci/tetmesh-corpus.py --fixtures fixtures/tetmeshes/faults` (Gmsh "
        f"{gmsh.__version__} and meshio {meshio.__version__} from the venv of `.ci/run`; one thread, fixed "
        "choices, so a rerun writes the same files). Legacy VTK 4.2 ASCII, tetrahedra only, "
        "every tetrahedron positively oriented unless said otherwise. What `halo4d check FILE "
        "--json` must say of each: exit status 0 for \"passes\", 1 for \"fails\" with each name "
        "listed among the `failures` (others may come with it).",
        "",
        "| file | tets | halo4d check | what it is |",
        "|---|---|---|---|",
    ]
    for case in fault_cases:
        if case.writer is not write_meshio:  # a file of pieces: made in CI only
            continue
        path = folder / f"{case.name}.vtk"
        with contextlib.redirect_stderr(io.StringIO()):  # meshio: ASCII VTK is "for debugging"
            meshio.vtk.write(path, tet_mesh(case.points, case.tets), fmt_version="4.2", binary=False)
        size = path.stat().st_size
        if size > 50_000:
            raise SystemExit(f"{path} is {size} bytes; fixtures stay under 50 KB")
        expect = case.expect
        if case.name == "cube-cavity":
            expect = "passes, `meshes[0].certificate.boundary.cavities == 1`"
        elif case.name == "sliver":
            expect = f"passes, `meshes[0].certificate.quality.worst[0].tet == {SLIVER_INDEX}`"
        elif case.names:
            expect = "fails: " + ", ".join(f"`{n}`" for n in case.names)
        lines.append(f"| {path.name} | {len(case.tets)} | {expect} | {case.what} |")
        print(f"{path}: {size} bytes, {len(case.tets)} tets, {case.expect}")
    (folder / "README.md").write_text("\n".join(lines) + "\n")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--halo4d", help="the halo4d binary")
    parser.add_argument("--out", type=Path, help="where the meshes are written")
    parser.add_argument("--table", type=Path, help="also write the Markdown table here")
    parser.add_argument("--fixtures", type=Path, help="write the fixture meshes and README.md here, and nothing else")
    args = parser.parse_args()
    if args.fixtures:
        return fixtures(args.fixtures)
    if not args.halo4d or not args.out:
        parser.error("--halo4d and --out are needed (or --fixtures)")
    return corpus(args.halo4d, args.out, args.table)


if __name__ == "__main__":
    sys.exit(main())
