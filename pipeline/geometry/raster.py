"""Top-down rasters of a room, vectorised NumPy (no OpenGL): the images PlanIT's placement networks read.

A *view* is a square window of ``size`` pixels at ``mpp`` metres per pixel, centred on a point of the floor plan;
pixel ``(row, col)`` covers the plan square whose centre is ``centre + ((col + 0.5) - size / 2, size / 2 -
(row + 0.5)) * mpp`` (rows run towards -y, as in an image). A room larger than the window is cropped to it: the
caller centres the window where it needs to look (an anchor, or the room's centre).

Filled shapes are convex quads (object footprints, wall and opening slabs: each as 4 corners) and one simple
polygon (the floor). Quads are filled within their own bounding window of pixels, the floor by scanlines, so a
render costs a few NumPy calls per shape.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple, cast

import numpy as np
from numpy.typing import ArrayLike


def pixel_centres(size: int, mpp: float, centre: Sequence[float] | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Plan coordinates of the pixel centres along x (columns, ``(size,)``) and y (rows, ``(size,)``)."""
    k = (np.arange(size) + 0.5 - size / 2) * mpp
    return centre[0] + k, centre[1] - k


def fill_polygon(xy: np.ndarray, size: int, mpp: float, centre: Sequence[float] | np.ndarray) -> np.ndarray:
    """``(size, size)`` bool: pixel centres inside a simple polygon ``xy (k, 2)`` (even-odd scanlines)."""
    xs, ys = pixel_centres(size, mpp, centre)
    a, b = np.asarray(xy, float), np.roll(np.asarray(xy, float), -1, axis=0)
    y = ys[:, None]
    crosses = (a[None, :, 1] <= y) != (b[None, :, 1] <= y)  # (rows, edges)
    t = (y - a[None, :, 1]) / np.where(b[:, 1] != a[:, 1], b[:, 1] - a[:, 1], 1.0)[None, :]
    x_at = np.where(crosses, a[None, :, 0] + t * (b[None, :, 0] - a[None, :, 0]), np.inf)
    left_of = (x_at[:, None, :] < xs[None, :, None]).sum(axis=2)  # crossings left of each pixel centre
    return cast(np.ndarray, left_of % 2 == 1)


FLAT_WINDOW = 1024  # pixels: smaller windows are tested all at once as one flat array, larger ones one by one


def _left_of_edges(corners: np.ndarray, px: np.ndarray, py: np.ndarray) -> np.ndarray:
    """Whether points ``(px, py)`` lie left of (or on) all 4 edges of ``corners (..., 4, 2)``, broadcast together."""
    inside = np.ones(np.broadcast_shapes(corners.shape[:-2], px.shape, py.shape), bool)
    for e in range(4):
        x0, y0, x1, y1 = corners[..., e, 0], corners[..., e, 1], corners[..., (e + 1) % 4, 0], corners[..., (e + 1) % 4, 1]
        inside &= (x1 - x0) * (py - y0) - (y1 - y0) * (px - x0) >= 0
    return inside


