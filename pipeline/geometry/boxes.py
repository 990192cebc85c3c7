"""Oriented boxes: footprints, projections, overlaps. Vectorised over ``n`` boxes.

A box is ``(cx, cy, cz, hx, hy, hz, yaw)``: centre, half extents in the local frame (x right,
y front, z up) and yaw (counter-clockwise about +Z).
"""
from __future__ import annotations

from typing import cast

import numpy as np
from numpy.typing import ArrayLike

# local-frame outward unit normals of the four vertical sides
SIDES = ("front", "back", "left", "right")
SIDE_NORMALS = np.array([[0.0, 1.0], [0.0, -1.0], [-1.0, 0.0], [1.0, 0.0]])


def rotation(yaw: ArrayLike) -> np.ndarray:
    """``(..., 2, 2)`` rotation matrices local -> world."""
    c, s = np.cos(yaw), np.sin(yaw)
    out = np.empty(np.shape(c) + (2, 2), np.result_type(c))
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    return out


def footprint_corners(cx: ArrayLike, cy: ArrayLike, hx: ArrayLike, hy: ArrayLike, yaw: ArrayLike) -> np.ndarray:
    """``(n, 4, 2)`` world corners of the floor footprints, counter-clockwise."""
    cx, cy, hx, hy, yaw = (np.atleast_1d(np.asarray(a, dtype=float)) for a in (cx, cy, hx, hy, yaw))
    local = np.stack([np.stack([-hx, -hy], -1), np.stack([hx, -hy], -1),
                      np.stack([hx, hy], -1), np.stack([-hx, hy], -1)], 1)  # (n, 4, 2)
    world = np.einsum("nij,nkj->nki", rotation(yaw), local)
    return cast(np.ndarray, world + np.stack([cx, cy], -1)[:, None, :])


def from_corners(corners: np.ndarray, z0: float, z1: float) -> np.ndarray:
    """``(m, 7)`` boxes standing from ``z0`` to ``z1`` m on the rectangles ``corners (m, 4, 2)`` (consecutive corners),
    their local x along each rectangle's first edge."""
    c = np.asarray(corners, float).reshape(-1, 4, 2)
    x, y = c[:, 1] - c[:, 0], c[:, 3] - c[:, 0]
    centre = c.mean(1)
    out = np.empty((len(c), 7))
    out[:, :2], out[:, 2], out[:, 5] = centre, (z0 + z1) / 2, (z1 - z0) / 2
    out[:, 3], out[:, 4] = np.linalg.norm(x, axis=1) / 2, np.linalg.norm(y, axis=1) / 2
    out[:, 6] = np.arctan2(x[:, 1], x[:, 0])
    return out


def on_floor(boxes: np.ndarray, floor_contact: float) -> np.ndarray:
    """``(n,)`` bool: the boxes ``(n, 7)`` whose bottom lies within ``floor_contact`` m of the floor (z = 0)."""
    b = np.asarray(boxes, float).reshape(-1, 7)
    return cast(np.ndarray, b[:, 2] - b[:, 5] <= floor_contact)


def point_box(xy: ArrayLike, yaw: float = 0.0) -> np.ndarray:
    """``(7,)`` a candidate centre ``xy (2,)`` turned ``yaw`` as a box of zero extents on the floor (what the plan
    predicates read of a pose before an object's extents matter)."""
    x, y = np.asarray(xy, float).reshape(2)
    return np.array([x, y, 0.0, 0.0, 0.0, 0.0, yaw], float)


def diagonal_2d(hx: ArrayLike, hy: ArrayLike) -> np.ndarray:
    """Footprint diagonal length."""
    return cast(np.ndarray, 2.0 * np.hypot(hx, hy))


def _axes(yaw: np.ndarray) -> np.ndarray:
    r = rotation(yaw)  # (n, 2, 2): columns are local x and y in world
    return np.stack([r[..., 0], r[..., 1]], 1)  # (n, 2 axes, 2)


def footprint_overlap(corners_a: np.ndarray, yaw_a: np.ndarray, corners_b: np.ndarray, yaw_b: np.ndarray) -> np.ndarray:
    """Separating-axis overlap depth of footprint pairs (``<= 0``: disjoint), shape ``(n,)``."""
    axes = np.concatenate([_axes(yaw_a), _axes(yaw_b)], axis=1)  # (n, 4, 2)
    pa = np.einsum("nkj,naj->nak", corners_a, axes)
    pb = np.einsum("nkj,naj->nak", corners_b, axes)
    overlap = np.minimum(pa.max(-1), pb.max(-1)) - np.maximum(pa.min(-1), pb.min(-1))
    return cast(np.ndarray, overlap.min(axis=1))


def clearing_moves(anchor: np.ndarray, target: np.ndarray, margin: float = 0.0) -> np.ndarray:
    """``(8, 2)`` floor translations of ``target (7,)`` that clear ``anchor (7,)``'s footprint by ``margin`` m, one
    per separating axis of the two footprints (both boxes' local axes) and side, shortest first: moved by any of
    them, the footprints' projections on that axis lie ``margin`` apart. The first is the minimum translation of the
    overlapping footprints (at least the plan part of :func:`penetration_depths`, which is the projections' shared
    length: more where one projection holds the other)."""
    a, b = np.asarray(anchor, float).reshape(7), np.asarray(target, float).reshape(7)
    corners = footprint_corners([a[0], b[0]], [a[1], b[1]], [a[3], b[3]], [a[4], b[4]], [a[6], b[6]])
    axes = np.concatenate([_axes(np.array([a[6]]))[0], _axes(np.array([b[6]]))[0]])  # (4, 2)
    pa, pb = corners[0] @ axes.T, corners[1] @ axes.T  # (4 corners, 4 axes)
    up = pa.max(0) - pb.min(0) + margin  # along +axis: target's low side past anchor's high side
    down = pb.max(0) - pa.min(0) + margin  # along -axis
    moves = np.concatenate([axes * up[:, None], -axes * down[:, None]])
    return moves[np.argsort(np.linalg.norm(moves, axis=1), kind="stable")]


def penetration_depths(boxes: np.ndarray) -> np.ndarray:
    """``(n, n)`` interpenetration depth of every box pair (0 where they do not overlap).

    ``boxes`` is ``(n, 7)``. Depth is the smallest overlap over the separating axes of the two
    footprints and the vertical axis: how far one box must move to clear the other.
    """
    b = np.asarray(boxes, dtype=float).reshape(-1, 7)
    n = len(b)
    out = np.zeros((n, n))
    if n < 2:
        return out
    i, j = np.triu_indices(n, 1)
    corners = footprint_corners(b[:, 0], b[:, 1], b[:, 3], b[:, 4], b[:, 6])
    plan = footprint_overlap(corners[i], b[i, 6], corners[j], b[j, 6])
    zo = np.minimum(b[i, 2] + b[i, 5], b[j, 2] + b[j, 5]) - np.maximum(b[i, 2] - b[i, 5], b[j, 2] - b[j, 5])
    depth = np.clip(np.minimum(plan, zo), 0.0, None)
    out[i, j] = depth
    out[j, i] = depth
    return out


def to_local(points: np.ndarray, cx: float, cy: float, yaw: float) -> np.ndarray:
    """World ``(..., 2)`` points into a box's local floor frame."""
    return cast(np.ndarray, (np.asarray(points, dtype=float) - [cx, cy]) @ rotation(yaw))
