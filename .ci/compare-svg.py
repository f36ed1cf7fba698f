"""The line art (.svg, rasterized by a real SVG program) against the picture (.png).

Usage: compare-svg.py SVG_RASTER.png PICTURE.png

Every pixel the SVG's lines cover fully (far from the background's colour) must find a
pixel of the same colour in the PNG within 2 pixels: the SVG's lines lie where the PNG's
are, in the PNG's inks. Fails when fewer than 95% do, or when the SVG has fewer than 1000
such pixels (lines that draw nothing prove nothing).
"""

import sys

import numpy as np
from PIL import Image

svg = np.asarray(Image.open(sys.argv[1]).convert("RGB"), dtype=np.int32)
png = np.asarray(Image.open(sys.argv[2]).convert("RGB"), dtype=np.int32)
if svg.shape != png.shape:
    sys.exit(f"the SVG rasterizes to {svg.shape[1]}x{svg.shape[0]}, the PNG is {png.shape[1]}x{png.shape[0]}")
background = svg[0, 0]
core = np.abs(svg - background).max(axis=2) > 120
ys, xs = np.nonzero(core)
if len(ys) < 1000:
    sys.exit(f"the SVG's lines cover only {len(ys)} pixels fully")
reach = 2
h, w, _ = png.shape
padded = np.pad(png, ((reach, reach), (reach, reach), (0, 0)), constant_values=-1000)
found = np.zeros(len(ys), dtype=bool)
for dy in range(-reach, reach + 1):
    for dx in range(-reach, reach + 1):
        near = padded[ys + reach + dy, xs + reach + dx]
        found |= np.abs(near - svg[ys, xs]).max(axis=1) <= 40
share = found.mean()
print(f"{found.sum()} of {len(ys)} fully covered SVG line pixels ({share:.1%}) have a PNG pixel of their colour within {reach} px")
if share < 0.95:
    bad = np.argmax(~found)
    sys.exit(f"the SVG's lines are not the PNG's: the first miss at ({xs[bad]}, {ys[bad]}), colour {svg[ys[bad], xs[bad]].tolist()}")