def quad_pixels(corners: np.ndarray, size: int, mpp: float,
                centre: Sequence[float] | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pixels whose centres lie inside each convex quad ``corners (n, 4, 2)`` (counter-clockwise), as
    ``(quad, row, col)`` index arrays ``(k,)``. Each quad is tested only within its own bounding window of pixels
    (one pixel wider): windows under :data:`FLAT_WINDOW` pixels all at once, larger ones one by one."""
    corners = np.asarray(corners, float).reshape(-1, 4, 2)
    xs, ys = pixel_centres(size, mpp, centre)
    col = np.clip(((corners[..., 0] - xs[0]) / mpp + 0.5).astype(int), 0, size)  # bounding windows in pixels
    row = np.clip(((ys[0] - corners[..., 1]) / mpp + 0.5).astype(int), 0, size)
    c0, r0 = np.maximum(col.min(1) - 1, 0), np.maximum(row.min(1) - 1, 0)
    width = np.maximum(np.minimum(col.max(1) + 1, size) - c0, 0)
    height = np.maximum(np.minimum(row.max(1) + 1, size) - r0, 0)
    area = np.where(width * height <= FLAT_WINDOW, width * height, 0)
    q = np.repeat(np.arange(len(corners)), area)  # one entry per pixel of every small window
    local = np.arange(len(q)) - np.repeat(np.cumsum(area) - area, area)
    rows, cols = r0[q] + local // np.maximum(width[q], 1), c0[q] + local % np.maximum(width[q], 1)
    inside = _left_of_edges(corners[q], xs[cols], ys[rows])
    out = [(q[inside], rows[inside], cols[inside])]
    for k in np.flatnonzero(width * height > FLAT_WINDOW):
        r, c = np.arange(r0[k], r0[k] + height[k]), np.arange(c0[k], c0[k] + width[k])
        i, j = np.nonzero(_left_of_edges(corners[k], xs[None, c], ys[r, None]))
        out.append((np.full(len(i), k), r[i], c[j]))
    q, rows, cols = (np.concatenate(parts) for parts in zip(*out))
    return q, rows, cols


def fill_quads(image: np.ndarray, corners: np.ndarray, value: float, mpp: float, centre: Sequence[float] | np.ndarray) -> None:
    """Set ``value`` in ``image (size, size)`` inside each convex quad ``corners (n, 4, 2)``."""
    _, rows, cols = quad_pixels(corners, image.shape[0], mpp, centre)
    image[rows, cols] = value


def segment_quads(segments: np.ndarray, half_width: ArrayLike) -> np.ndarray:
    """``(m, 4, 2)`` counter-clockwise slabs around segments ``(m, 2, 2)``, ``half_width`` m either side."""
    a, b = segments[:, 0], segments[:, 1]
    d = b - a
    n = np.stack([-d[:, 1], d[:, 0]], 1) / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
    w = np.broadcast_to(np.asarray(half_width, float), (len(a),))[:, None] * n
    return np.stack([a - w, b - w, b + w, a + w], axis=1)


CHANNELS = ("floor", "walls", "doors", "windows", "height", "sin_yaw", "cos_yaw", "anchor")


class Canvas(NamedTuple):
    """A square image of ``size`` pixels of ``mpp`` m each, centred at plan point ``centre`` (m)."""
    size: int
    mpp: float
    centre: Sequence[float] | np.ndarray = (0.0, 0.0)


class Shell(NamedTuple):
    """A room's architecture in plan: ``outline (k, 2)`` floor polygon; ``walls (m, 2, 2)`` segments with half
    thicknesses ``wall_half (m,)``; ``openings`` {'doors': (d, 2, 2), 'windows': (w, 2, 2)} segments."""
    outline: np.ndarray
    walls: np.ndarray
    wall_half: np.ndarray
    openings: dict[str, Any]


def render_room(shell: Shell, boxes: np.ndarray, category: np.ndarray, n_categories: int, canvas: Canvas,
                anchor: int | None = None) -> np.ndarray:
    """``(len(CHANNELS) + n_categories, size, size)`` float32 top-down view of one room on ``canvas``: its ``shell``
    and objects ``boxes (n, 7)`` (cx, cy, cz, hx, hy, hz, yaw) of categories ``category (n,)`` (index into the
    per-category channels). Heights are object tops (m); where objects overlap, the higher one sets height and
    orientation. ``anchor``: an object whose footprint fills the anchor channel.
    """
    from .boxes import footprint_corners

    outline, walls, wall_half, openings = shell
    size, mpp, centre = canvas

    image = np.zeros((len(CHANNELS) + n_categories, size, size), np.float32)
    image[0] = fill_polygon(outline, size, mpp, centre)
    seg = [np.asarray(openings.get(name, np.zeros((0, 2, 2))), float).reshape(-1, 2, 2) for name in ("doors", "windows")]
    slabs = [segment_quads(walls, wall_half), *(segment_quads(s, np.full(len(s), 2 * mpp)) for s in seg)]
    channel = np.repeat([1, 2, 3], [len(s) for s in slabs])  # walls, doors, windows
    b = np.asarray(boxes, float).reshape(-1, 7)
    order = np.argsort(b[:, 2] + b[:, 5], kind="stable")  # low to high: the higher object wins
    footprints = footprint_corners(b[order, 0], b[order, 1], b[order, 3], b[order, 4], b[order, 6]).reshape(-1, 4, 2)
    q, rows, cols = quad_pixels(np.concatenate([*slabs, footprints]), size, mpp, centre)
    arch = q < len(channel)
    image[channel[q[arch]], rows[arch], cols[arch]] = 1.0
    q, rows, cols = q[~arch] - len(channel), rows[~arch], cols[~arch]  # objects, by rank in ``order``
    k = order[q]
    image[len(CHANNELS) + np.asarray(category, int)[k], rows, cols] = 1.0
    if anchor is not None:
        mine = k == anchor
        image[7, rows[mine], cols[mine]] = 1.0
    top = np.full((size, size), -1)
    np.maximum.at(top, (rows, cols), q)  # per pixel, the highest object covering it
    rows, cols = np.nonzero(top >= 0)
    k = order[top[rows, cols]]
    for c, values in zip((4, 5, 6), (b[:, 2] + b[:, 5], np.sin(b[:, 6]), np.cos(b[:, 6]))):
        image[c, rows, cols] = values[k]
    return image
