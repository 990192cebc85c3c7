"""Top-down category renders for the evaluation (the ThreedFront toolkit's convention): white background, no floor,
each object filled with its category's colour from a fixed HLS palette (one hue per category, lightness 0.6,
saturation 0.65), higher objects drawn over lower ones; a square window centred on the room's bounding box. A render
is kept as a label map (category index per pixel, -1 empty): colours for the classifier, labels for similarity."""
from __future__ import annotations

import colorsys
from collections.abc import Sequence

import numpy as np

from ..room import RoomInput
from ..geometry import boxes
from ..geometry.raster import fill_quads

EMPTY = -1


def palette(categories: Sequence[str]) -> np.ndarray:
    """``(c, 3)`` RGB in [0, 1]: hue ``k / c`` for the k-th of ``categories`` (pass them sorted: the palette is
    pinned by the category list)."""
    c = max(len(categories), 1)
    return np.array([colorsys.hls_to_rgb(k / c, 0.6, 0.65) for k in range(len(categories))], dtype=np.float32)


def label_map(room: RoomInput, index: dict[str, int], size: int, mpp: float) -> np.ndarray:
    """``(size, size)`` int16 category index of the top-most object per pixel (``EMPTY`` where none; categories
    missing from ``index`` are skipped)."""
    out = np.full((size, size), EMPTY, np.int16)
    centre = (room.outline.min(0) + room.outline.max(0)) / 2
    b = room.boxes
    for k in np.argsort(b[:, 2] + b[:, 5], kind="stable") if len(b) else []:
        if room.categories[k] in index:
            corners = boxes.footprint_corners(b[k, 0], b[k, 1], b[k, 3], b[k, 4], b[k, 6])
            fill_quads(out, corners, index[room.categories[k]], mpp, centre)
    return out


def to_rgb(labels: np.ndarray, colors: np.ndarray) -> np.ndarray:
    """``(..., size, size, 3)`` float32 image of label maps ``(..., size, size)``: white where empty."""
    rgb = np.ones(labels.shape + (3,), np.float32)
    hit = labels != EMPTY
    rgb[hit] = colors[labels[hit]]
    return rgb


def dihedral(labels: np.ndarray) -> np.ndarray:
    """``(8, size, size)``: the four quarter turns of a label map and of its mirror."""
    return np.stack([np.rot90(m, k) for m in (labels, labels[:, ::-1]) for k in range(4)])


def similarity(query: np.ndarray, pool: np.ndarray) -> np.ndarray:
    """``(N,)`` layout similarity of a label map ``(s, s)`` to each of ``pool (N, s, s)``: pixels where both show
    the same category over pixels where either shows one, the best over the query's 8 turns and mirrors (1: the
    same layout)."""
    if not len(pool):
        return np.zeros(0)
    best = np.zeros(len(pool))
    for q in dihedral(query):
        same = ((pool == q) & (q != EMPTY)).sum((1, 2))
        union = ((pool != EMPTY) | (q != EMPTY)).sum((1, 2))
        best = np.maximum(best, same / np.maximum(union, 1))
    return best
