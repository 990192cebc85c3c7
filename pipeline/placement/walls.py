"""Which objects stand with their back to the wall they stand against, learned from the training rooms: a desk in a
room's corner stands against two walls, its back to one and its side to the other, so a plan's "adjacent to this
wall" edge does not say which way the desk turns, and a location network or a relative-pose density drawn near a
corner turns it either way. Per category, the share of the training rooms' floor objects standing square against a
wall (some side within ``gap`` m of it, turned within ``angle`` rad) whose back is the side against a wall, by the
evaluation's own predicate (:func:`~pipeline.geometry.function.back_to_wall`)."""
from __future__ import annotations

from itertools import combinations

import numpy as np

from ..geometry.boxes import diagonal_2d, on_floor
from ..geometry.function import back_to_wall
from ..geometry.relations import DistanceBands, distance_thresholds
from ..room import RoomInput, Walls

PARALLEL_COS = 0.999  # two walls whose inner normals' dot product is below minus this face each other (2.6 degrees)


def wall_stands(rooms: list[RoomInput], gap: float, angle: float, floor_contact: float) -> dict[str, list[int]]:
    """category -> per training floor object, 0 (not against a wall), 1 (against one, another side to it) or 2
    (against one, its back to it)."""
    stands: dict[str, list[int]] = {}
    for room in rooms:
        b = room.boxes.reshape(-1, 7)
        floor = np.flatnonzero(on_floor(b, floor_contact))
        if not len(floor):
            continue
        near = back_to_wall(b[floor], room.outline, gap, angle, ["rotational-4"] * len(floor))  # any side
        back = back_to_wall(b[floor], room.outline, gap, angle)
        for k, stand in zip(floor, near.astype(int) + (near & back).astype(int)):
            stands.setdefault(room.categories[k], []).append(int(stand))
    return stands


def learn_wall_backs(rooms: list[RoomInput], gap: float, angle: float, min_pairs: int,
                     floor_contact: float) -> dict[str, float]:
    """category -> the share of its training floor objects against a wall that have their back to a wall (only
    categories with at least ``min_pairs`` such objects and a positive share)."""
    against = {c: [s == 2 for s in v if s] for c, v in wall_stands(rooms, gap, angle, floor_contact).items()}
    shares = {c: round(float(np.mean(flags)), 3) for c, flags in sorted(against.items()) if len(flags) >= min_pairs}
    return {c: s for c, s in shares.items() if s > 0}


def learn_wall_bound(rooms: list[RoomInput], gap: float, angle: float, share: float, min_pairs: int,
                     floor_contact: float) -> frozenset[str]:
    """The categories whose training floor objects stand against a wall at least ``share`` of the time (at least
    ``min_pairs`` objects; ``share`` 0: none): the search never breaks such an object's planned wall adjacency."""
    if share <= 0:
        return frozenset()
    stands = wall_stands(rooms, gap, angle, floor_contact)
    return frozenset(c for c, v in stands.items() if len(v) >= min_pairs and np.mean(np.asarray(v) > 0) >= share)


def unspanned(walls: Walls, wall_ids: list[str], halves: np.ndarray, distance: dict,
              margin: float) -> tuple[str, str, float] | None:
    """Two of ``wall_ids`` that face each other too far apart (or too near) for any footprint of half extents ``halves
    (k, 2)`` to be adjacent to both, turned any way: its extent across them lies between its smaller side and its
    diagonal, and must reach within extraction's adjacent gap (``distance``: ``extract.distance``) of each face without
    crossing them by more than ``margin`` m each. Returns (wall, wall, distance m) of the first such pair, else None:
    a wall-bound object planned so fails whatever the search draws."""
    halves = np.asarray(halves, float).reshape(-1, 2)
    longest = diagonal_2d(halves[:, 0], halves[:, 1])
    shortest = 2 * halves.min(1)
    adjacent = distance_thresholds(longest, DistanceBands.of(distance))[0]
    index = [walls.ids.index(w) for w in wall_ids if w in walls.ids]
    for i, j in combinations(index, 2):
        if walls.normal[i] @ walls.normal[j] > -PARALLEL_COS:
            continue
        apart = float((walls.a[j] - walls.a[i]) @ walls.normal[i])
        if not ((longest >= apart - 2 * adjacent) & (shortest <= apart + 2 * margin)).any():
            return walls.ids[i], walls.ids[j], apart
    return None
