"""A partitioned mesh certified as one: `halo4d check` on a .pvtu of many pieces against
the same mesh as one .vtu, and vtkCellValidator on both, in one run.

    python benches/pvtu/run.py --halo4d target/release/halo4d [--n 119] [--pieces 8]
        [--out DIR] [--validator]

The mesh is Kuhn's cube [0, n]^3 (6 n^3 tetrahedra: n = 119 gives 10.1M), written by
VTK's own writers (appended raw data, as VTK and ParaView write by default): once as one
.vtu, once as a .pvtu of `pieces` slabs along x, each piece with its own copy of the points
on its cuts. Each `halo4d check FILE --json` runs under /usr/bin/time -v (wall time and
peak memory as the operating system measures them) and must pass with 6 n^3 tetrahedra of
volume n^3; `--validator` also times vtkCellValidator (VTK's per-cell check) reading and
checking each file in this process. Needs numpy and vtk (the venv of .ci/run has both).
"""

import argparse
import json
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray, vtk_to_numpy

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / ".ci"))
import vtk_pieces  # noqa: E402 - the .pvtu writer .ci/tetmesh-corpus.py uses too

# Each path from corner 0 to corner 7 along the axes in one order, with its parity (as
# `halo4d::certify::kuhn_cube`).
ORDERS = (((0, 1, 2), False), ((0, 2, 1), True), ((1, 0, 2), True), ((1, 2, 0), False), ((2, 0, 1), False),
          ((2, 1, 0), True))


def kuhn(n, x0=0, x1=None):
    """Points and tetrahedra (VTK's positive orientation) of the cubes whose x is in
    [x0, x1) of Kuhn's cube [0, n]^3, numbered by their own points."""
    x1 = n if x1 is None else x1
    xs = np.arange(x0, x1 + 1)
    m = n + 1
    gx, gy, gz = np.meshgrid(xs, np.arange(m), np.arange(m), indexing="ij")
    points = np.column_stack([gx.ravel(), gy.ravel(), gz.ravel()]).astype(np.float64)
    ident = lambda x, y, z: ((x - x0) * m + y) * m + z  # noqa: E731
    cx, cy, cz = np.meshgrid(np.arange(x0, x1), np.arange(n), np.arange(n), indexing="ij")
    cx, cy, cz = cx.ravel(), cy.ravel(), cz.ravel()
    tets = []
    for order, odd in ORDERS:
        at = [cx.copy(), cy.copy(), cz.copy()]
        t = [ident(*at)]
        for axis in order:
            at[axis] = at[axis] + 1
            t.append(ident(*at))
        t = np.column_stack(t)
        # The path turns clockwise seen from the corner for even orders: negative in
        # VTK's orientation, so two vertices swap.
        if not odd:
            t[:, [0, 1]] = t[:, [1, 0]]
        tets.append(t)
    return points, np.vstack(tets)


def grid(points, tets):
    g = vtk.vtkUnstructuredGrid()
    p = vtk.vtkPoints()
    p.SetDataTypeToDouble()
    p.SetData(numpy_to_vtk(points, deep=True))
    g.SetPoints(p)
    cells = vtk.vtkCellArray()
    cells.SetData(numpy_to_vtkIdTypeArray(np.arange(0, 4 * len(tets) + 1, 4, dtype=np.int64), deep=True),
                  numpy_to_vtkIdTypeArray(tets.astype(np.int64).ravel(), deep=True))
    g.SetCells(vtk.VTK_TETRA, cells)
    return g


def write_vtu(path, n):
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetInputData(grid(*kuhn(n)))
    w.SetFileName(str(path))
    w.SetDataModeToAppended()
    w.EncodeAppendedDataOff()
    assert w.Write() == 1


def write_pvtu(path, n, pieces):
    cuts = np.linspace(0, n, pieces + 1).round().astype(int)
    vtk_pieces.write_pvtu(path, lambda k: grid(*kuhn(n, cuts[k], cuts[k + 1])), pieces, appended_raw=True)


def halo4d_check(binary, path):
    """(wall s, peak GB, report) of `halo4d check PATH --json` under /usr/bin/time -v."""
    proc = subprocess.run(["/usr/bin/time", "-v", binary, "check", str(path), "--json"], capture_output=True, text=True)
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", proc.stderr).group(1)
    seconds = sum(float(x) * 60**i for i, x in enumerate(reversed(wall.split(":"))))
    peak = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", proc.stderr).group(1)) / 1e6
    return seconds, peak, json.loads(proc.stdout)


def validator(path):
    t0 = time.perf_counter()
    reader = vtk.vtkXMLPUnstructuredGridReader() if path.suffix == ".pvtu" else vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    v = vtk.vtkCellValidator()
    v.SetInputConnection(reader.GetOutputPort())
    v.Update()
    state = vtk_to_numpy(v.GetOutput().GetCellData().GetArray("ValidityState"))
    return time.perf_counter() - t0, int(np.count_nonzero(state))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--halo4d", required=True)
    parser.add_argument("--n", type=int, default=119)
    parser.add_argument("--pieces", type=int, default=8)
    parser.add_argument("--out", type=Path)
    parser.add_argument("--validator", action="store_true")
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp())
    out.mkdir(parents=True, exist_ok=True)
    n = args.n
    files = [out / f"kuhn-{n}.vtu", out / f"kuhn-{n}-{args.pieces}.pvtu"]
    t0 = time.perf_counter()
    write_vtu(files[0], n)
    write_pvtu(files[1], n, args.pieces)
    print(f"wrote {6 * n**3} tetrahedra as {files[0].name} and {files[1].name} in {time.perf_counter() - t0:.1f} s")
    print("| file | halo4d check: wall, peak memory | verdict | vtkCellValidator |")
    print("| --- | --- | --- | --- |")
    failed = False
    for f in files:
        wall, peak, report = halo4d_check(args.halo4d, f)
        stats = report["meshes"][0]["stats"]
        good = report["passes"] and stats["tets"] == 6 * n**3 and abs(stats["volume"] - n**3) < 1e-9 * n**3
        failed |= not good
        cell = "n/a"
        if args.validator:
            t, flagged = validator(f)
            cell = f"{t:.1f} s, {flagged} cells flagged"
        print(f"| {f.name} | {wall:.2f} s, {peak:.2f} GB | {'passes' if good else 'FAILED ' + str(report['failures'])}, "
              f"{stats['tets']} tetrahedra, {stats['vertices']} vertices | {cell} |")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
