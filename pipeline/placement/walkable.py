"""A floor object may not close the floor off from the door: the least door-connected share of the free floor the
training rooms keep (the evaluation's walkability measure, :mod:`pipeline.room.walkability`), and the check that
refuses a floor object leaving a room below it. PlanIT's search checks a door's clearance only; a sofa and an
armchair can each keep it and together wall a pocket of the floor off from the door (docs/departures.md)."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..room import RoomInput, door_segments
from ..room.walkability import Walk, walkable_share


def learn_walkable_floor(rooms: list[RoomInput], walk: Walk, quantile: float) -> float:
    """The ``quantile`` of the walkable shares of the training ``rooms`` that have a door; 0 (no check) when none has
    (AI2-THOR's rooms: the share would only say how whole the floor is, and such rooms keep 99% of it whole)."""
    shares = [walkable_share(r, walk) for r in rooms if len(r.outline) >= 3 and len(door_segments(r))]
    return round(float(np.quantile(shares, quantile)), 3) if shares else 0.0


@dataclass(frozen=True)
class FloorKept:
    """The check: ``least`` walkable share a floor object may leave by the ``walk`` measure, and how much lower than
    without it (``tolerance``) a room already under it may go."""
    walk: Walk
    least: float
    tolerance: float

    @classmethod
    def learn(cls, rooms: list[RoomInput], walk: Mapping[str, Any], cfg: Mapping[str, Any]) -> "FloorKept | None":
        """From the training ``rooms``, the ``evaluate.walk`` settings and ``instantiate.checks.walkable`` (None when
        disabled or nothing is learned)."""
        measure = Walk.of(walk)
        least = learn_walkable_floor(rooms, measure, cfg["quantile"]) if cfg["enabled"] else 0.0
        return cls(measure, least, float(cfg["tolerance"])) if least > 0 else None

    def closes(self, room: RoomInput, k: int) -> tuple[float, float] | None:
        """``(share before, share after)`` when floor object ``k`` of ``room`` leaves the walkable share under
        ``least`` and more than ``tolerance`` under what it was without the object; else None (a room already under
        ``least`` may still take objects that do not make it worse; a room with no door is not checked)."""
        if not len(door_segments(room)):
            return None
        after = walkable_share(room, self.walk)
        if after >= self.least:
            return None
        before = walkable_share(replace(room, boxes=np.delete(room.boxes, k, axis=0)), self.walk)
        return (before, after) if after < before - self.tolerance else None
