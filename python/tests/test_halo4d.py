"""The Python package against the command line: the same scene built by `halo4d build` and
by `halo4d.Scene(...).build()` gives the same numbers, bit for bit where the files keep
f64 (the 4OFF's 4D vertices, the VTK's halo points, t and d_orig) and to f32 where they
keep f32 (the PLY); errors name their field; threads and Ctrl-C behave.

Run with the package installed (`pip install ./python`) and the release binary built
(`cargo build --release`; HALO4D_BIN names another): `python -m pytest python/tests`.
"""

import json
import os
import subprocess
import sys
import threading
from pathlib import Path

import meshio
import numpy as np
import pytest

import halo4d

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("HALO4D_BIN", ROOT / "target" / "release" / "halo4d"))
DEFAULT = ROOT / "fixtures" / "scenes" / "default.json"
FLAT_TORUS = ROOT / "fixtures" / "scenes" / "flat-torus.json"


def scene_dict(path=DEFAULT, **outputs):
    """A fixture scene as a dict, with every mesh output on (and `outputs` over them)."""
    d = json.loads(Path(path).read_text())
    d["outputs"] = {"glb": True, "ply": True, "obj": False, "vtk": True, "off4": True,
                    "report": True, "svg": False, "png": False, **outputs}
    return d


@pytest.fixture(scope="module")
def cli_build(tmp_path_factory):
    """The default scene with every mesh output, built by the command line and in Python."""
    assert BIN.is_file(), f"{BIN} is missing: run `cargo build --release` first"
    folder = tmp_path_factory.mktemp("cli")
    scene_file = folder / "scene.json"
    scene_file.write_text(json.dumps(scene_dict()))
    out = folder / "out"
    subprocess.run([str(BIN), "build", str(scene_file), "--out", str(out), "--quiet"],
                   check=True)
    built = halo4d.Scene(scene_file).build()
    return out, built


def untimed(value):
    """`value` without the times it holds (keys `ms` and `*_ms`), which differ run to run."""
    if isinstance(value, dict):
        return {k: untimed(v) for k, v in value.items() if k != "ms" and not k.endswith("_ms")}
    if isinstance(value, list):
        return [untimed(v) for v in value]
    return value


def read_4off(path):
    lines = [l for l in Path(path).read_text().splitlines() if l and not l.startswith("#")]
    assert lines[0] == "4OFF"
    n, m, _ = map(int, lines[1].split())
    vertices = np.array([[float(x) for x in l.split()] for l in lines[2:2 + n]])
    faces = np.array([[int(x) for x in l.split()[1:]] for l in lines[2 + n:2 + n + m]])
    return vertices, faces


def test_the_arrays_are_the_files_of_halo4d_build(cli_build):
    out, built = cli_build
    assert built.verified, built.failures
    (surface,) = built.surfaces
    name = built.scene.name
    # The 4D mesh: the 4OFF keeps f64 (shortest round-trip digits), so bit for bit.
    v4, faces = read_4off(out / f"{name}.4off")
    assert surface.vertices4d.dtype == np.float64 and surface.vertices4d.shape == v4.shape
    assert np.array_equal(surface.vertices4d, v4)
    assert np.array_equal(surface.triangles, faces)
    # The projected surface: the PLY keeps f32, and the positions are rounded to f32.
    ply = meshio.read(out / f"{name}.ply")
    assert np.array_equal(surface.positions, ply.points.astype(np.float64))
    assert np.array_equal(surface.positions.astype(np.float32).astype(np.float64),
                          surface.positions)
    assert np.array_equal(surface.triangles, ply.cells_dict["triangle"])
    assert np.array_equal(surface.w.astype(np.float32), ply.point_data["quality"])
    # The halo: the VTK keeps f64.
    halo = surface.halo
    vtk = meshio.read(out / f"{name}-halo.vtk")
    assert np.array_equal(halo.vertices, vtk.points)
    assert np.array_equal(halo.tetrahedra, vtk.cells_dict["tetra"])
    # In the files' orientation: every tetrahedron positive by VTK's rule.
    a, b, c, d = (halo.vertices[halo.tetrahedra[:, k]] for k in range(4))
    assert (np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) > 0).all()
    assert np.array_equal(halo.t, vtk.point_data["t"].ravel())
    assert np.array_equal(halo.d_orig, vtk.point_data["d_orig"].ravel())
    assert halo.surface_vertices == len(surface.vertices4d)
    # The curves: as many, and as many points, as the report says.
    report = json.loads((out / "report.json").read_text())
    assert len(built.curves) == report["curves"]["count"] > 0
    assert sum(len(c) for c in built.curves) == report["curves"]["points"]
    for c in built.curves:
        assert c.points.shape == (len(c), 3) and c.w.shape == (len(c), 2)
        assert set(np.unique(c.over)) <= {0, 1}
        assert np.array_equal(c.over, (c.w[:, 1] < c.w[:, 0]).astype(np.uint8))
    # The report: the file's, but for what writing adds (the files) and the times.
    mine = built.report
    for key in ["surfaces", "curves", "halo_verification", "verified"]:
        assert untimed(mine[key]) == untimed(report[key]), key
    assert mine["verified"] is True


