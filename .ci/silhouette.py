"""Silhouettes compared: the pixels of a picture that differ from its background, and their
intersection over union with another picture's, with a side-by-side of the two and their
difference. Shared by .ci/blender-import.py and .ci/browser-compare.py."""

import numpy as np
from PIL import Image

# The smallest intersection over union the checks accept.
MIN_IOU = 0.95
# How far (of 255, in any channel) a pixel must be from the background to count as covered:
# the anti-aliased edge counts from about a tenth of its coverage on the lightest surface
# colours.
BACKGROUND_STEP = 8


def covered(image):
    """The pixels of `image` (RGB) more than BACKGROUND_STEP from its corner pixel, the
    background the fitted camera's margin leaves there."""
    background = image[0, 0].astype(int)
    return (np.abs(image.astype(int) - background) > BACKGROUND_STEP).any(axis=2)


def compare(picture, a, other, b, side_by_side):
    """IoU of the covered pixels `a` (of `picture`) and `b` (of `other`), and the counts only
    in each; writes `picture`, `other` and their difference (grey both, red only in the
    picture, blue only in the other) side by side to `side_by_side`."""
    iou = float((a & b).sum() / max((a | b).sum(), 1))
    diff = np.full(picture.shape, 255, np.uint8)
    diff[a & b] = (150, 150, 150)
    diff[a & ~b] = (220, 30, 30)
    diff[b & ~a] = (30, 60, 220)
    Image.fromarray(np.concatenate([picture, other, diff], axis=1)).save(side_by_side)
    return iou, int((a & ~b).sum()), int((b & ~a).sum())
