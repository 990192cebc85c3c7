"""The annealer's moves (Infinigen section 3.3; S-AOG section 5): translate and rotate inside an object's degrees of
freedom, move it to another wall, swap two objects' places, add or delete an object within its count range,
resample its model, or start its pose afresh. Each returns a new realised state, or None when the move does not
apply."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...geometry.polygon import poke_out
from ...placement.retrieval import ModelPool
from .state import Item, State, top_range, wall_range

MOVES = ("translate", "rotate", "replane", "swap", "add", "delete", "resample", "reinit")


@dataclass(frozen=True)
class Spec:
    """What may be placed of one category: its count range, solving stage, degrees of freedom and support parent
    category (``dof`` on)."""
    category: str
    count: tuple[int, int]
    stage: str
    dof: str  # floor | wall | on
    parent: str | None = None
    symmetry: str = "none"
    beside: str | None = None  # a category whose side it stands against (Infinigen's relation plane of next_to)


@dataclass(frozen=True)
class Steps:
    """Step sizes: translation ``sigma = clip(scale * T, least, most)`` m, rotation ``sigma = pi T`` rounded to
    ``quantum`` rad (0: continuous)."""
    scale: float
    least: float
    most: float
    quantum: float


class Proposer:
    """Draws moves for the items of one stage (``active``: the categories being solved)."""

    def __init__(self, specs: dict[str, Spec], pool: ModelPool, steps: Steps, prefix: str = "obj",
                 violations=None, attempts: int = 1, pick=None):
        self.specs, self.pool, self.steps, self.prefix = specs, pool, steps, prefix
        self.pick = pick  # pick(spec, rng) -> Instance for new objects (default: a random training instance)
        self.violations, self.attempts = violations, attempts  # a new pose is drawn up to `attempts` times
        self.made = 0

    def propose(self, state: State, kind: str, active: set[str], temp: float, rng: np.random.Generator):
        movable = [k for k, it in enumerate(state.items) if it.category in active]
        if kind == "add":
            return self.add(state, active, rng)
        if not movable:
            return None
        k = int(rng.choice(movable))
        if kind == "swap":
            return self.swap(state, k, movable, rng)
        if kind == "delete":
            return self.delete(state, k)
        it = state.items[k]
        new = {"translate": self.translate, "rotate": self.rotate, "replane": self.replane,
               "resample": self.resample, "reinit": self.reinit}[kind](state, it, temp, rng)
        return None if new is None else state.with_items([*state.items[:k], new, *state.items[k + 1:]])

    def translate(self, state: State, it: Item, temp: float, rng) -> Item:
        s = self.steps
        sigma = float(np.clip(s.scale * temp, s.least, s.most))
        if it.dof == "wall":
            lo, hi = wall_range(state.walls, it.wall, it.inst)
            return replace(it, u=(float(np.clip(it.u[0] + rng.normal(0, sigma), lo, hi)), 0.0))
        u = np.asarray(it.u) + rng.normal(0, sigma, 2)
        if it.dof == "on":
            lim = top_range(state.items[it.parent].inst, it.inst, it.yaw)
            u = np.clip(u, -lim, lim)
        return replace(it, u=(float(u[0]), float(u[1])))

    def rotate(self, state: State, it: Item, temp: float, rng) -> Item | None:
        if it.dof == "wall":
            return None
        turn = rng.normal(0, np.pi * temp)
        q = self.steps.quantum
        turn = q * np.round(turn / q) if q > 0 else turn
        if it.dof == "on":
            turn = np.pi / 2 * np.round(turn / (np.pi / 2))  # keeps the footprint inside the parent's top range
        return None if turn == 0 else replace(it, yaw=float(it.yaw + turn))

    def replane(self, state: State, it: Item, temp: float, rng) -> Item | None:
        """Another wall for a wall object (Infinigen's relation-plane change), at the same share of its length."""
        if it.dof != "wall" or len(state.walls.ids) < 2:
            return None
        w = int(rng.choice([j for j in range(len(state.walls.ids)) if j != it.wall]))
        lo, hi = wall_range(state.walls, it.wall, it.inst)
        share = (it.u[0] - lo) / max(hi - lo, 1e-9)
        lo2, hi2 = wall_range(state.walls, w, it.inst)
        return replace(it, wall=w, u=(float(lo2 + share * (hi2 - lo2)), 0.0))

    def swap(self, state: State, k: int, movable: list[int], rng) -> State | None:
        """Two objects of different categories with the same degrees of freedom trade places."""
        a = state.items[k]
        others = [j for j in movable if state.items[j].category != a.category and state.items[j].dof == a.dof
                  and a.dof != "on"]
        if not others:
            return None
        j = int(rng.choice(others))
        b = state.items[j]
        items = list(state.items)
        items[k], items[j] = replace(a, u=b.u, yaw=b.yaw, wall=b.wall), replace(b, u=a.u, yaw=a.yaw, wall=a.wall)
        return state.with_items(items)

    def instance(self, spec: Spec, rng):
        if self.pick is not None:
            return self.pick(spec, rng)
        return self.pool.pick(spec.category, spec.symmetry, rng, spec.dof != "on")

    def resample(self, state: State, it: Item, temp: float, rng) -> Item:
        return replace(it, inst=self.instance(self.specs[it.category], rng))

    def reinit(self, state: State, it: Item, temp: float, rng) -> Item | None:
        return self.fresh(state, self.specs[it.category], rng, it)

    def add(self, state: State, active: set[str], rng) -> State | None:
        room = [c for c in sorted(active) if state.count(c) < self.specs[c].count[1]]
        if not room:
            return None
        it = self.fresh(state, self.specs[room[int(rng.integers(len(room)))]], rng)
        return None if it is None else state.with_items([*state.items, it])

    def delete(self, state: State, k: int) -> State | None:
        """Remove item ``k`` (within its count range) and what stands on it."""
        if state.count(state.items[k].category) <= self.specs[state.items[k].category].count[0]:
            return None
        return state.with_items(drop_items(state.items, k))

    def fresh(self, state: State, spec: Spec, rng, old: Item | None = None) -> Item | None:
        """A new item of ``spec`` (or ``old`` with a new pose): up to ``attempts`` random poses of its degrees of
        freedom (beside its ``beside`` category half the time), the first that adds no hard violation (Infinigen's
        20 attempts to find a pose)."""
        inst = old.inst if old is not None else self.instance(spec, rng)
        if old is None:
            self.made += 1
        oid = old.object_id if old is not None else f"{self.prefix}_{self.made:03d}_{spec.category}"
        base = Item(oid, spec.category, inst, spec.dof, spec.stage, (0.0, 0.0))
        rest = [it for it in state.items if it.object_id != oid]
        before = None if self.violations is None else self.violations(state if old is None else state.with_items(rest))
        it = None
        for _ in range(self.attempts):
            it = self.pose(state, spec, base, rng, old)
            if it is None or before is None or self.violations(state.with_items([*rest, it])) <= before:
                return it
        return it

    def pose(self, state: State, spec: Spec, base: Item, rng, old: Item | None) -> Item | None:
        """A random pose of ``base`` in its degrees of freedom."""
        if spec.dof == "on":
            parents = [old.parent] if old is not None else [j for j, p in enumerate(state.items) if p.category == spec.parent]
            if not parents:
                return None
            j = int(rng.choice(parents))
            lim = top_range(state.items[j].inst, base.inst)
            return replace(base, parent=j, u=tuple(float(v) for v in rng.uniform(-lim, lim)))
        anchors = [a for a in state.items if a.category == spec.beside and a.dof == spec.dof and a.parent < 0]
        if anchors and rng.random() < 0.5:
            return beside(base, anchors[int(rng.integers(len(anchors)))], rng)
        if spec.dof == "wall":
            w = int(rng.integers(len(state.walls.ids)))
            lo, hi = wall_range(state.walls, w, base.inst)
            return replace(base, wall=w, u=(float(rng.uniform(lo, hi)), 0.0))
        return replace(base, u=random_floor_point(state, rng), yaw=float(rng.integers(4) * np.pi / 2))


def beside(it: Item, anchor: Item, rng: np.random.Generator) -> Item:
    """``it`` flush against the left or right side of ``anchor``, facing the same way (same wall for wall items)."""
    side = float(rng.choice([-1.0, 1.0])) * (anchor.inst.half[0] + it.inst.half[0])
    if it.dof == "wall":
        return replace(it, wall=anchor.wall, u=(anchor.u[0] + side, 0.0))
    c, s = np.cos(anchor.yaw), np.sin(anchor.yaw)
    return replace(it, u=(anchor.u[0] + c * side, anchor.u[1] + s * side), yaw=anchor.yaw)


def random_floor_point(state: State, rng: np.random.Generator, tries: int = 50) -> tuple[float, float]:
    """A uniform point inside the room's outline (rejection sampling in its bounding box)."""
    lo, hi = state.room.outline.min(0), state.room.outline.max(0)
    pts = rng.uniform(lo, hi, (tries, 2))
    inside = np.flatnonzero(poke_out(state.room.outline, pts) <= 0)
    p = pts[inside[0]] if len(inside) else (lo + hi) / 2
    return float(p[0]), float(p[1])


def drop_items(items: list[Item], k: int) -> list[Item]:
    """The items without ``k`` and its descendants, parent indices renumbered."""
    gone = {k}
    for j, it in enumerate(items):
        if it.parent in gone:
            gone.add(j)
    keep = [j for j in range(len(items)) if j not in gone]
    index = {j: n for n, j in enumerate(keep)}
    return [replace(items[j], parent=index[items[j].parent] if items[j].parent >= 0 else -1) for j in keep]
