"""Functional relations between objects, from their oriented boxes: where a target stands around an anchor (its
region in the anchor's frame), how far (the plan gap between footprints), whether it faces the anchor, and whether
an object stands with its back to a wall. Pure functions over ``(n, 7)`` boxes (``cx, cy, cz, hx, hy, hz, yaw``;
local +y is the front); one implementation for the evaluation's functional checks and every method that wants them.

Regions of a target's centre in an anchor's frame, its footprint scaled to the unit square ``|u|, |v| <= 1``:
``front`` (v > 1, |u| <= 1), ``back`` (v < -1), ``side_front`` / ``side_back`` (|u| > 1, |v| <= 1, the front or
back half: a nightstand beside a bed's head is ``side_back``), ``corner`` (|u| > 1 and |v| > 1) and ``over``
(inside the footprint: on it, under it or tucked in).
"""
from __future__ import annotations

from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from .boxes import footprint_corners, footprint_overlap, point_box, rotation
from .frames import FOLD, RADIAL_FRAMES, front_of, turn_error, wrap
from .polygon import inward_normals, make_ccw, polygon_segments

REGIONS = ("front", "back", "side_front", "side_back", "corner", "over")


def offsets(boxes: np.ndarray) -> np.ndarray:
    """``(n, n, 2)`` each target ``j``'s centre in anchor ``i``'s frame (m; x right, y front; row: anchor)."""
    b = np.asarray(boxes, float).reshape(-1, 7)
    rel = b[None, :, :2] - b[:, None, :2]  # (anchor, target, 2)
    return cast(np.ndarray, np.einsum("aji,atj->ati", rotation(b[:, 6]), rel))  # R^T (world -> anchor's local)


