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

import numpy as np


def pixel_centres(size: int, mpp: float, centre) -> tuple[np.ndarray, np.ndarray]:
    """Plan coordinates of the pixel centres along x (columns, ``(size,)``) and y (rows, ``(size,)``)."""
    k = (np.arange(size) + 0.5 - size / 2) * mpp
    return centre[0] + k, centre[1] - k


def fill_polygon(xy: np.ndarray, size: int, mpp: float, centre) -> np.ndarray:
    """``(size, size)`` bool: pixel centres inside a simple polygon ``xy (k, 2)`` (even-odd scanlines)."""
    xs, ys = pixel_centres(size, mpp, centre)
    a, b = np.asarray(xy, float), np.roll(np.asarray(xy, float), -1, axis=0)
    y = ys[:, None]
    crosses = (a[None, :, 1] <= y) != (b[None, :, 1] <= y)  # (rows, edges)
    t = (y - a[None, :, 1]) / np.where(b[:, 1] != a[:, 1], b[:, 1] - a[:, 1], 1.0)[None, :]
    x_at = np.where(crosses, a[None, :, 0] + t * (b[None, :, 0] - a[None, :, 0]), np.inf)
    left_of = (x_at[:, None, :] < xs[None, :, None]).sum(axis=2)  # crossings left of each pixel centre
    return left_of % 2 == 1


def quad_masks(corners: np.ndarray, size: int, mpp: float, centre):
    """For each convex quad ``corners (n, 4, 2)`` (counter-clockwise): its pixel window ``(rows, cols)`` as slices
    and the bool mask of pixel centres inside it within that window (None for a quad outside the view)."""
    xs, ys = pixel_centres(size, mpp, centre)
    col = np.clip(((corners[..., 0] - xs[0]) / mpp + 0.5).astype(int), 0, size)  # bounding windows in pixels
    row = np.clip(((ys[0] - corners[..., 1]) / mpp + 0.5).astype(int), 0, size)
    for q, c0, c1, r0, r1 in zip(corners, col.min(1) - 1, col.max(1) + 1, row.min(1) - 1, row.max(1) + 1):
        c0, r0, c1, r1 = max(c0, 0), max(r0, 0), min(c1, size), min(r1, size)
        if c1 <= c0 or r1 <= r0:
            yield None
            continue
        px, py = xs[None, c0:c1], ys[r0:r1, None]
        inside = np.ones((r1 - r0, c1 - c0), bool)
        for (x0, y0), (x1, y1) in zip(q, np.roll(q, -1, axis=0)):  # left of every edge
            inside &= (x1 - x0) * (py - y0) - (y1 - y0) * (px - x0) >= 0
        yield (slice(r0, r1), slice(c0, c1)), inside


def fill_quads(image: np.ndarray, corners: np.ndarray, value: float, mpp: float, centre) -> None:
    """Set ``value`` in ``image (size, size)`` inside each convex quad ``corners (n, 4, 2)``."""
    for hit in quad_masks(corners, image.shape[0], mpp, centre):
        if hit is not None:
            image[hit[0]][hit[1]] = value


def segment_quads(segments: np.ndarray, half_width) -> np.ndarray:
    """``(m, 4, 2)`` counter-clockwise slabs around segments ``(m, 2, 2)``, ``half_width`` m either side."""
    a, b = segments[:, 0], segments[:, 1]
    d = b - a
    n = np.stack([-d[:, 1], d[:, 0]], 1) / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
    w = np.broadcast_to(np.asarray(half_width, float), (len(a),))[:, None] * n
    return np.stack([a - w, b - w, b + w, a + w], axis=1)


CHANNELS = ("floor", "walls", "doors", "windows", "height", "sin_yaw", "cos_yaw", "anchor")


def render_room(outline: np.ndarray, walls: np.ndarray, wall_half: np.ndarray, openings: dict, boxes: np.ndarray,
                category: np.ndarray, n_categories: int, size: int, mpp: float, centre,
                anchor: int | None = None) -> np.ndarray:
    """``(len(CHANNELS) + n_categories, size, size)`` float32 top-down view of one room.

    ``outline (k, 2)`` floor polygon; ``walls (m, 2, 2)`` segments with half thicknesses ``wall_half (m,)``;
    ``openings`` {'doors': (d, 2, 2), 'windows': (w, 2, 2)} segments; ``boxes (n, 7)`` objects (cx, cy, cz, hx, hy,
    hz, yaw) of categories ``category (n,)`` (index into the per-category channels). Heights are object tops (m);
    where objects overlap, the higher one sets height and orientation. ``anchor``: an object whose footprint fills
    the anchor channel.
    """
    from .boxes import footprint_corners

    image = np.zeros((len(CHANNELS) + n_categories, size, size), np.float32)
    image[0] = fill_polygon(outline, size, mpp, centre)
    fill_quads(image[1], segment_quads(walls, wall_half), 1.0, mpp, centre)
    for k, name in ((2, "doors"), (3, "windows")):
        seg = np.asarray(openings.get(name, np.zeros((0, 2, 2))), float).reshape(-1, 2, 2)
        fill_quads(image[k], segment_quads(seg, np.full(len(seg), 2 * mpp)), 1.0, mpp, centre)
    b = np.asarray(boxes, float).reshape(-1, 7)
    if not len(b):
        return image
    quads = footprint_corners(b[:, 0], b[:, 1], b[:, 3], b[:, 4], b[:, 6])
    order = np.argsort(b[:, 2] + b[:, 5], kind="stable")  # low to high: the higher object wins
    for k, hit in zip(order, quad_masks(quads[order], size, mpp, centre)):
        if hit is None:
            continue
        (rows, cols), inside = hit
        values = (b[k, 2] + b[k, 5], np.sin(b[k, 6]), np.cos(b[k, 6]))
        for channel, v in zip((4, 5, 6), values):
            image[channel, rows, cols][inside] = v
        image[len(CHANNELS) + int(category[k]), rows, cols][inside] = 1.0
        if anchor == k:
            image[7, rows, cols][inside] = 1.0
    return image
