"""Known-bad rooms made from real ones, for the classifier's power check: each object moved a fixed distance in a
random direction (jitter), turned to a random yaw (turns), the categories shuffled among a room's objects
(shuffle), or the room's objects placed at random on its floor (placement). Pure NumPy over RoomInputs, seeded."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..geometry.frames import wrap
from ..geometry.raster import fill_polygon, pixel_centres
from ..room import RoomInput
from ..seeding import rng_for

KINDS = ("jitter", "turns", "shuffle", "placement")


def _moved(room: RoomInput, xy: np.ndarray, yaw: np.ndarray, categories: list[str] | None = None) -> RoomInput:
    """The room with its objects' plan positions ``(n, 2)`` and yaws ``(n,)`` replaced (boxes and poses alike)."""
    b, p = room.boxes.copy(), room.poses.copy()
    shift = xy - b[:, :2]
    b[:, :2] += shift
    p[:, :2] += shift
    b[:, 6] = p[:, 3] = wrap(yaw)
    return replace(room, boxes=b, poses=p, categories=list(categories or room.categories))


def jitter(room: RoomInput, distance: float, rng: np.random.Generator) -> RoomInput:
    """Every object moved ``distance`` m in its own random plan direction."""
    angle = rng.uniform(0, 2 * np.pi, len(room.object_ids))
    return _moved(room, room.boxes[:, :2] + distance * np.stack([np.cos(angle), np.sin(angle)], -1), room.boxes[:, 6])


def turns(room: RoomInput, rng: np.random.Generator) -> RoomInput:
    """Every object turned about its centre to a uniformly random yaw."""
    return _moved(room, room.boxes[:, :2], rng.uniform(-np.pi, np.pi, len(room.object_ids)))


def shuffle(room: RoomInput, rng: np.random.Generator) -> RoomInput:
    """The categories permuted among the room's objects (boxes stay)."""
    return _moved(room, room.boxes[:, :2], room.boxes[:, 6], [room.categories[k] for k in
                                                             rng.permutation(len(room.categories))])


def placement(room: RoomInput, rng: np.random.Generator, cell: float = 0.05) -> RoomInput:
    """Every object's centre at a uniformly random point of the floor, its yaw a random quarter turn."""
    lo, hi = room.outline.min(0), room.outline.max(0)
    size = int(np.ceil((hi - lo).max() / cell)) + 2
    centre = (lo + hi) / 2
    rows, cols = np.nonzero(fill_polygon(room.outline, size, cell, centre))
    xs, ys = pixel_centres(size, cell, centre)
    pick = rng.integers(len(rows), size=len(room.object_ids)) if len(rows) else np.zeros(len(room.object_ids), int)
    xy = np.stack([xs[cols[pick]], ys[rows[pick]]], -1) if len(rows) else room.boxes[:, :2]
    return _moved(room, xy, rng.integers(4, size=len(room.object_ids)) * np.pi / 2)


def perturbed(rooms: list[RoomInput], kind: str, strength: float, copies: int, seed: int) -> list[RoomInput]:
    """``copies`` perturbed versions of each room (room-major: copies of one room are neighbours), seeded."""
    rng = rng_for(seed, "perturb", KINDS.index(kind), int(round(strength * 1000)))
    make = {"jitter": lambda r: jitter(r, strength, rng), "turns": lambda r: turns(r, rng),
            "shuffle": lambda r: shuffle(r, rng), "placement": lambda r: placement(r, rng)}[kind]
    return [replace(make(r), room_id=f"{r.room_id}~{kind}{k}") for r in rooms for k in range(copies)]