def _normalised(boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(n, n)`` each target ``j``'s centre in anchor ``i``'s frame, scaled by the anchor's half extents: ``u``
    (signed, +x right) and ``v`` (+y front)."""
    b = np.asarray(boxes, float).reshape(-1, 7)
    local = offsets(b)
    return local[..., 0] / np.maximum(b[:, None, 3], 1e-9), local[..., 1] / np.maximum(b[:, None, 4], 1e-9)


def regions(boxes: np.ndarray) -> np.ndarray:
    """``(n, n)`` index into :data:`REGIONS` of target ``j``'s centre in anchor ``i``'s frame (row: anchor)."""
    u, v = _normalised(boxes)
    wide, long = np.abs(u) > 1.0, np.abs(v) > 1.0
    out = np.where(wide & long, 4, np.where(wide, np.where(v >= 0, 2, 3), np.where(long, np.where(v > 0, 0, 1), 5)))
    return out.astype(np.int8)


def equivalent_regions(boxes: np.ndarray, symmetry: ArrayLike | None = None) -> np.ndarray:
    """``(t, n, n)`` index into :data:`REGIONS` of target ``j``'s centre in each frame anchor ``i`` cannot be told
    apart from (row: anchor): its own, and for a rotational-k anchor its frames turned by ``2 pi m / k``, for a radial
    one by ``2 pi m /`` :data:`~pipeline.geometry.frames.RADIAL_FRAMES` (mirrors change no region). A rotational-2
    coffee table turned by half a turn holds the sofa in its front region in one of its frames. Anchors with fewer
    frames repeat their own; ``symmetry (n,)``: each object's type (None: literal fronts, ``t`` = 1)."""
    b = np.asarray(boxes, float).reshape(-1, 7)
    kinds = ["none"] * len(b) if symmetry is None else list(np.asarray(symmetry, object))
    k = np.array([RADIAL_FRAMES if s == "radial" else max(FOLD.get(s, 1), 1) for s in kinds], int)
    out = []
    for m in range(int(k.max(initial=1))):
        turned = b.copy()
        turned[:, 6] += 2 * np.pi * (m % k) / k
        out.append(regions(turned))
    return np.stack(out)


def sides(boxes: np.ndarray, corners: bool = True) -> np.ndarray:
    """``(n, n)`` index into :data:`~pipeline.geometry.boxes.SIDES` (front, back, left, right) of the anchor side
    target ``j``'s centre lies beyond (over the anchor's footprint, e.g. a chair tucked under a desk: the side it is
    nearest in the anchor's scaled frame), -1 in a corner region (``corners=False``: the side it lies farthest beyond
    in the scaled frame) and on the diagonal (row: anchor)."""
    u, v = _normalised(boxes)
    wide, long = np.abs(u) > 1.0, np.abs(v) > 1.0
    corner = wide & long
    long = np.where(wide ^ long, long, np.abs(v) >= np.abs(u))
    out = np.where(long, np.where(v > 0, 0, 1), np.where(u < 0, 2, 3))
    out = np.where(corner, -1, out) if corners else out
    np.fill_diagonal(out, -1)
    return out.astype(np.int8)


SIDE_FACING_TURNS = np.array([np.pi, 0.0, -np.pi / 2, np.pi / 2])  # per SIDES: the turn, relative to the anchor's, facing it


def facing_turn(anchor: np.ndarray, xy: np.ndarray) -> float:
    """The yaw (rad) of an object centred at ``xy (2,)`` that squarely faces the side of ``anchor (7,)`` (a box) it
    stands beyond (:func:`sides` without corners): a coffee table drawn diagonally off a sofa's front corner faces the
    sofa's front, not whichever of its sides the diagonal happens to be nearer."""
    boxes = np.vstack([np.asarray(anchor, float).reshape(7), point_box(xy)])
    return float(boxes[0, 6] + SIDE_FACING_TURNS[sides(boxes, corners=False)[0, 1]])


def faces_wall(xy: np.ndarray, yaw: ArrayLike, a: np.ndarray, b: np.ndarray, normal: np.ndarray,
               limit: float) -> np.ndarray:
    """``(m,)`` bool: a pose at ``xy (m, 2)`` turned ``yaw (m,)`` faces the wall segment ``a``-``b`` (``(2,)`` each)
    whose inward unit ``normal (2,)`` is given: its front turned within ``limit`` rad of the wall's outward normal
    (square to it, so that whatever stands with its back to the wall faces it back) and its front ray meeting the
    segment. A sofa facing the wall its television stand will stand against; not a wall it sees along its length."""
    xy, yaw = np.asarray(xy, float).reshape(-1, 2), np.broadcast_to(np.asarray(yaw, float), (len(xy),))
    front = front_of(yaw)
    square = np.arccos(np.clip(front @ -np.asarray(normal, float), -1.0, 1.0)) <= limit
    along, rel = np.asarray(b, float) - a, np.asarray(a, float) - xy  # segment a + s * along meets xy + t * front
    cross = lambda u, v: u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]
    den = cross(front, along)
    ok = np.abs(den) > 1e-12
    t = np.where(ok, cross(rel, along) / np.where(ok, den, 1.0), -1.0)
    s = np.where(ok, cross(rel, front) / np.where(ok, den, 1.0), -1.0)
    return cast(np.ndarray, square & (t > 0) & (s >= 0) & (s <= 1))


def _corner_edge_gaps(ca: np.ndarray, cb: np.ndarray) -> np.ndarray:
    """``(k, m)`` least distance from a corner of each footprint ``ca (k, 4, 2)`` to an edge of each
    ``cb (m, 4, 2)``."""
    d = np.roll(cb, -1, axis=1) - cb  # (m, 4, 2) edges from each corner to the next
    p = ca[:, None, :, None, :] - cb[None, :, None, :, :]  # (point box, edge box, corner, edge, 2)
    t = np.clip(np.einsum("pqcej,qej->pqce", p, d) / np.maximum(np.einsum("qej,qej->qe", d, d), 1e-18)[None, :, None],
                0.0, 1.0)
    return cast(np.ndarray, np.linalg.norm(p - t[..., None] * d[None, :, None], axis=-1).min((2, 3)))


