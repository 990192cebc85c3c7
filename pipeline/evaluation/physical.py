"""Physical plausibility per room: objects that collide (mesh or oriented box, the filter's penetration measure) and
objects out of bounds (ThreedFront toolkit's test: the footprint eroded by a margin still leaves the floor)."""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..geometry import boxes
from ..geometry.collision import CollisionTest, penetrating_pairs
from ..geometry.meshes import Mesh
from ..geometry.polygon import outside_area
from ..room import RoomInput


def colliding(room: RoomInput, parents: Sequence[str | None], meshes: Sequence[Mesh | None],
              test: CollisionTest) -> np.ndarray:
    """``(n,)`` bool: objects penetrating another deeper than ``test.limit``, ignoring support pairs.

    ``parents``: each object's support parent id (or None); ``meshes``: each object's ``(vertices, faces)`` or None
    (measured as its box); ``test``: the evaluation's (``evaluate.collision``, :meth:`CollisionTest.of`).
    """
    n = len(room.object_ids)
    out = np.zeros(n, bool)
    if n < 2:
        return out
    ids = np.asarray(room.object_ids, dtype=object)
    par = np.asarray([p if isinstance(p, str) else None for p in parents], dtype=object)
    depth = boxes.penetration_depths(room.boxes)
    depth[(par[:, None] == ids[None, :]) | (par[None, :] == ids[:, None])] = 0.0
    for i, j, _, _ in penetrating_pairs(depth, {"meshes": list(meshes), "poses": room.poses}, test):
        out[i] = out[j] = True
    return out


def out_of_bounds(outline: np.ndarray, box: np.ndarray, erode: float, tolerance: float) -> np.ndarray:
    """``(n,)`` bool: footprints of ``box (n, 7)`` that, eroded by ``erode`` m, keep more than ``tolerance`` m^2
    outside the floor polygon ``outline (k, 2)``."""
    if not len(box):
        return np.zeros(0, bool)
    corners = boxes.footprint_corners(box[:, 0], box[:, 1], box[:, 3], box[:, 4], box[:, 6])
    return outside_area(outline, corners, erode) > tolerance
