"""Pose rules learned from the training rooms and applied by the search to a floor object's orientation where its plan
puts it beside an anchor: how a target of one category turns relative to an anchor of another on each side of it
(a desk chair in front of its desk faces it: half a turn; a nightstand beside a bed turns with the bed: none).
PlanIT's orientation network sees the location only, not the planned relation; these rules carry the relation
(docs/departures.md). A rule "back to the wall it is planned against" was tried and dropped: on 20 sampled bedroom
graphs it turned beds against the wrong wall of a corner and placed fewer against any (docs/benchmarks.md).

A rule is kept when the Wilson 95% lower bound of its share of the training pairs is at least ``min_share``, over at
least ``min_pairs`` pairs. The side is geometric (:func:`pipeline.geometry.function.sides` of the target's centre), in
training and in the search alike, so symmetric anchors whose edge labels fold their sides are read the same way."""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from ..geometry.boxes import SIDES
from ..geometry.function import plan_gaps, sides
from ..room import RoomInput
from ..room.contents import wilson_lower

QUARTER = np.pi / 2
DISTANCES = ("adjacent", "proximal", "distant")


@dataclass
class PoseRules:
    """``turns``: (anchor category, target category, side index) -> quarter turns of the target's yaw from the
    anchor's."""
    turns: dict = field(default_factory=dict)

    def yaw(self, room: RoomInput, category: str, anchors: list, xy: np.ndarray) -> float | None:
        """The yaw (rad) the rules give an object of ``category`` centred at ``xy (2,)``: its first object anchor's
        rule (:class:`~pipeline.placement.search.Anchor`, the nearest planned distance first); None when no rule
        applies."""
        for a in sorted(anchors, key=lambda a: DISTANCES.index(a.distance) if a.distance in DISTANCES else 3):
            if a.obj is None:
                continue
            box = room.boxes[a.obj]
            side = int(sides(np.stack([box, [*xy, 0.0, 0.0, 0.0, 0.0, 0.0]]))[0, 1])
            turn = self.turns.get((room.categories[a.obj], category, side))
            if turn is not None:
                return float(box[6] + turn * QUARTER)
        return None


def quarter_turns(rel: np.ndarray, max_error: float) -> np.ndarray:
    """Yaw differences ``rel`` (rad) as quarter turns 0..3, -1 where more than ``max_error`` rad off every one."""
    k = np.round(np.asarray(rel) / QUARTER)
    off = np.abs(np.angle(np.exp(1j * (np.asarray(rel) - k * QUARTER))))
    return np.where(off <= max_error, np.mod(k, 4), -1).astype(int)


def turn_tally(rooms: list[RoomInput], near_gap: float, max_error: float) -> dict:
    """(anchor category, target category, side) -> the quarter turns of every training pair whose target stands
    beyond that side within ``near_gap`` m (footprint gap)."""
    tally: dict = {}
    for room in rooms:
        b = room.boxes.reshape(-1, 7)
        side, gap = sides(b), plan_gaps(b)
        turns = quarter_turns(b[None, :, 6] - b[:, None, 6], max_error)
        for i, j in zip(*np.nonzero((side >= 0) & (gap <= near_gap))):
            tally.setdefault((room.categories[i], room.categories[j], int(side[i, j])), []).append(int(turns[i, j]))
    return tally


def confident(outcomes: list, cfg: dict):
    """The most frequent outcome of ``outcomes`` when it is confidently frequent enough, else None."""
    if len(outcomes) < cfg["min_pairs"]:
        return None
    value, count = Counter(outcomes).most_common(1)[0]
    return value if wilson_lower(count, len(outcomes)) >= cfg["min_share"] else None


def learn_pose_rules(rooms: list[RoomInput], cfg: dict) -> PoseRules:
    """The rules the training ``rooms`` hold with confidence (``cfg``: the ``instantiate.pose_rules`` section)."""
    tally = turn_tally(rooms, cfg["near_gap"], np.radians(cfg["max_angle"]))
    turns = {key: t for key, ks in tally.items() if (t := confident(ks, cfg)) is not None and t >= 0}
    return PoseRules(turns)


def describe(rules: PoseRules) -> list[str]:
    """One line per rule, for the log."""
    return [f"{t} beyond the {SIDES[s]} of {a}: turned {k * 90} deg from it" for (a, t, s), k in sorted(rules.turns.items())]
