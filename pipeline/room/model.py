"""The room model every package uses: one room as arrays (:class:`RoomInput`), its merged walls (:class:`Walls`)
and the column order of object boxes and poses in the canonical tables. Pure data and geometry, no IO."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from ..geometry.polygon import door_zones, inward_normals, merge_collinear, outline_from_loop, signed_area, wall_loop

BOX_COLUMNS = ["cx", "cy", "cz", "hx", "hy", "hz", "yaw"]
POSE_COLUMNS = ["px", "py", "pz", "yaw", "sx", "sy", "sz"]


@dataclass
class RoomInput:
    """One room as arrays: what extraction needs from the canonical tables."""
    room_id: str
    room_type: str
    height: float
    outline: np.ndarray  # (k, 2) floor outline
    wall_ids: list[str]
    wall_segments: np.ndarray  # (w, 2, 2) inner faces
    wall_thickness: np.ndarray  # (w,)
    openings: list[dict[str, Any]]  # element_id, kind, x0, y0, x1, y1, z0, z1
    object_ids: list[str]
    categories: list[str]
    model_ids: list[str]
    boxes: np.ndarray  # (n, 7) BOX_COLUMNS
    poses: np.ndarray  # (n, 7) POSE_COLUMNS


def door_segments(room: RoomInput) -> np.ndarray:
    """``(d, 2, 2)`` the floor-plan segments of the room's doors (its openings of kind ``door``)."""
    doors = [[[o["x0"], o["y0"]], [o["x1"], o["y1"]]] for o in room.openings if o["kind"] == "door"]
    return np.array(doors, float).reshape(-1, 2, 2)


def door_zones_of(room: RoomInput, depth: float) -> np.ndarray:
    """``(d, 4, 2)`` the rectangles reaching ``depth`` m into the room from each of its doors
    (:func:`~pipeline.geometry.polygon.door_zones`); none when ``depth`` is 0 or the room has no door. The one door
    clearance of PlanIT's search, the annealing solvers' hard limits and GRAINS's repair."""
    doors = door_segments(room)
    if depth <= 0 or not len(doors):
        return np.zeros((0, 4, 2))
    return door_zones(room.outline, doors, depth)


@dataclass
class Walls:
    """Merged wall segments of a room in loop order (inner faces, counter-clockwise)."""
    ids: list[str]
    a: np.ndarray  # (w, 2) start points
    b: np.ndarray  # (w, 2) end points
    normal: np.ndarray  # (w, 2) into the room
    thickness: np.ndarray
    height: float

    @property
    def length(self) -> np.ndarray:
        return cast(np.ndarray, np.linalg.norm(self.b - self.a, axis=1))

    @property
    def dir(self) -> np.ndarray:
        return cast(np.ndarray, (self.b - self.a) / self.length[:, None])

    @property
    def segments(self) -> np.ndarray:
        """``(w, 2, 2)`` inner faces, start to end."""
        return np.stack([self.a, self.b], 1)


def merge_walls(segs: np.ndarray, ids: list[str], thick: np.ndarray, height: float, tol: float = 1e-3) -> Walls:
    """Order wall segments along their loop, make it counter-clockwise and merge collinear neighbours.

    A merged wall keeps the id of the original wall at its start. Raises ValueError for an open loop.
    """
    segs = np.asarray(segs, float).reshape(-1, 2, 2)
    thick = np.where(np.isfinite(thick), thick, 0.1)
    closed, why, order = wall_loop(segs, tol)
    if not closed:
        raise ValueError(f"walls do not form a closed loop: {why}")
    oriented = [(segs[o], o) if o >= 0 else (segs[-o - 1][::-1], -o - 1) for o in order]
    if signed_area(outline_from_loop(segs, order)) < 0:
        oriented = [(s[::-1], k) for s, k in oriented[::-1]]
    start = {tuple(np.round(s[0], 6)): k for s, k in oriented}
    outline = merge_collinear(np.array([s[0] for s, _ in oriented]))
    keys = [start.get(tuple(np.round(p, 6))) for p in outline]
    names = [ids[k] if k is not None else f"wall_m{i}" for i, k in enumerate(keys)]
    thickness = np.array([thick[k] if k is not None else float(np.median(thick)) for k in keys])
    nxt = np.roll(outline, -1, axis=0)
    return Walls(names, outline, nxt, inward_normals(np.stack([outline, nxt], 1)), thickness, height)


def wall_footprints(w: Walls) -> np.ndarray:
    """(w, 4, 2) counter-clockwise footprints of the walls, behind their inner faces."""
    back = -w.normal * w.thickness[:, None]
    return np.stack([w.a, w.b, w.b + back, w.a + back], 1)[:, ::-1]