def test_write_gives_the_files_and_the_report_of_halo4d_build(cli_build, tmp_path):
    out, built = cli_build
    report = built.write(tmp_path)
    assert report["verified"] is True
    # The proven bound beside the audited one: never below it.
    sampling = report["surfaces"][0]["sampling"]
    assert sampling["max_error"] <= sampling["proven_max_error"], sampling
    assert sampling["unproven_triangles"] == 0, sampling
    for f in report["files"]:
        assert (tmp_path / f).is_file(), f
    # The same bytes as the command line's, but for the timings the report holds.
    name = built.scene.name
    for f in [f"{name}.4off", f"{name}-halo.vtk", f"{name}.ply"]:
        assert (tmp_path / f).read_bytes() == (out / f).read_bytes(), f
    checked = halo4d.check(tmp_path)
    assert checked["verified"], checked["failures"]
    assert checked["halos"][0]["tets"] == len(built.surfaces[0].halo.tetrahedra)
    assert checked["verification"]["wrong"] == 0 < checked["verification"]["correct"]
    assert checked["curves"]["count"] == len(built.curves)
    assert checked["text"].startswith(f"scene {name}:")
    # A planted fault: the halo as meshio writes it, one tetrahedron turned inside out.
    halo = built.surfaces[0].halo
    tets = halo.tetrahedra.copy()
    tets[7, [2, 3]] = tets[7, [3, 2]]
    flipped = tmp_path / "flipped.vtk"
    meshio.write(flipped, meshio.Mesh(halo.vertices, [("tetra", tets.astype(np.int64))]))
    checked = halo4d.check(flipped)
    assert not checked["verified"]
    assert checked["halos"][0]["inverted"] == 1, checked["halos"]
    assert any("inverted" in f for f in checked["failures"]), checked["failures"]


def test_any_tetrahedral_mesh_is_certified_with_its_faults_per_tetrahedron():
    faults = ROOT / "fixtures" / "tetmeshes" / "faults"
    clean = halo4d.check(faults / "cube.vtk")
    assert clean["verified"] and clean["format"] == "legacy VTK ASCII", clean["failures"]
    assert clean["certificate"]["boundary"]["windings"] == [1]
    assert not any(clean["certificate"]["faults"])
    nested = halo4d.check(faults / "nested-balls.vtk")
    assert not nested["verified"]
    assert nested["certificate"]["boundary"]["windings"] == [1, 2]
    assert any(f.split()[1] == "wrong_winding" for f in nested["failures"]), nested["failures"]
    marked = np.asarray(nested["certificate"]["faults"])
    assert len(marked) == nested["halos"][0]["tets"] and np.count_nonzero(marked & 1024) > 0


