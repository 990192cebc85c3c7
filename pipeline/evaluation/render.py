"""Top-down category renders for the evaluation (the ThreedFront toolkit's convention): white background, no floor,
each object filled with its category's colour from a fixed HLS palette (one hue per category, lightness 0.6,
saturation 0.65), higher objects drawn over lower ones; a square window centred on the room's bounding box. A render
is kept as a label map (category index per pixel, -1 empty) for the layout similarity. The classifier's renders add
the floor and each object's front, and fit each room to the window (:func:`classifier_map`, :func:`fitted_mpp`)."""
from __future__ import annotations

import colorsys
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..geometry import boxes
from ..geometry.raster import fill_polygon, fill_quads
from ..room import RoomInput

EMPTY = -1
FLOOR = -2


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


def classifier_map(room: RoomInput, index: dict[str, int], size: int, mpp: float, front: float) -> np.ndarray:
    """``(size, size)`` int16 render for the real-vs-synthetic classifier (a departure from the toolkit's renders,
    which show neither the floor nor which way an object faces): the floor ``FLOOR``, each object its category
    index ``k`` and the front ``front`` share of its footprint ``k + len(index)``, higher objects over lower ones."""
    centre = (room.outline.min(0) + room.outline.max(0)) / 2
    out = np.where(fill_polygon(room.outline, size, mpp, centre), FLOOR, EMPTY).astype(np.int16)
    b = room.boxes
    for k in np.argsort(b[:, 2] + b[:, 5], kind="stable") if len(b) else []:
        if room.categories[k] in index:
            cx, cy, hx, hy, yaw = b[k, 0], b[k, 1], b[k, 3], b[k, 4], b[k, 6]
            fill_quads(out, boxes.footprint_corners(cx, cy, hx, hy, yaw), index[room.categories[k]], mpp, centre)
            shift = (1.0 - front) * hy  # the front strip's centre, along the object's local +y
            fill_quads(out, boxes.footprint_corners(cx - shift * np.sin(yaw), cy + shift * np.cos(yaw), hx, front * hy,
                                                    yaw), index[room.categories[k]] + len(index), mpp, centre)
    return out


def classifier_rgb(labels: np.ndarray, colors: np.ndarray) -> np.ndarray:
    """``(..., size, size, 3)`` float32 image of :func:`classifier_map` renders: white outside the room, light grey
    floor, category colours, their fronts at half the lightness."""
    rgb = np.ones(labels.shape + (3,), np.float32)
    rgb[labels == FLOOR] = 0.85
    full = np.concatenate([colors, colors * 0.5]) if len(colors) else colors
    hit = labels >= 0
    rgb[hit] = full[labels[hit]]
    return rgb


def fitted_mpp(room: RoomInput, size: int, finest: float) -> float:
    """m per pixel that fits the room's larger extent (and a 5% margin) into ``size`` pixels, never below ``finest``."""
    return max(finest, float((room.outline.max(0) - room.outline.min(0)).max()) * 1.05 / size)


def classifier_images(rooms: Sequence[RoomInput], index: dict[str, int], colors: np.ndarray, cfg: dict[str, Any]) -> np.ndarray:
    """``(n, size, size, 3)`` classifier images of ``rooms``, each room fitted to the window (``cfg``: ``size``,
    ``finest_mpp``, ``front``)."""
    maps = [classifier_map(r, index, cfg["size"], fitted_mpp(r, cfg["size"], cfg["finest_mpp"]), cfg["front"])
            for r in rooms]
    labels = np.stack(maps) if maps else np.zeros((0, cfg["size"], cfg["size"]), np.int16)
    return classifier_rgb(labels, colors)


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
