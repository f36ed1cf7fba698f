"""Zips the Blender add-on for Edit › Preferences › Get Extensions › Install from Disk.

    python blender/pack.py [OUT.zip] [--wheel halo4d-*.whl]

writes exports/halo4d_blender.zip by default: the files of blender/halo4d_blender/ at the
zip's top level, `blender_manifest.toml` among them, as Blender 4.2's extension format
wants (and `blender --command extension build` makes). `--wheel` bundles halo4d's wheel
into the zip (`wheels/`), naming it in the manifest's `wheels` with the platform it is
built for, so that Blender installs it with the extension; without it, halo4d must be
installed into Blender's Python (README.md). The zip is the same bytes for the same files.
"""

import argparse
import json
import os
import sys
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
ADDON = os.path.join(HERE, "halo4d_blender")
DEFAULT_OUT = os.path.join(os.path.dirname(HERE), "exports", "halo4d_blender.zip")


def platform_of(wheel):
    """The manifest's platform for a wheel file name (`...-manylinux_2_35_x86_64.whl`)."""
    tag = os.path.basename(wheel)[: -len(".whl")].rsplit("-", 1)[-1]
    for part in tag.split("."):
        if part.startswith("macosx"):
            return "macos-arm64" if part.endswith(("arm64", "universal2")) else "macos-x64"
        if part.startswith("win"):
            return "windows-arm64" if part.endswith("arm64") else "windows-x64"
        if "linux" in part:
            return "linux-arm64" if part.endswith("aarch64") else "linux-x64"
    if tag == "any":
        return None
    raise SystemExit(f"pack.py: {wheel}: cannot tell the platform of the wheel tag `{tag}`")


def files():
    """The add-on's files, (path on disk, name in the zip), sorted, without caches."""
    found = []
    for folder, dirs, names in os.walk(ADDON):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in names:
            if name.endswith((".pyc", ".pyo")):
                continue
            path = os.path.join(folder, name)
            found.append((path, os.path.relpath(path, ADDON).replace(os.sep, "/")))
    return sorted(found, key=lambda f: f[1])


def manifest_with_wheels(text, wheels):
    """The manifest with `wheels` and `platforms` set, before its first table."""
    platforms = sorted({p for p in map(platform_of, wheels) if p})
    lines = [f"wheels = {json.dumps(['./wheels/' + os.path.basename(w) for w in wheels])}"]
    if platforms:
        lines.append(f"platforms = {json.dumps(platforms)}")
    out, placed = [], False
    for line in text.splitlines():
        if not placed and line.startswith("["):
            out += lines + [""]
            placed = True
        out.append(line)
    if not placed:
        out += lines
    return "\n".join(out) + "\n"


def pack(out, wheels=()):
    """Writes the zip to `out`; gives the names in it."""
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    names = []

    def add(archive, name, data):
        info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
        info.compress_type = zipfile.ZIP_DEFLATED
        info.external_attr = 0o644 << 16
        archive.writestr(info, data)
        names.append(name)

    temporary = out + ".part"
    with zipfile.ZipFile(temporary, "w") as archive:
        for path, name in files():
            with open(path, "rb") as f:
                data = f.read()
            if name == "blender_manifest.toml" and wheels:
                data = manifest_with_wheels(data.decode("utf-8"), wheels).encode("utf-8")
            add(archive, name, data)
        for wheel in wheels:
            with open(wheel, "rb") as f:
                add(archive, "wheels/" + os.path.basename(wheel), f.read())
    os.replace(temporary, out)
    return names


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default=DEFAULT_OUT, help="the zip to write")
    parser.add_argument("--wheel", action="append", default=[], help="a wheel to bundle (repeatable)")
    args = parser.parse_args(argv)
    for wheel in args.wheel:
        if not (wheel.endswith(".whl") and os.path.isfile(wheel)):
            parser.error(f"--wheel {wheel}: not a .whl file")
    names = pack(args.out, args.wheel)
    print(f"{args.out}: {len(names)} files ({', '.join(names)})")


if __name__ == "__main__":
    main(sys.argv[1:])