def test_the_picture_is_the_command_lines(cli_build, tmp_path):
    _, built = cli_build
    small = built.render(160, 120, samples=1)
    assert small.shape == (120, 160, 3) and small.dtype == np.uint8
    assert len(np.unique(small.reshape(-1, 3), axis=0)) > 50, "the picture shows something"
    # The halos' gap is set in pixels of the scene's own picture: built for that size, the
    # picture is `halo4d render`'s, pixel for pixel.
    scene = scene_dict(png=True)
    scene["render"] = {**scene.get("render", {}), "width": 160, "height": 120, "samples": 1}
    picture = halo4d.Scene(scene).build().render()
    scene_file = tmp_path / "scene.json"
    scene_file.write_text(json.dumps(scene))
    png = tmp_path / "picture.png"
    subprocess.run([str(BIN), "render", str(scene_file), "--out", str(png)], check=True,
                   capture_output=True)
    from PIL import Image
    assert np.array_equal(np.asarray(Image.open(png).convert("RGB")), picture)
    with pytest.raises(ValueError, match="style"):
        built.render(style="pointillist")
    with pytest.raises(ValueError, match="width"):
        built.render(width=0)


def test_a_scene_from_a_dict_json_or_file_is_the_same_scene():
    d = json.loads(DEFAULT.read_text())
    a = halo4d.Scene(d)
    b = halo4d.Scene(json.dumps(d))
    c = halo4d.Scene(DEFAULT)
    d_ = halo4d.Scene(str(DEFAULT))
    assert a.to_dict() == b.to_dict() == c.to_dict() == d_.to_dict()
    assert halo4d.Scene().name == c.name == "spun-trefoil"
    assert halo4d.Scene(a.to_json()).to_dict() == a.to_dict()


@pytest.mark.parametrize(
    "edit, field",
    [
        (lambda d: d["surfaces"][0]["surface"].update(n=3), "surfaces[0].surface.n"),
        (lambda d: d.update(halo={"rho": -1.0}), "halo.rho"),
        (lambda d: d["view"]["rotation"].update(xw="ten"), "view.rotation.xw"),
        (lambda d: d.update(name=""), "name"),
    ],
)
def test_a_bad_scene_raises_scene_error_naming_its_field(edit, field):
    d = json.loads(DEFAULT.read_text())
    d.setdefault("halo", {})
    edit(d)
    with pytest.raises(halo4d.SceneError) as caught:
        halo4d.Scene(d)
    assert caught.value.field == field, str(caught.value)
    assert field in str(caught.value)
    assert isinstance(caught.value, ValueError)


def test_a_scene_of_a_mesh_file_reads_back_from_anywhere(tmp_path, monkeypatch):
    # The mesh's path is relative to the scene file; the dict and JSON give it absolute, so
    # that they read back from another folder, and a view of it builds.
    scene = halo4d.Scene(ROOT / "fixtures" / "scenes" / "mesh-clifford-torus.json")
    monkeypatch.chdir(tmp_path)
    again = halo4d.Scene(scene.to_dict())
    assert Path(again.to_dict()["surfaces"][0]["surface"]["path"]).is_absolute()
    view = scene.to_dict()["view"]
    view["rotation"]["xw"] += 10.0
    a, b = scene.sample().build(view=view), again.build(view=view)
    assert np.array_equal(a.surfaces[0].positions, b.surfaces[0].positions)
    assert a.verified and b.verified


def test_unreadable_and_foreign_sources_are_refused(tmp_path):
    with pytest.raises(halo4d.SceneError) as caught:
        halo4d.Scene(tmp_path / "missing.json")
    assert caught.value.field is None and "cannot read" in str(caught.value)
    with pytest.raises(halo4d.SceneError, match="dict, a JSON string or the path"):
        halo4d.Scene(42)
    with pytest.raises(halo4d.SceneError) as caught:
        halo4d.Scene("{not json")
    assert caught.value.file == "<json>" and caught.value.field == "(top level)", str(caught.value)
    with pytest.raises(halo4d.SceneError) as caught:
        halo4d.Scene(42)
    assert caught.value.field is None and caught.value.file == "<argument>"
    with pytest.raises(halo4d.SceneError) as caught:
        halo4d.Scene().build(view={"rotation": {"xw": float("nan")}})
    assert caught.value.field.startswith("view")
    with pytest.raises(OSError, match="missing.glb"):
        halo4d.check(tmp_path / "missing.glb")


