"""How objects standing on a support are turned relative to it, learned from the training rooms.

PlanIT's orientation network draws an object's turn on a 5-degree grid, square to the nearest wall with its snap
probability, else more than the snap angle off the walls' axes. On a support that spreads farther than the training
rooms do: a default run's PlanIT offices turned 10% of their monitors 10-12 degrees off their desk (one by 124), where
no training monitor stands more than 9.7 degrees off its desk's turn; at a metre, 10 degrees moves the monitor's front
0.17 m off the office chair facing it, and 4 of 5 failing rooms failed "the chair faces its monitor" so
(docs/benchmarks.md). Per (support category, object category), the quarter turns of the support the training pairs
stand at (in at least ``min_share`` of them) and each quarter's residual turns: the search keeps the drawn turn's
nearest such quarter and adds one of its residuals (:class:`~pipeline.placement.proposers.TurnedOnSupport`)."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..geometry.frames import wrap
from ..room import RoomInput
from .support import support_pairs

QUARTER = np.pi / 2


class SupportTurn(NamedTuple):
    """The quarter turns (0-3, counter-clockwise from the support's front) one (support category, object category)'s
    training pairs stand at, and per quarter the pairs' residual turns from it (rad, within 45 degrees)."""

    quarters: tuple[int, ...]
    residuals: tuple[tuple[float, ...], ...]


def relative_turns(rooms: list[RoomInput], tolerance: float, floor_contact: float) -> dict[tuple[str, str], list[float]]:
    """(support category, object category) -> the training objects' turns relative to their support (rad, wrapped)."""
    seen: dict[tuple[str, str], list[float]] = {}
    for room in rooms:
        b, cats = room.boxes.reshape(-1, 7), room.categories
        for k, j, _ in support_pairs(room, tolerance, floor_contact):
            seen.setdefault((cats[j], cats[k]), []).append(float(wrap(b[k, 6] - b[j, 6])))
    return seen


def learn_support_turns(rooms: list[RoomInput], tolerance: float, floor_contact: float, min_pairs: int,
                        min_share: float) -> dict[tuple[str, str], SupportTurn]:
    """(support category, object category) -> :class:`SupportTurn`, for pairs of categories seen at least
    ``min_pairs`` times; a quarter counts where at least ``min_share`` of the pairs stand at it."""
    rules = {}
    for pair, turns in sorted(relative_turns(rooms, tolerance, floor_contact).items()):
        if len(turns) < min_pairs:
            continue
        t = np.asarray(turns)
        quarter = np.round(t / QUARTER).astype(int) % 4
        residual = wrap(t - quarter * QUARTER)
        kept = [q for q in range(4) if np.mean(quarter == q) >= min_share]
        if kept:
            rules[pair] = SupportTurn(tuple(kept), tuple(tuple(np.round(residual[quarter == q], 4).tolist())
                                                         for q in kept))
    return rules
