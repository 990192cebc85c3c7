"""Walkability (PhyScene's measure): the floor minus the footprints of the objects an agent cannot pass under,
eroded by the agent's radius, as a grid; the share of that free space connected to a door, and whether every floor
object's front can be reached from a door. SciPy's ndimage does the erosion, labelling and distances. One measure
for the evaluation, PlanIT's search (a floor object may not close the floor off from the door:
``placement/walkable.py``) and the Infinigen-style solver's free-floor term."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage

from ..geometry import boxes
from ..geometry.raster import fill_polygon, fill_quads, pixel_centres
from .model import RoomInput, door_segments


@dataclass(frozen=True)
class Walk:
    """The measure's settings (``evaluate.walk``), read once from the validated config."""
    cell: float  # m, grid cell
    robot_radius: float  # m, the agent's radius
    clearance: float  # m; objects whose bottom is higher do not block
    door_reach: float  # m beyond the radius from a door's midpoint that counts as at the door
    front_reach: float  # m from an object's front midpoint to the nearest door-connected agent centre

    @classmethod
    def of(cls, cfg: Mapping[str, Any]) -> "Walk":
        """From the config's ``evaluate.walk`` section."""
        return cls(**{k: float(v) for k, v in cfg.items()})


def walk_grid(room: RoomInput, cell: float, clearance: float) -> tuple[np.ndarray, float, np.ndarray]:
    """``(size, size)`` bool free floor (inside the outline, outside every footprint whose bottom is below
    ``clearance`` m), the grid's ``cell`` size and its centre ``(2,)``."""
    lo, hi = room.outline.min(0), room.outline.max(0)
    centre = (lo + hi) / 2
    size = int(np.ceil((hi - lo).max() / cell)) + 4
    free = fill_polygon(room.outline, size, cell, centre)
    b = room.boxes[(room.boxes[:, 2] - room.boxes[:, 5]) < clearance] if len(room.boxes) else room.boxes
    if len(b):
        blocked = np.zeros_like(free)
        fill_quads(blocked, boxes.footprint_corners(b[:, 0], b[:, 1], b[:, 3], b[:, 4], b[:, 6]), True, cell, centre)
        free &= ~blocked
    return free, cell, centre


def door_connected(free: np.ndarray, room: RoomInput, cell: float, centre: np.ndarray, radius: float,
                   door_reach: float) -> tuple[np.ndarray, np.ndarray]:
    """The agent's free centres (``free`` eroded by ``radius``) and those connected to a door: components with a
    cell within ``radius + door_reach`` of a door's midpoint (no door: the largest component)."""
    k = int(np.ceil(radius / cell))
    yy, xx = np.mgrid[-k:k + 1, -k:k + 1]
    agent = ndimage.binary_erosion(free, structure=(xx ** 2 + yy ** 2) * cell ** 2 <= radius ** 2, border_value=0)
    labels, n = ndimage.label(agent)
    if n == 0:
        return agent, agent
    xs, ys = pixel_centres(free.shape[0], cell, centre)
    doors = door_segments(room)
    seeds = set()
    for mx, my in doors.mean(1):
        near = (xs[None, :] - mx) ** 2 + (ys[:, None] - my) ** 2 <= (radius + door_reach) ** 2
        seeds |= set(np.unique(labels[near & agent]).tolist())
    if not len(doors):
        seeds = {int(np.argmax(np.bincount(labels.ravel())[1:])) + 1}
    return agent, np.isin(labels, sorted(seeds - {0}))


def front_points(room: RoomInput, clearance: float) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the floor objects (bottom below ``clearance``) and the midpoints ``(m, 2)`` of their front faces."""
    b = room.boxes
    idx = np.nonzero((b[:, 2] - b[:, 5]) < clearance)[0] if len(b) else np.zeros(0, int)
    local = np.stack([np.zeros(len(idx)), b[idx, 4]], -1)
    return idx, np.einsum("nij,nj->ni", boxes.rotation(b[idx, 6]), local) + b[idx, :2]


def connected_share(agent: np.ndarray, connected: np.ndarray) -> float:
    """The door-connected share of the agent's free centres (none free: 0)."""
    return float(connected.sum() / agent.sum()) if agent.any() else 0.0


def walkable_share(room: RoomInput, walk: Walk) -> float:
    """The door-connected share of the agent's free space alone."""
    free, cell, centre = walk_grid(room, walk.cell, walk.clearance)
    return connected_share(*door_connected(free, room, cell, centre, walk.robot_radius, walk.door_reach))


def walkability(room: RoomInput, walk: Walk) -> dict[str, Any]:
    """``walkable_share``: door-connected share of the agent's free space; ``reachable``: share of floor objects
    whose front midpoint lies within ``front_reach`` of a door-connected agent centre; ``all_reachable``."""
    free, cell, centre = walk_grid(room, walk.cell, walk.clearance)
    agent, connected = door_connected(free, room, cell, centre, walk.robot_radius, walk.door_reach)
    share = connected_share(agent, connected)
    idx, fronts = front_points(room, walk.clearance)
    if not connected.any() or not len(idx):
        ok = np.zeros(len(idx), bool)
    else:
        dist = ndimage.distance_transform_edt(~connected) * cell
        xs, ys = pixel_centres(free.shape[0], cell, centre)
        col = np.clip(np.round((fronts[:, 0] - xs[0]) / cell).astype(int), 0, free.shape[1] - 1)
        row = np.clip(np.round((ys[0] - fronts[:, 1]) / cell).astype(int), 0, free.shape[0] - 1)
        ok = dist[row, col] <= walk.front_reach
    return {"walkable_share": share, "reachable": float(ok.mean()) if len(ok) else 1.0,
            "all_reachable": bool(ok.all())}