def test_sampling_once_builds_every_view_as_a_whole_build_of_that_view():
    scene = halo4d.Scene(DEFAULT)
    sampled = scene.sample()
    assert sampled.triangles == len(scene.build().surfaces[0].triangles)
    view = scene.to_dict()["view"]
    for xw in [10.0, 35.0]:
        turned = {**view, "rotation": {**view["rotation"], "xw": xw}}
        once = sampled.build(view=turned)
        d = scene.to_dict()
        d["view"] = turned
        whole = halo4d.Scene(d).build()
        assert once.scene.to_dict()["view"]["rotation"]["xw"] == xw
        a, b = once.surfaces[0], whole.surfaces[0]
        assert np.array_equal(a.vertices4d, b.vertices4d)
        assert np.array_equal(a.positions, b.positions)
        assert np.array_equal(a.halo.vertices, b.halo.vertices)
        assert [len(c) for c in once.curves] == [len(c) for c in whole.curves]
        assert once.verified == whole.verified


def test_one_sampling_builds_another_halo_without_sampling_again():
    d = json.loads(DEFAULT.read_text())
    sampled = halo4d.Scene(d).sample()
    d["halo"] = {"rho": 0.02, "delta_d": 0.5, "delta_t": 0.3}
    wider = halo4d.Scene(d)
    once = sampled.build(scene=wider)
    whole = wider.build()
    assert once.scene.to_dict()["halo"]["rho"] == 0.02
    assert np.array_equal(once.surfaces[0].halo.vertices, whole.surfaces[0].halo.vertices)
    assert not np.array_equal(
        once.surfaces[0].halo.vertices, sampled.build().surfaces[0].halo.vertices
    )
    # With a view too; and a scene of other surfaces is refused.
    view = wider.to_dict()["view"]
    view["rotation"]["xw"] += 5.0
    assert sampled.build(view=view, scene=wider).scene.to_dict()["halo"]["rho"] == 0.02
    d["surfaces"][0]["surface"]["scale"] = 0.5
    with pytest.raises(ValueError, match="other surfaces or sampling"):
        sampled.build(scene=halo4d.Scene(d))


def test_two_threads_build_at_once_and_get_what_one_gets():
    alone = halo4d.Scene(DEFAULT).build()
    results = [None, None]
    errors = []

    def work(i):
        try:
            results[i] = halo4d.Scene(DEFAULT).build()
        except Exception as e:  # reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    for r in results:
        assert r.verified
        assert np.array_equal(r.surfaces[0].positions, alone.surfaces[0].positions)
        assert np.array_equal(r.surfaces[0].halo.tetrahedra, alone.surfaces[0].halo.tetrahedra)
        assert [c.points.tolist() for c in r.curves] == [c.points.tolist() for c in alone.curves]


def test_the_catalogue_lists_every_surface_with_its_topology():
    entries = halo4d.catalogue()
    types = {e["type"] for e in entries}
    assert {"spun_trefoil", "flat_torus", "klein_bottle"} <= types
    by_type = {e["type"]: e for e in entries}
    assert by_type["flat_torus"]["euler_characteristic"] == 0
    assert by_type["klein_bottle"]["orientable"] is False
    for e in entries:
        # Every entry builds as a scene of its own type.
        assert halo4d.Scene({"name": "x", "surfaces": [{"surface": {"type": e["type"]}}]})


