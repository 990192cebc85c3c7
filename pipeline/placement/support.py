"""How far a supported object may overhang its support, learned from the training rooms: PlanIT's check asks every
supported object to keep ``checks.min_support`` (0.9) of its footprint over its support, but real rooms hold
televisions wider than their stands and plants wider than their shelves. Per category, the share a training room
shows at its low end (the ``quantile`` of the shares seen, over at least ``min_pairs`` supported objects) lowers the
check for that category, never raises it, and never below ``least`` (0.5: half the footprint over the support)
(docs/departures.md).

A training object's support is geometric: the object whose box top lies within ``tolerance`` m of its bottom and
whose footprint holds the most of it; the share is the check's own :func:`~pipeline.placement.checks.support_share`."""
from __future__ import annotations

import numpy as np

from ..room import RoomInput
from .checks import support_share


def supported_shares(room: RoomInput, tolerance: float, floor_contact: float) -> list[tuple[str, float]]:
    """(category, share of its footprint over its support) for every object of the room standing on another."""
    b = room.boxes.reshape(-1, 7)
    bottom, top = b[:, 2] - b[:, 5], b[:, 2] + b[:, 5]
    out = []
    for k in np.flatnonzero(bottom > floor_contact):
        below = np.flatnonzero((np.abs(top - bottom[k]) <= tolerance) & (np.arange(len(b)) != k))
        shares = [support_share(b[k], b[j]) for j in below]
        if shares and max(shares) > 0:
            out.append((room.categories[k], max(shares)))
    return out


def learn_support_floor(rooms: list[RoomInput], cfg: dict, floor_contact: float) -> dict[str, float]:
    """Category -> the lowest support share the check accepts for it, where the training rooms show one below
    ``min_support`` (``cfg``: the ``instantiate.checks`` section; its ``learned_support`` settings)."""
    learned = cfg["learned_support"]
    if not learned["enabled"]:
        return {}
    seen: dict[str, list[float]] = {}
    for room in rooms:
        for category, share in supported_shares(room, learned["tolerance"], floor_contact):
            seen.setdefault(category, []).append(share)
    floor = {c: max(float(np.quantile(s, learned["quantile"])), learned["least"])
             for c, s in seen.items() if len(s) >= learned["min_pairs"]}
    return {c: round(f, 3) for c, f in sorted(floor.items()) if f < cfg["min_support"]}
