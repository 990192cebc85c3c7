"""Energy terms over a solver state. Hard constraints are counted as violations (a move that adds one is rejected):
collisions (the box penetration depth of ``geometry.boxes``, the first test of PlanIT's placement check),
footprints outside the floor (``geometry.polygon.outside_area``, the check's and the evaluation's test), door
clearances (``placement.checks.blocks_door``'s zones) and overhangs (``placement.checks.support_share``). Soft terms
are weighted scores (:class:`Term`); those of Infinigen's operators live in ``operators``."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import shapely

from ...geometry import boxes as gb
from ...geometry.function import footprint_gaps
from ...geometry.polygon import outside_area
from ...placement.checks import AREA_EPS, required_support, support_shares
from ...room import door_zones_of
from .state import State

HARD = ("collision", "outside", "door", "overhang")


@dataclass(frozen=True)
class Term:
    """A weighted soft term: ``fn(state)`` is a non-negative score."""
    name: str
    weight: float
    fn: Callable[[State], float]


@dataclass(frozen=True)
class Limits:
    """The hard constraints' thresholds (from ``instantiate.checks``: the same margins PlanIT's search uses)."""
    collision: float  # m of penetration allowed
    outside: float  # m the footprint is eroded by before the outside test
    door: float  # m: depth of the clearance zone inside each door
    min_support: float  # share of a supported footprint that must rest on its parent
    support_floor: dict[str, float] = field(default_factory=dict)  # category -> a lower share learned from training rooms

    def support(self, categories: list[str]) -> np.ndarray:
        """``(n,)`` the share each category must keep over its parent: PlanIT's check's
        (:meth:`~pipeline.placement.checks.Checker.min_support`: ``min_support``, lowered by the learned floor)."""
        return np.array([required_support(self.min_support, self.support_floor, c) for c in categories], float)


def footprints(b: np.ndarray) -> np.ndarray:
    """``(n, 4, 2)`` footprint corners of ``(n, 7)`` boxes."""
    return gb.footprint_corners(b[:, 0], b[:, 1], b[:, 3], b[:, 4], b[:, 6])


def related_mask(state: State) -> np.ndarray:
    """``(n, n)`` True for support parent-child pairs (their contact is no collision)."""
    n = len(state.items)
    rel = np.eye(n, dtype=bool)
    for k, it in enumerate(state.items):
        if it.parent >= 0:
            rel[k, it.parent] = rel[it.parent, k] = True
    return rel


def colliding_pairs(state: State, limit: float) -> np.ndarray:
    """``(m, 2)`` index pairs ``(i, j)``, ``i < j``, that penetrate deeper than ``limit`` m, not parent and child, in
    row-major order."""
    depth = gb.penetration_depths(state.boxes)
    return np.argwhere(np.triu((depth > limit) & ~related_mask(state), 1))


class Hard:
    """A state's hard violations; the room's door zones are built once."""

    def __init__(self, state: State, limits: Limits):
        self.limits = limits
        quads = door_zones_of(state.room, limits.door)
        self.zones = shapely.union_all(shapely.polygons(quads)) if len(quads) else None

    def total(self, state: State) -> int:
        return sum(self.counts(state).values())

    def counts(self, state: State) -> dict[str, int]:
        """Violations per hard constraint (colliding pairs; objects outside, in a door zone, overhanging)."""
        return {kind: len(ks) for kind, ks in self.offenders(state).items()}

    def offenders(self, state: State) -> dict[str, list[int]]:
        """Per hard constraint, the items in violation: the later item of each colliding pair (one entry per pair),
        the grounded items outside the floor or in a door's clearance zone, the supported items overhanging."""
        if not state.items:
            return {kind: [] for kind in HARD}
        grounded = np.array([k for k, it in enumerate(state.items) if it.parent < 0], int)
        corners = footprints(state.boxes[grounded])
        outside, door = np.zeros(len(grounded), bool), np.zeros(len(grounded), bool)
        if len(corners):
            outside = outside_area(state.room.outline, corners, self.limits.outside) > AREA_EPS
            if self.zones is not None:
                door = shapely.area(shapely.intersection(shapely.polygons(corners), self.zones)) > AREA_EPS
        on = np.array([k for k, it in enumerate(state.items) if it.parent >= 0], int)
        parents = np.array([state.items[k].parent for k in on], int)
        need = self.limits.support([state.items[k].category for k in on])
        over: np.ndarray | list[bool] = support_shares(state.boxes[on], state.boxes[parents]) < need if len(on) else []
        return {"collision": colliding_pairs(state, self.limits.collision)[:, 1].tolist(),
                "outside": grounded[outside].tolist(), "door": grounded[door].tolist(),
                "overhang": on[np.asarray(over, bool)].tolist()}


class Energy:
    """A state's violation count and weighted energy, with each part for the trace."""

    def __init__(self, hard: Hard, terms: list[Term]):
        self.hard, self.terms = hard, [t for t in terms if t.weight > 0]

    def __call__(self, state: State) -> tuple[int, float, dict]:
        counts = self.hard.counts(state)
        parts = {t.name: t.weight * t.fn(state) for t in self.terms}
        return sum(counts.values()), float(sum(parts.values())), {**counts, **parts}


def gaps(state: State, i: int, js: list[int]) -> np.ndarray:
    """``(len(js),)`` m between item ``i``'s footprint and each of ``js``' (0 where they touch or overlap)."""
    return footprint_gaps(state.boxes[i], state.boxes[js])[0]


def front_of(box: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The front face's midpoint ``(2,)`` and outward normal ``(2,)`` of a box ``(7,)``."""
    normal = gb.rotation(box[6]) @ np.array([0.0, 1.0])
    return box[:2] + normal * box[4], normal