def test_ctrl_c_stops_a_long_build_and_frees_its_memory():
    # A build of 3M triangles, far longer than the wait (python/bench/interrupt.py): SIGINT
    # after it started must raise KeyboardInterrupt in the calling thread within a fraction
    # of a second, with the work stopped (the process's CPU time no longer grows) and its
    # memory given back.
    sys.path.insert(0, str(ROOT / "python" / "bench"))
    from interrupt import interrupt

    r = interrupt(4.0)
    assert not r["finished"], r
    # Raised once the work was cancelled and joined: a fraction of a second after the signal
    # (the build had tens of seconds to go; the bound leaves room for a loaded machine).
    assert r["after_signal"] < 2.0, r
    # Nothing runs on after: a few hundredths of a CPU second in the next second at most.
    assert r["cpu_next_second"] < 0.2, r
    # The build's memory is freed: the process holds less than 200 MB more than before it.
    assert r["rss_after"] < r["rss_before"] + 200, r


def test_a_build_reports_its_progress_and_prints_nothing(capfd):
    # The events of a build, in order, to the function given; a tqdm bar draws them. A
    # budget too small for the tolerance: its warning is an event, never a line on stderr.
    import io

    short = json.loads(FLAT_TORUS.read_text())
    short["sampling"] = {"method": "adaptive", "tolerance": 1e-6, "max_triangles": 2000}
    capfd.readouterr()
    halo4d.Scene(short).build()
    assert capfd.readouterr().err == ""
    events = []
    halo4d.Scene(short).build(progress=events.append)
    assert any(e["kind"] == "warning" and "max_triangles = 2000" in e["text"] for e in events)
    assert capfd.readouterr().err == ""
    events = []
    scene = halo4d.Scene(FLAT_TORUS)
    scene.build(progress=events.append)
    kinds = [e["kind"] for e in events]
    assert kinds[0] == "begin" and events[0]["task"] == "sampling", events[:3]
    assert kinds.count("begin") == kinds.count("end") == 2, kinds
    assert [e["task"] for e in events if e["kind"] == "begin"] == ["sampling", "view"]
    assert any(e["kind"] == "doing" and e["text"].startswith("halo of") for e in events)
    # Each task's steps go up one at a time, to the number it began with.
    for task in "sampling", "view":
        start = next(i for i, e in enumerate(events) if e.get("task") == task)
        end = next(i for i, e in enumerate(events) if i > start and e["kind"] == "end")
        done = [e["done"] for e in events[start:end] if e["kind"] == "done"]
        assert done == list(range(1, len(done) + 1)), (task, done)
        assert len(done) == events[start]["steps"], (task, done)
    out = io.StringIO()
    built = scene.build(progress=halo4d.tqdm_progress(file=out))
    assert built.verified
    assert "sampling" in out.getvalue() and "view" in out.getvalue(), out.getvalue()


def test_a_progress_function_that_raises_stops_the_build():
    calls = []

    def stop(event):
        calls.append(event)
        if event["kind"] == "doing":
            raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        halo4d.Scene(FLAT_TORUS).build(progress=stop)
    # Nothing was heard after the exception: the work was cancelled and joined.
    assert calls[-1]["kind"] == "doing", calls


def test_the_type_stubs_name_what_the_module_has():
    # Every public class, method, property and function of the native module has its stub
    # in `_native.pyi`, and every stub names something the module has.
    import ast
    import halo4d._native as native

    tree = ast.parse((Path(halo4d.__file__).parent / "_native.pyi").read_text())
    stubbed = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            stubbed[node.name] = {
                n.target.id if isinstance(n, ast.AnnAssign) else n.name
                for n in node.body
                if isinstance(n, (ast.FunctionDef, ast.AnnAssign))
            }
        elif isinstance(node, ast.FunctionDef):
            stubbed[node.name] = None
    public = {n for n in dir(native) if not n.startswith("_")}
    assert set(stubbed) == public, (set(stubbed) ^ public)
    for name, members in stubbed.items():
        if members is None:
            continue
        cls = getattr(native, name)
        own = {m for m in vars(cls) if not m.startswith("_")} | (
            {"__init__"} if name == "Scene" else set()
        ) | ({"__len__"} if "__len__" in vars(cls) else set())
        if issubclass(cls, Exception):
            own |= {"field", "file"} if name == "SceneError" else set()
        assert members == own, (name, members ^ own)


