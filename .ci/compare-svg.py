"""The line art (.svg, rasterized by a real SVG program) against the picture (.png).

Usage: compare-svg.py LINES.svg SVG_RASTER.png PICTURE.png

The pixels of the raster that a line of the SVG covers fully (within 30 of one of the
SVG's stroke colours in every channel) must each find a pixel of the same colour in the PNG
within 2 pixels: the SVG's lines lie where the PNG's are, in the PNG's inks. Fails when
fewer than 95% do, or when fewer than 1000 pixels are covered fully (lines that draw
nothing prove nothing). Thin lines whose raster never reaches their stroke's colour (the
broken edges, half the lines' width) are left out by that rule.
"""

import re
import sys

import numpy as np
from PIL import Image

svg_text = open(sys.argv[1], encoding="utf-8").read()
inks = {tuple(map(int, m)) for m in re.findall(r'stroke="rgb\((\d+),(\d+),(\d+)\)"', svg_text)}
if not inks:
    sys.exit(f"{sys.argv[1]} strokes no path")
svg = np.asarray(Image.open(sys.argv[2]).convert("RGB"), dtype=np.int32)
png = np.asarray(Image.open(sys.argv[3]).convert("RGB"), dtype=np.int32)
if svg.shape != png.shape:
    sys.exit(f"the SVG rasterizes to {svg.shape[1]}x{svg.shape[0]}, the PNG is {png.shape[1]}x{png.shape[0]}")
core = np.zeros(svg.shape[:2], dtype=bool)
for ink in inks:
    core |= np.abs(svg - np.array(ink)).max(axis=2) <= 30
ys, xs = np.nonzero(core)
if len(ys) < 1000:
    sys.exit(f"the SVG's lines cover only {len(ys)} pixels fully")
reach = 2
padded = np.pad(png, ((reach, reach), (reach, reach), (0, 0)), constant_values=-1000)
found = np.zeros(len(ys), dtype=bool)
for dy in range(-reach, reach + 1):
    for dx in range(-reach, reach + 1):
        near = padded[ys + reach + dy, xs + reach + dx]
        found |= np.abs(near - svg[ys, xs]).max(axis=1) <= 40
share = found.mean()
print(f"{found.sum()} of {len(ys)} fully covered SVG line pixels ({share:.1%}), in {len(inks)} inks, have a PNG pixel of their colour within {reach} px")
if share < 0.95:
    bad = np.argmax(~found)
    sys.exit(f"the SVG's lines are not the PNG's: the first miss at ({xs[bad]}, {ys[bad]}), colour {svg[ys[bad], xs[bad]].tolist()}")
