"""Runs a notebook and checks what it shows:

    python examples/run_notebook.py [NOTEBOOK] [--out OUT.ipynb]

executes NOTEBOOK (examples/halo4d.ipynb by default) with nbclient in a kernel of this very
Python (so the notebook sees the packages of the venv running this), and exits 1 unless the
notebook came without outputs (they are not committed), every cell ran without an error,
and it showed at least one picture, each a PNG of some size that is not one flat colour.
`--out` writes the executed notebook. Needs nbclient, nbformat, ipykernel, matplotlib and
NumPy, besides what the notebook imports.
"""

import argparse
import base64
import io
import json
import os
import sys
import tempfile
import time

import matplotlib.image
import nbclient
import nbformat
import numpy as np
from jupyter_client import KernelManager

HERE = os.path.dirname(os.path.abspath(__file__))
MIN_PNG_BYTES = 4096
WHOAMI = "import sys; print(sys.executable)"


def kernel_of_this_python(folder):
    """A kernelspec `python3` in `folder` that runs this Python with matplotlib's inline
    backend (whatever MPLBACKEND says outside), first on JUPYTER_PATH so that no other
    `python3` kernel is taken for it."""
    spec = os.path.join(folder, "kernels", "python3")
    os.makedirs(spec)
    with open(os.path.join(spec, "kernel.json"), "w", encoding="utf-8") as f:
        json.dump(
            {
                "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
                "display_name": f"Python ({sys.executable})",
                "language": "python",
                "env": {"MPLBACKEND": "module://matplotlib_inline.backend_inline"},
            },
            f,
        )
    os.environ["JUPYTER_PATH"] = os.pathsep.join(filter(None, [folder, os.environ.get("JUPYTER_PATH")]))


def fail(message):
    print(f"run_notebook: FAILED: {message}", file=sys.stderr)
    sys.exit(1)


def picture(data, where):
    """Checks one image/png output; gives (bytes, width, height, colours)."""
    raw = base64.b64decode(data)
    if len(raw) < MIN_PNG_BYTES:
        fail(f"{where}: a PNG of {len(raw)} bytes, less than {MIN_PNG_BYTES}")
    pixels = matplotlib.image.imread(io.BytesIO(raw), format="png")
    if pixels.ndim != 3 or min(pixels.shape[:2]) < 32:
        fail(f"{where}: a PNG of shape {pixels.shape}")
    flat = pixels[..., :3].reshape(-1, 3)
    colours = len(np.unique((flat * 255).round().astype(np.uint8), axis=0))
    if np.ptp(flat, axis=0).max() < 0.1 or colours < 16:
        fail(f"{where}: the picture is (nearly) one colour ({colours} colours)")
    return len(raw), pixels.shape[1], pixels.shape[0], colours


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("notebook", nargs="?", default=os.path.join(HERE, "halo4d.ipynb"))
    parser.add_argument("--out", help="write the executed notebook here")
    parser.add_argument("--timeout", type=int, default=600, help="seconds a cell may take")
    args = parser.parse_args(argv)

    nb = nbformat.read(args.notebook, as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    kept = [i for i, c in enumerate(nb.cells) if c.cell_type == "code" and (c.outputs or c.execution_count)]
    if kept:
        fail(
            f"{args.notebook}: cells {kept} keep outputs; clear them before committing (the notebook is run here)"
        )

    # One cell more, dropped before writing: the kernel says which Python it is.
    nb.cells.append(nbformat.v4.new_code_cell(WHOAMI))
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="halo4d-kernel-") as folder:
        kernel_of_this_python(folder)
        # Over a local socket file, not TCP (ipykernel warns of unencrypted TCP).
        km = KernelManager(kernel_name="python3", transport="ipc", ip=os.path.join(folder, "kernel"))
        client = nbclient.NotebookClient(
            nb,
            kernel_name="python3",
            km=km,
            timeout=args.timeout,
            resources={"metadata": {"path": os.path.dirname(os.path.abspath(args.notebook))}},
        )
        try:
            client.execute()
        except nbclient.exceptions.CellExecutionError as e:
            fail(f"{args.notebook}: a cell failed:\n{e}")
        finally:
            if km.has_kernel:
                km.shutdown_kernel(now=True)
    seconds = time.perf_counter() - started
    whoami = nb.cells.pop()
    said = "".join(o.get("text", "") for o in whoami.outputs).strip()
    if os.path.realpath(said) != os.path.realpath(sys.executable):
        fail(f"the kernel ran {said!r}, not this Python {sys.executable}")

    pictures, errors = [], []
    for index, cell in enumerate(nb.cells):
        for output in cell.get("outputs", []):
            if output.output_type == "error":
                errors.append(f"cell {index}: {output.ename}: {output.evalue}")
            data = output.get("data", {})
            if "image/png" in data:
                pictures.append((index, picture(data["image/png"], f"cell {index}")))
    if errors:
        fail("; ".join(errors))
    if not pictures:
        fail(f"{args.notebook}: no cell showed a picture (image/png)")

    if args.out:
        nbformat.write(nb, args.out)
    print(f"run_notebook: ok: {args.notebook}, {len(code)} code cells ran in {seconds:.1f} s in {said}")
    for index, (size, width, height, colours) in pictures:
        print(f"  cell {index}: PNG {width} x {height}, {size} bytes, {colours} colours")
    if args.out:
        print(f"  executed notebook: {args.out}")


if __name__ == "__main__":
    main(sys.argv[1:])
