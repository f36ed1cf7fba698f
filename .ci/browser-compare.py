"""A browser's screenshot of halo4d's viewer page against halo4d's own picture of the scene,
the same size (.ci/run's browser step).

  browser-compare.py SHOT.png PICTURE.png OUT_DIR

Checked: the screenshot is not blank (at least MIN_COVERED of its pixels differ from the
picture's background); the curves show (at least MIN_INK pixels in the curves' ink, every
channel at most INK_LEVEL of 255: the tubes are near black, and no surface colour of the
picture's colour maps is that dark in all three channels); and its silhouette matches the
picture's, intersection over union at least MIN_IOU (a pixel covered where it differs from
the background, the corner pixel, by more than BACKGROUND_STEP in a channel, in either
image). Writes OUT_DIR/browser-side-by-side.png (the picture, the screenshot, where they
differ: grey both, red the picture only, blue the screenshot only) and
OUT_DIR/browser-result.json. Exit status 0 when all pass, 1 otherwise.
"""

import json
import sys
from pathlib import Path

import numpy as np
from PIL import Image

from silhouette import MIN_IOU, compare, covered

MIN_COVERED = 0.05
MIN_INK = 200
INK_LEVEL = 40


def main():
    if len(sys.argv) != 4:
        print(__doc__)
        sys.exit(2)
    shot_path, picture_path, out = Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3])
    shot = np.asarray(Image.open(shot_path).convert("RGB"))
    picture = np.asarray(Image.open(picture_path).convert("RGB"))
    if shot.shape != picture.shape:
        sys.exit(f"the screenshot is {shot.shape[1]}x{shot.shape[0]}, the picture {picture.shape[1]}x{picture.shape[0]}")
    a, b = covered(picture), covered(shot)
    iou, picture_only, shot_only = compare(picture, a, shot, b, out / "browser-side-by-side.png")
    share = b.mean()
    ink = int((shot <= INK_LEVEL).all(axis=2).sum())
    record = {
        "shot": str(shot_path),
        "picture": str(picture_path),
        "iou": float(iou),
        "covered_share": float(share),
        "ink_pixels": ink,
        "picture_only": picture_only,
        "shot_only": shot_only,
        "min_iou": MIN_IOU,
    }
    (out / "browser-result.json").write_text(json.dumps(record, indent=2) + "\n")
    print(
        f"browser screenshot {shot_path}: {share:.1%} of it covered, {ink} pixels in the curves' ink, "
        f"silhouette IoU {iou:.4f} against halo4d's picture ({record['picture_only']} pixels only in the picture, "
        f"{record['shot_only']} only in the screenshot); {out / 'browser-side-by-side.png'}"
    )
    problems = []
    if share < MIN_COVERED:
        problems.append(f"the screenshot is blank ({share:.2%} covered)")
    if ink < MIN_INK:
        problems.append(f"only {ink} pixels in the curves' ink")
    if iou < MIN_IOU:
        problems.append(f"silhouette IoU {iou:.4f} < {MIN_IOU}")
    for p in problems:
        print(f"FAILED {p}")
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
