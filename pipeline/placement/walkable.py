"""A floor object may not close the floor off from the door: the least door-connected share of the free floor the
training rooms keep (the evaluation's walkability measure, :mod:`pipeline.room.walkability`), and the check that
refuses a floor object leaving a room below it. PlanIT's search checks a door's clearance only; a sofa and an
armchair can each keep it and together wall a pocket of the floor off from the door (docs/departures.md)."""
from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from ..room import RoomInput
from ..room.walkability import walkable_share


def learn_walkable_floor(rooms: list[RoomInput], walk: dict[str, Any], cfg: dict[str, Any]) -> float:
    """The ``cfg["quantile"]`` of the training ``rooms``' walkable shares (``walk``: the ``evaluate.walk``
    settings; ``cfg``: ``instantiate.checks.walkable``); 0 (no check) when disabled or no room has a floor."""
    if not cfg["enabled"] or not rooms:
        return 0.0
    shares = [walkable_share(r, walk) for r in rooms if len(r.outline) >= 3]
    return round(float(np.quantile(shares, cfg["quantile"])), 3) if shares else 0.0


def closes_floor(room: RoomInput, k: int, floor: float, walk: dict[str, Any], tolerance: float) -> tuple[float, float] | None:
    """``(share before, share after)`` when floor object ``k`` of ``room`` leaves the door-connected share of the free
    floor under ``floor`` and more than ``tolerance`` under what it was without the object; else None (a room
    already under ``floor`` may still take objects that do not make it worse)."""
    if floor <= 0:
        return None
    after = walkable_share(room, walk)
    if after >= floor:
        return None
    before = walkable_share(replace(room, boxes=np.delete(room.boxes, k, axis=0)), walk)
    return (before, after) if after < before - tolerance else None