def test_a_mesh_in_memory_is_certified_without_a_file_with_its_faults_per_cell():
    import pyvista

    faults = ROOT / "fixtures" / "tetmeshes" / "faults"
    # The same mesh from a file, as a PyVista grid, as a meshio mesh and as arrays: the
    # same certificate.
    by_file = halo4d.check(faults / "nested-balls.vtk")
    grid = pyvista.read(faults / "nested-balls.vtk")
    mesh = meshio.read(faults / "nested-balls.vtk")
    tets = mesh.cells_dict["tetra"]
    for source in (grid, mesh, (mesh.points, tets)):
        got = halo4d.check(source)
        assert got["failures"] == by_file["failures"], type(source)
        assert got["certificate"]["boundary"] == by_file["certificate"]["boundary"]
        assert np.array_equal(got["certificate"]["faults"], by_file["certificate"]["faults"])
        assert got["cell_faults"].dtype == np.uint32
    # The bits per cell, to show in PyVista: every cell of the inner ball's boundary marked
    # wrong winding (1024), none of the outer's interior.
    result = halo4d.check(grid)
    grid.cell_data["fault"] = result["cell_faults"]
    assert grid.cell_data["fault"].shape == (grid.n_cells,)
    assert np.count_nonzero(result["cell_faults"] & 1024) > 0
    # A triangle among the cells is skipped (fault 0), the tetrahedra keep theirs.
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    mixed = meshio.Mesh(points, [("triangle", np.array([[0, 1, 2]])), ("tetra", np.array([[0, 1, 2, 3]]))])
    got = halo4d.check(mixed)
    assert got["verified"] and list(got["cell_faults"]) == [0, 0], got["failures"]
    flipped = halo4d.check((points, np.array([[0, 2, 1, 3], [0, 1, 2, 3]])))
    assert not flipped["verified"]
    # Bad input is a clear error, not a crash.
    with pytest.raises(ValueError, match="names point 9"):
        halo4d.check((points, np.array([[0, 1, 2, 9]])))
    prism = pyvista.UnstructuredGrid({16: np.arange(12)[None, :]}, np.random.default_rng(1).random((12, 3)))
    with pytest.raises(ValueError, match="1 hexagonal prism"):
        halo4d.check(prism)
    with pytest.raises(TypeError, match="PyVista UnstructuredGrid"):
        halo4d.check(42)


def test_a_mixed_mesh_in_memory_gets_the_files_certificate_and_each_cells_faults():
    import pyvista

    here = ROOT / "fixtures" / "tetmeshes"
    for name, failures in [("mixed-vtk9.vtu", []), ("mixed-split-hex.vtu", ["nonconforming_quads"]),
                           ("mixed-inverted-wedge.vtu", ["inverted"])]:
        by_file = halo4d.check(here / name)
        grid = pyvista.read(here / name)
        # meshio keeps wedges in Gmsh's corner order and turns them at the file: the same mesh.
        mesh = meshio.read(here / name)
        for source in (grid, mesh):
            got = halo4d.check(source)
            assert [f.split()[1] for f in got["failures"]] == failures, (name, type(source), got["failures"])
            assert got["certificate"]["cells"] == by_file["certificate"]["cells"], (name, type(source))
            assert sorted(got["cell_faults"]) == sorted(by_file["certificate"]["faults"]), (name, type(source))
        # Each cell's bits where the grid has it: the faulty cells are the named kind.
        faulty = np.flatnonzero(halo4d.check(grid)["cell_faults"])
        kinds = {"mixed-vtk9.vtu": set(), "mixed-split-hex.vtu": {12}, "mixed-inverted-wedge.vtu": {13}}[name]
        assert set(grid.celltypes[faulty]) == kinds, name