def footprint_gaps(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(k, m)`` distance (m) between the footprint of each of boxes ``a (k, 7)`` and each of ``b (m, 7)`` (0 where
    they overlap)."""
    a, b = np.asarray(a, float).reshape(-1, 7), np.asarray(b, float).reshape(-1, 7)
    ca = footprint_corners(a[:, 0], a[:, 1], a[:, 3], a[:, 4], a[:, 6])
    cb = footprint_corners(b[:, 0], b[:, 1], b[:, 3], b[:, 4], b[:, 6])
    i, j = (x.ravel() for x in np.meshgrid(np.arange(len(a)), np.arange(len(b)), indexing="ij"))
    touching = (footprint_overlap(ca[i], a[i, 6], cb[j], b[j, 6]) > 0).reshape(len(a), len(b))
    return np.where(touching, 0.0, np.minimum(_corner_edge_gaps(ca, cb), _corner_edge_gaps(cb, ca).T))


def plan_gaps(boxes: np.ndarray) -> np.ndarray:
    """``(n, n)`` symmetric distance (m) between the footprints of every pair (0 where they overlap)."""
    gap = footprint_gaps(boxes, boxes)
    np.fill_diagonal(gap, 0.0)
    return gap


def facing_angles(boxes: np.ndarray, symmetry: ArrayLike | None = None) -> np.ndarray:
    """``(n, n)`` angle (rad, 0..pi) between target ``j``'s front and the direction from its centre to anchor
    ``i``'s footprint (its nearest point; its centre where ``j``'s centre lies inside it). Row: anchor. With
    ``symmetry (n,)`` (each object's type), a symmetric target's nearest equivalent front counts
    (:func:`~pipeline.geometry.frames.turn_error`)."""
    b = np.asarray(boxes, float).reshape(-1, 7)
    local = np.einsum("aji,atj->ati", rotation(b[:, 6]), b[None, :, :2] - b[:, None, :2])  # target in anchor frame
    half = b[:, None, 3:5]
    near = np.clip(local, -half, half)  # nearest footprint point, anchor frame
    inside = np.all(np.abs(local) <= half, axis=-1)
    near = np.where(inside[..., None], 0.0, near)
    to_anchor = np.einsum("aij,atj->ati", rotation(b[:, 6]), near - local)  # world direction target -> anchor
    front = front_of(b[:, 6])[None]  # (1, target, 2)
    cross = front[..., 0] * to_anchor[..., 1] - front[..., 1] * to_anchor[..., 0]
    angle = np.arctan2(cross, np.einsum("atj,atj->at", to_anchor, front))
    return turn_error(angle, "none" if symmetry is None else np.asarray(symmetry, object)[None, :])


def facing_each_other(boxes: np.ndarray, limit: float) -> np.ndarray:
    """``(n, n)`` bool: target ``j``'s front lies within ``limit`` rad of the direction to anchor ``i``'s footprint and
    ``i``'s front within ``limit`` of the direction to ``j``'s centre (literal fronts; row: anchor, diagonal False). A
    sofa and the television stand across the room from it; a box of zero extents is a candidate centre."""
    b = np.asarray(boxes, float).reshape(-1, 7)
    centres = b.copy()
    centres[:, 3:6] = 0.0
    out = (facing_angles(b) <= limit) & (facing_angles(centres).T <= limit)
    np.fill_diagonal(out, False)
    return out


def in_front(boxes: np.ndarray, points: np.ndarray, limit: float) -> np.ndarray:
    """``(n,)`` bool: some box of ``boxes (m, 7)`` has its front within ``limit`` rad of the direction from its centre
    to ``points (n, 2)``: where a candidate centre stands for :func:`facing_each_other`'s second test (the television
    stand's front turned towards the sofa), for a whole grid at once."""
    b = np.asarray(boxes, float).reshape(-1, 7)
    d = np.asarray(points, float).reshape(-1, 2)[:, None, :] - b[None, :, :2]  # (n, m, 2)
    front = front_of(b[:, 6])[None]  # (1, m, 2)
    cos = np.einsum("nmj,nmj->nm", d, front) / np.maximum(np.linalg.norm(d, axis=-1), 1e-12)
    out: np.ndarray = (cos >= np.cos(limit)).any(axis=1)
    return out


def back_to_wall(boxes: np.ndarray, outline: np.ndarray, max_gap: float, max_angle: float,
                 symmetry: ArrayLike | None = None) -> np.ndarray:
    """``(n,)`` bool: the object's back faces a wall of the floor ``outline (k, 2)`` (its back normal within
    ``max_angle`` rad of the wall's outward normal; with ``symmetry (n,)``, any of a symmetric object's equivalent
    backs) and that back side's midpoint lies within ``max_gap`` m of that wall's inner face, over the wall's
    length."""
    b = np.asarray(boxes, float).reshape(-1, 7)
    walls = polygon_segments(make_ccw(np.asarray(outline, float)))
    normal = inward_normals(walls)  # (w, 2) into the room
    wall_yaw = np.arctan2(-normal[:, 0], normal[:, 1])  # the yaw whose front points into the room from the wall
    sym = np.broadcast_to(np.asarray("none" if symmetry is None else symmetry, object), (len(b),))
    err = turn_error(b[:, 6, None] - wall_yaw[None], sym[:, None])  # (n, w) turn off "back to this wall"
    fold = np.array([FOLD.get(x, 1) for x in sym])[:, None]
    step = 2 * np.pi / np.maximum(fold, 1)
    eq = np.where(fold == 0, wall_yaw[None], b[:, 6, None] + step * np.round(wrap(wall_yaw[None] - b[:, 6, None]) / step))
    depth = np.where(np.abs(np.sin(eq - b[:, 6, None])) > 0.5, b[:, 3, None], b[:, 4, None])  # (n, w)
    mid = b[:, None, :2] - front_of(eq) * depth[..., None]  # the equivalent back's midpoint
    rel = mid - walls[None, :, 0]  # (n, w, 2)
    d = walls[:, 1] - walls[:, 0]
    along = np.einsum("nwj,wj->nw", rel, d) / np.maximum(np.einsum("wj,wj->w", d, d), 1e-18)
    off = np.einsum("nwj,wj->nw", rel, normal)  # distance in front of the wall's face
    return cast(np.ndarray, np.any((err <= max_angle) & (np.abs(off) <= max_gap) & (along >= 0.0) & (along <= 1.0), axis=1))


def off_axis(boxes: np.ndarray, outline: np.ndarray, angle: float, symmetry: ArrayLike | None = None) -> np.ndarray:
    """``(n,)`` float: 1.0 where an object's yaw lies more than ``angle`` rad off the axes of the wall nearest its
    centre (a quarter turn of it), 0.0 where not, NaN for a radially symmetric object (its yaw means nothing)."""
    b = np.asarray(boxes, float).reshape(-1, 7)
    walls = polygon_segments(make_ccw(np.asarray(outline, float)))
    normal = inward_normals(walls)
    a, d = walls[:, 0], walls[:, 1] - walls[:, 0]
    t = np.clip(np.einsum("nwj,wj->nw", b[:, None, :2] - a[None], d) / np.maximum(np.einsum("wj,wj->w", d, d), 1e-18), 0, 1)
    near = np.argmin(np.linalg.norm(a[None] + t[..., None] * d[None] - b[:, None, :2], axis=-1), axis=1)
    wall_yaw = np.arctan2(-normal[near, 0], normal[near, 1])
    out = (turn_error(b[:, 6] - wall_yaw, "rotational-4") > angle).astype(float)
    sym = np.broadcast_to(np.asarray("none" if symmetry is None else symmetry, object), (len(b),))
    return np.where(sym == "radial", np.nan, out)
