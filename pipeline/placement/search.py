"""Placing a planned graph's objects one at a time with backtracking (PlanIT section 6, Appendix B).

Each object asks the proposer for a pose (:class:`~pipeline.placement.proposers.Request`): a centre among the allowed
candidates (the floor or its support's top, off what stands there, outside the squares around its rejected points) and a
yaw, conditioned on its anchors (every planned edge to what is already placed); it slides flush against the anchors it
must be adjacent to, then must pass :func:`~pipeline.placement.checks.check`. After its sample budget, the search
backtracks to the nearest earlier object that caused one of its failures (or the one before it) and that object is
placed afresh elsewhere, within a backtrack budget of ``backtracks_per_object`` per object to place (at least
``max_backtracks``; PlanIT: a fixed 25, which fails large graphs far more often than small ones). The relation tolerance
is 0 until an object has failed ``relax.start`` times (``per_object``; PlanIT: until the scene has spent a quarter of
its backtracks), then grows as ``((f - start) / (full - start)) ** 1.5`` up to ``relax.max``; an object accepted with a
broken relation is recorded with the edges it broke and why (:attr:`Outcome.relaxed`). A rejected point's square is
sized to the object (``per_object``: a share of its smaller half extent, growing with its failures; PlanIT: 0.6 m
growing with the scene's backtracks). With ``keep_relations``, a candidate that breaks some of its relations within that
tolerance is kept only when the object's remaining samples find none that keeps them all (the cheapest such candidate is
taken). With ``early_backtrack``, an object at zero tolerance whose planned bands share no free cell backtracks at once
instead of spending its samples. With ``lookahead`` (forward checking), a candidate that leaves a later floor object
it is planned to relate to no free cell in every band of that object's placed anchors is refused (at zero tolerance
only, or ``always``). A scene fails, with its reason, when the backtrack or candidate budget runs out (or the
time budget, a safety net: the one outcome a machine's speed can change), or an object's category has no training
instance; with ``on_exhausted: drop``, such an object is left out instead (with the objects it supports) and the search
goes on. A scene whose backtrack budget runs out starts over from scratch with a fresh seed, at most ``restarts`` times
(each attempt with its own budgets); its counts add up over the attempts. With ``redraw``, an object that spends its
samples draws another training instance of its category (shared with its hub's spokes or its chain's members from then
on): models are drawn at random, not by a predicted size, and a size that cannot fit is not forced on the object again.
"""
from __future__ import annotations

import logging
import time
from collections import Counter
from dataclasses import dataclass, field, replace
from functools import partial
from typing import NamedTuple, Protocol

import numpy as np

from ..geometry.boxes import SIDE_NORMALS, SIDES, footprint_corners, rotation
from ..geometry.relations import in_footprint
from ..room import RoomInput, Walls
from .anchors import Anchor, anchors_of, planned_edges
from .checks import Checker, check, fits_on
from .layout import add_object, walls_of, with_objects
from .order import chains
from .plan import ScenePlan
from .proposers import Grid, RelationPrior, Request, gap_thresholds
from .retrieval import ModelPool, place
from .walls import unspanned

log = logging.getLogger("planit.instantiate")


class Proposer(Protocol):
    def pose(self, req: Request, rng: np.random.Generator) -> tuple[np.ndarray, float] | None:
        """A centre ``(2,)`` among ``req``'s allowed candidates and a yaw (rad), or None when none has mass."""


@dataclass
class Outcome:
    """A scene's search: its status, the room it reached, and the counts of PlanIT's Table 3."""
    ok: bool
    room: RoomInput
    reason: str = ""
    seconds: float = 0.0
    insertions: int = 0  # accepted placements, the ones undone by backtracking included
    rejections: int = 0
    backtracks: int = 0
    failures: dict = field(default_factory=dict)  # reason kind -> count
    dropped: list = field(default_factory=list)  # plan ids left out (on_exhausted: drop), in the order dropped
    drops: list = field(default_factory=list)  # per dropped id: its category, cause and (no_place) the check that refused it most
    attempts: int = 1  # searches from scratch (1 + restarts used)
    accepted: dict = field(default_factory=dict)  # PlanEdge -> its cost when the later of its two ends was placed
    relaxed: list = field(default_factory=list)  # per object accepted with a broken relation: what it broke and why

    @property
    def status(self) -> str:
        return "failed" if not self.ok else "partial" if self.dropped else "placed"


DROP_CAUSES = {"no_place": "no place once the backtrack budget was spent", "no_model": "no training instance",
               "no_span": "planned against two facing walls no instance spans", "support_dropped": "support dropped"}


def side_plane(a: Anchor, room: RoomInput) -> tuple[np.ndarray, np.ndarray]:
    """Point on and outward normal of the anchor's side named by its edge direction (world)."""
    if a.wall is not None:
        return np.array(a.frame.origin), rotation(a.frame.yaw) @ SIDE_NORMALS[0]
    b = room.boxes[a.obj]
    s = SIDES.index(a.direction)
    normal = rotation(b[6]) @ SIDE_NORMALS[s]
    return b[:2] + normal * (b[4] if s < 2 else b[3]), normal


def snap(box: np.ndarray, anchors: list[Anchor], room: RoomInput, walls: Walls, extract: dict, cfg: dict) -> np.ndarray:
    """Slide ``box (7,)`` along the normal of each anchor side it is planned adjacent or proximal to (walls first)
    until its footprint's gap to the side is where extraction finds that label: ``cfg['gap']`` m for adjacent, for
    proximal inside the extraction's proximal band (:func:`~pipeline.placement.proposers.gap_thresholds`) by
    ``cfg['margin']`` m at both ends; only when the slide is under ``cfg['reach']`` m and the box is on the side's
    outer half-space (or across a wall). ``cfg``: the ``instantiate.snap`` section (``enabled``: else no slide)."""
    box = box.copy()
    if not cfg["enabled"]:
        return box
    reach = cfg["reach"]
    spatial = (a for a in anchors if a.kind == "spatial" and not a.reverse and a.distance in ("adjacent", "proximal"))
    for a in sorted(spatial, key=lambda a: a.wall is None):
        point, normal = side_plane(a, room)
        d = float(((footprint_corners(*box[[0, 1, 3, 4, 6]])[0] - point) @ normal).min())
        adj, prox = gap_thresholds(replace(a, target_half=tuple(box[3:5])), room, walls, extract)
        lo, hi = (cfg["gap"], cfg["gap"]) if a.distance == "adjacent" else (adj + cfg["margin"], prox - cfg["margin"])
        want = min(max(d, lo), hi)
        if abs(want - d) < reach and (a.wall is not None or d > -reach):  # never leave a footprint through a wall
            box[:2] += normal * (want - d)
    return box


def inside_walls(box: np.ndarray, walls: Walls, gap: float, reach: float) -> np.ndarray:
    """Push ``box (7,)`` back into the room past every wall whose inner face its footprint crosses by less than
    ``reach`` m (only corners opposite the wall's own span count, so reflex corners do not push)."""
    box = box.copy()
    for _ in range(2):
        corners = footprint_corners(*box[[0, 1, 3, 4, 6]])[0]
        rel = corners[None] - walls.a[:, None]  # (w, 4, 2)
        along = np.einsum("wkj,wj->wk", rel, walls.dir)
        depth = np.einsum("wkj,wj->wk", rel, walls.normal)
        inside_span = (along > 0) & (along < walls.length[:, None])
        worst = np.where(inside_span & (depth < 0) & (depth > -reach), depth, 0.0).min(1)
        if not (worst < 0).any():
            break
        w = int(np.argmin(worst))
        box[:2] += walls.normal[w] * (gap - worst[w])
    return box


def tolerance(failures: float, start: float, full: float) -> float:
    """Violation cost allowed after ``failures`` (0 before ``start``, then growing to 1 at ``full``)."""
    return 0.0 if failures < start else min(1.0, ((failures - start) / max(full - start, 1e-9)) ** 1.5)


def _in_box(points: np.ndarray, b: np.ndarray, inset=(0.0, 0.0), least: float = 0.0) -> np.ndarray:
    """``(m,)`` points inside box ``b (7,)``'s footprint shrunk by ``inset`` (x, y) m in its frame, each half extent
    kept >= ``least`` m; for boxes ``b (k, 7)``, ``(k, m)`` (``geometry.relations.in_footprint``)."""
    boxes = np.asarray(b, float).reshape(-1, 7)
    out = in_footprint(points[None], boxes[:, None], inset, least)
    return out if np.ndim(b) == 2 else out[0]


class Kit(NamedTuple):
    """What the search places with: the model ``pool`` it draws each object's instance from and the ``checker`` that
    accepts a place."""
    pool: ModelPool
    checker: Checker


class Search:
    """One scene's search state (the room's walls: :func:`~pipeline.placement.layout.walls_of`)."""

    def __init__(self, plan: ScenePlan, room: RoomInput, order: list[int], proposer: Proposer, kit: Kit, cfg: dict,
                 rng: np.random.Generator):
        self.plan, self.walls, self.order = plan, walls_of(room), order
        self.proposer, self.pool, self.cfg, self.rng = proposer, kit.pool, cfg, rng
        self.checker = replace(kit.checker, weighted=cfg["weighted_relations"])
        self.fixed = len(room.object_ids)  # objects given (completion) are never moved
        self.room = room
        self.grid = Grid(room.outline, cfg["grid_mpp"])
        self.bands = RelationPrior(kit.checker.extract_cfg, slack=cfg["band_slack"])
        self.sym = dict(zip(plan.ids, plan.symmetry)) | {o: "none" for o in room.object_ids if o not in plan.ids}
        self.rejected: dict[str, list[tuple[float, float, float]]] = {}  # plan id -> (x, y, half side) of squares
        self.shared: dict[tuple, object] = {}
        self.unit = {}
        self.backtracks = self.rejections = self.insertions = self.candidates = 0
        self.strikes: Counter = Counter()  # plan id -> times it spent its samples without a place
        self.failures: dict[str, int] = {}
        self.dropped: list[str] = []
        self.drops: list[dict] = []  # why each was dropped (``drop``)
        self.refusals: dict[str, Counter] = {}  # plan id -> rejections by check (``nowhere`` included)
        self.accepted: dict = {}  # PlanEdge -> cost when its later end was last placed
        self.relaxed: dict[str, dict] = {}  # plan id -> its broken relations and why, as last placed
        self.exhausted = False  # the backtrack budget ran out (the one failure a restart may cure)
        self.budget = max(cfg["max_backtracks"], int(np.ceil(cfg["backtracks_per_object"] * len(order))))
        self._free = None  # the last free_floor: (room boxes and grow, cells)

    def model_key(self, k: int) -> tuple:
        """Which instance object ``k`` shares: its own, its hub's spokes', or its chain's."""
        cat = self.plan.categories[k]
        if self.plan.role[k] == "spoke":
            hubs = [e.source for e in self.plan.edges if e.target == self.plan.ids[k] and e.source in self.plan.ids
                    and "hub" in self.plan.role[self.plan.index(e.source)]]
            return ("spoke", hubs[0] if hubs else None, cat)
        return ("chain", self.unit[k], cat) if k in self.unit else ("own", k)

    def model_for(self, k: int):
        """The instance for object ``k``: spokes of one hub share one, chain members copy their chain's; a floor node
        with planned spatial edges takes one that stood on the floor; one that fits its support and its children where
        the category has such (:meth:`fits`; :meth:`ModelPool.pick`)."""
        cat, key = self.plan.categories[k], self.model_key(k)
        if key not in self.shared:
            v, parent = self.plan.ids[k], self.plan.parent[k]
            grounded = parent is None and any(
                e.edge_type == "spatial" and v in (e.source, e.target) for e in self.plan.edges)
            self.shared[key] = self.pool.pick(cat, self.plan.symmetry[k], self.rng, grounded, partial(self.fits, k))
        return self.shared[key]

    def fits(self, k: int, half: np.ndarray) -> np.ndarray:
        """``(n,)`` bool: which instances of half extents ``half (n, 3)`` object ``k`` can take so that it can stand on
        its support, if placed, and each category it is planned to support has an instance that can stand on it
        (:func:`~pipeline.placement.checks.fits_on`: centred and square, with the share the support check asks): a
        television no wider than the stand placed for it, a side table that some television of the training rooms
        fits on."""
        ok = np.ones(len(half), bool)
        parent, v = self.plan.parent[k], self.plan.ids[k]
        if parent in self.room.object_ids:
            support = self.room.boxes[self.room.object_ids.index(parent), 3:5]
            ok &= fits_on(half, support[None], self.checker.min_support(self.plan.categories[k]))[0]
        sizes, back = np.unique(np.asarray(half, float)[:, :2], axis=0, return_inverse=True)
        for cat in {c for c, p in zip(self.plan.categories, self.plan.parent) if p == v and self.pool.has(c)}:
            ok &= fits_on(self.pool.sizes(cat), sizes, self.checker.min_support(cat)).any(1)[back.ravel()]
        return ok

    def occupied(self, grow: float, room: RoomInput | None = None) -> np.ndarray:
        """``(cells,)`` candidate centres inside a placed floor object's footprint grown by ``grow`` m (in ``room``,
        else the search's room)."""
        b = (room or self.room).boxes.reshape(-1, 7)
        floor = b[b[:, 2] - b[:, 5] < self.cfg["checks"]["collision"] + 0.05]
        return _in_box(self.grid.points, floor, (-grow, -grow)).any(0)

    def free_floor(self, half, room: RoomInput | None = None) -> np.ndarray:
        """``(cells,)`` candidate centres on the floor and off the placed floor objects of ``room`` (else the search's
        room) grown by the smaller of an object's half extents ``half (2,)`` (a fresh array; the last one is kept, as
        an object's samples ask again)."""
        room, grow = room or self.room, float(min(half))
        key = (room.boxes.tobytes(), grow)
        if self._free is None or self._free[0] != key:
            self._free = (key, self.grid.floor & ~self.occupied(grow, room))
        return self._free[1].copy()

    def free_top(self, pk: int, half) -> np.ndarray:
        """``(cells,)`` candidate centres on placed object ``pk``'s top shrunk by the smaller of ``half (2,)`` (any
        turn of the object; each half extent kept >= half a cell), with ``free_support`` off the footprints (grown
        the same) of the objects already standing on it."""
        pb = self.room.boxes[pk]
        grow = float(min(half))
        top = _in_box(self.grid.points, pb, (grow, grow), self.grid.mpp / 2)
        if not self.cfg["free_support"]:
            return top
        b = self.room.boxes.reshape(-1, 7)
        on = np.abs(b[:, 2] - b[:, 5] - (pb[2] + pb[5])) < self.cfg["checks"]["collision"] + 0.05
        on[pk] = False
        return top & ~_in_box(self.grid.points, b[on], (-grow, -grow)).any(0) if on.any() else top

    def band_cells(self, anchors: list[Anchor], half, room: RoomInput | None = None) -> np.ndarray:
        """``(cells,)`` :meth:`free_floor` cells of ``room`` (else the search's room) inside every anchor's planned
        band (:class:`~pipeline.placement.proposers.RelationPrior`, no softness)."""
        room = room or self.room
        return self.free_floor(half, room) & (self.bands.density(room, self.walls, "", anchors, self.grid.points) > 0)

    def forecloses(self, i: int, room: RoomInput, tol: float) -> set[str] | None:
        """Forward checking (``lookahead``: ``at_zero_tolerance``, ``always`` or ``none``): when object ``order[i]``
        placed as in ``room`` leaves a later floor object it has a planned spatial edge with no free cell in every
        band of its placed anchors (two at least), those other anchors (what to move instead); else None."""
        mode = self.cfg["lookahead"]
        if mode == "none" or (mode == "at_zero_tolerance" and tol > 0):
            return None
        v = self.plan.ids[self.order[i]]
        for j in self.order[i + 1:]:
            w = self.plan.ids[j]
            if self.plan.parent[j] is not None or not any(
                    e.edge_type == "spatial" and {e.source, e.target} == {v, w} for e in self.plan.edges):
                continue
            half = self.model_for(j).half[:2]
            anchors = anchors_of(w, self.plan, room, self.walls, self.sym, half)
            if len(anchors) >= 2 and not self.band_cells(anchors, half, room).any():
                return {a.node for a in anchors if a.obj is not None and a.node != v}
        return None

    def nowhere(self, k: int, tol: float) -> set[str] | None:
        """With ``early_backtrack``, at zero tolerance: the placed objects among floor object ``k``'s anchors when
        no free cell lies in every planned band (its samples would almost all break a relation), else None."""
        if not self.cfg["early_backtrack"] or tol > 0 or self.plan.parent[k] is not None:
            return None
        half = self.model_for(k).half[:2]
        anchors = anchors_of(self.plan.ids[k], self.plan, self.room, self.walls, self.sym, half)
        if not anchors or self.band_cells(anchors, half).any():
            return None
        return {a.node for a in anchors if a.obj is not None}

    def tolerance(self, v: str) -> float:
        """The violation cost object ``v`` may be accepted with now: after its own failures (``per_object``), or
        after the scene's backtracks (PlanIT: from a quarter of the budget)."""
        if self.cfg["per_object"]:
            relax = self.cfg["relax"]
            return min(relax["max"], tolerance(self.strikes[v], relax["start"], relax["full"]))
        return tolerance(self.backtracks, self.budget / 4, self.budget)

    def reject_half(self, v: str, half) -> float:
        """Half side (m) of the square a rejected point of object ``v`` (half extents ``half (2,)``) clears: a share
        of its smaller half extent growing with its failures, never beyond it (``per_object``), or PlanIT's square
        growing with the scene's backtracks."""
        if self.cfg["per_object"]:
            small = float(min(half))
            grown = self.cfg["reject_fraction"] * small * self.cfg["reject_growth"] ** self.strikes[v]
            return max(self.grid.mpp / 2, min(grown, small))
        return min(self.cfg["reject_half"] * self.cfg["reject_growth"] ** self.backtracks, self.cfg["reject_max_half"])

    def culprit_half(self, u: str, i: int) -> float:
        """Half side of the square cleared around culprit ``u``'s place when object ``order[i]`` backtracks to it: its
        own square, or (``per_object``) at least the failing object's smaller half extent, so that the culprit moves
        far enough to leave it room."""
        own = self.reject_half(u, self.room.boxes[self.room.object_ids.index(u), 3:5])
        if not self.cfg["per_object"]:
            return own
        return max(own, float(min(self.model_for(self.order[i]).half[:2])))

    def request(self, k: int, inst) -> tuple[Request, int | None]:
        """What the proposer is asked for object ``k`` (instance ``inst``), and its support's index in the room."""
        v, half = self.plan.ids[k], inst.half[:2]
        parent = self.plan.parent[k]
        pk = self.room.object_ids.index(parent) if parent in self.room.object_ids else None
        mask = self.free_floor(half) if pk is None else self.free_top(pk, half)
        scene = None if self.cfg["per_object"] else self.reject_half(v, half)  # PlanIT: every square grows with the scene
        for x, y, r in self.rejected.get(v, []):
            r = r if scene is None else scene
            mask &= (np.abs(self.grid.points[:, 0] - x) > r) | (np.abs(self.grid.points[:, 1] - y) > r)
        anchors = anchors_of(v, self.plan, self.room, self.walls, self.sym, half)
        return Request(self.room, self.walls, self.plan.categories[k], self.plan.symmetry[k], anchors, self.grid,
                       mask, self.ahead(v), self.later_sides(v)), pk

    def ahead(self, v: str) -> tuple[tuple[str, int], ...]:
        """The plan's objects not placed yet that are not ``v``'s anchors (no edge, or one from ``v``: a television
        stand the plan puts in front of the sofa placed first), as (category, wall index) of each wall it is planned
        adjacent to (:attr:`~pipeline.placement.proposers.Request.ahead`)."""
        placed, wall = set(self.room.object_ids), {w: k for k, w in enumerate(self.walls.ids)}
        joined = {e.source for e in self.plan.edges if e.target == v}
        return tuple((self.plan.categories[self.plan.index(e.target)], wall[e.source]) for e in self.plan.edges
                     if e.source in wall and e.edge_type == "spatial" and e.distance == "adjacent"
                     and e.target in self.plan.ids and e.target not in placed | joined | {v})

    def later_sides(self, v: str) -> tuple[str, ...]:
        """The directions of ``v``'s planned spatial edges to objects not placed yet
        (:attr:`~pipeline.placement.proposers.Request.later_sides`)."""
        placed = set(self.room.object_ids)
        return tuple(e.direction for e in self.plan.edges if e.source == v and e.edge_type == "spatial"
                     and e.target in self.plan.ids and e.target not in placed and e.direction is not None)

    def propose(self, k: int):
        """A candidate box and pose for object ``k``, or None when no allowed candidate has mass."""
        inst = self.model_for(k)
        req, pk = self.request(k, inst)
        drawn = self.proposer.pose(req, self.rng)
        if drawn is None:
            return None
        xy, yaw = drawn
        support = None if pk is None else float(self.room.boxes[pk, 2] + self.room.boxes[pk, 5])
        box, _ = place(inst, xy[0], xy[1], support, yaw)
        box = snap(box, req.anchors, self.room, self.walls, self.checker.extract_cfg, self.cfg["snap"])
        if pk is None and self.cfg["snap"]["enabled"]:
            box = inside_walls(box, self.walls, self.cfg["snap"]["gap"], self.cfg["snap"]["reach"])
        box, pose = place(inst, box[0], box[1], support, yaw)
        return xy, box, pose, inst.model_id, pk

    def try_place(self, i: int) -> set[str] | None:
        """Place object ``order[i]`` within its sample budget: None on success, else the culprits of its failures."""
        k = self.order[i]
        v = self.plan.ids[k]
        culprits: set[str] = set()
        budget = max(self.cfg["min_samples"], self.cfg["samples"] - self.backtracks // 5)
        tol = self.tolerance(v)
        blocked = self.nowhere(k, tol)
        if blocked is not None:
            log.debug("%s %s: no free cell in every planned band", self.plan.scene_id, v)
            self.refuse(v, "nowhere")
            return blocked
        best = None  # with relaxed relations: the cheapest acceptable candidate so far (room, verdict)
        for _ in range(budget):
            if self.candidates >= self.cfg["candidate_budget"]:
                break
            cand = self.propose(k)
            if cand is None:  # no free cell left for it (not a rejection: no candidate was drawn)
                self.refusals.setdefault(v, Counter())["no_cell"] += 1
                break
            self.candidates += 1
            xy, box, pose, model, pk = cand
            room = add_object(self.room, v, self.plan.categories[k], model, box, pose)
            present = set(self.room.object_ids) | set(self.walls.ids)
            verdict = check(room, len(room.object_ids) - 1, None if pk is None else pk, set(),
                            planned_edges(v, self.plan, present), tol, self.checker)
            foreclosed = self.forecloses(i, room, tol) if verdict.ok else None
            if foreclosed is not None:
                verdict = replace(verdict, ok=False, reason="forecloses a later object's planned place",
                                  culprits=foreclosed)
            if verdict.ok and (verdict.cost == 0 or not self.cfg["keep_relations"]):
                return self.accept(k, room, verdict, tol)
            if verdict.ok:
                best = min(best or (room, verdict), (room, verdict), key=lambda rv: rv[1].cost)
                continue
            self.rejections += 1
            log.debug("%s %s (%s) at %.2f, %.2f: %s", self.plan.scene_id, v, self.plan.categories[k], box[0], box[1], verdict.reason)
            self.refuse(v, verdict.reason.split(" ")[0])
            self.rejected.setdefault(v, []).append((float(xy[0]), float(xy[1]), self.reject_half(v, box[3:5])))
            culprits |= verdict.culprits
        return culprits if best is None else self.accept(k, *best, tol)

    def refuse(self, v: str, kind: str) -> None:
        """Count a refusal of object ``v`` by check ``kind``."""
        self.failures[kind] = self.failures.get(kind, 0) + 1
        self.refusals.setdefault(v, Counter())[kind] += 1

    def accept(self, k: int, room: RoomInput, verdict, tol: float) -> None:
        """Keep a candidate's room and the costs of its planned relations (the edges' loss records); an object kept
        with a broken relation is recorded with the edges it broke, what extraction found instead, and why it was
        allowed to (its failures and tolerance, and the check that refused it most)."""
        v = self.plan.ids[k]
        self.room = room
        self.insertions += 1
        self.accepted.update(verdict.edge_costs)
        self.relaxed.pop(v, None)
        if verdict.cost > 0:
            refused = self.refusals.get(v)
            self.relaxed[v] = {"id": v, "category": self.plan.categories[k], "cost": round(verdict.cost, 3),
                               "tolerance": round(tol, 3), "failures": int(self.strikes[v]),
                               "cause": refused.most_common(1)[0][0] if refused else None,
                               "broken": [broken(e, verdict.found) for e, c in verdict.edge_costs if c > 0]}
        return None

    def drop(self, k: int, cause: str) -> None:
        """Leave object ``k`` out (``on_exhausted: drop``), recording why: ``no_model`` (no training instance of its
        category), ``support_dropped`` (what it stands on was left out) or ``no_place`` (its budget spent; ``check``:
        the check that refused its candidates most, ``no_cell`` where no free cell was left to draw one from)."""
        v = self.plan.ids[k]
        self.dropped.append(v)
        refused = self.refusals.get(v)
        self.drops.append({"id": v, "category": self.plan.categories[k], "cause": cause,
                           "check": refused.most_common(1)[0][0] if cause == "no_place" and refused else None})

    def run(self, deadline: float) -> str:
        """Place every object in order; '' on success, else why the scene failed."""
        for u, unit in enumerate(chains(self.plan)):
            for k in unit:
                self.unit[k] = u
        missing = {k for k in self.order if not self.pool.has(self.plan.categories[k])}  # held-out categories
        if missing and self.cfg["on_exhausted"] == "fail":  # no model to place: fail before placing anything
            k = next(k for k in self.order if k in missing)
            return f"no training instance of category '{self.plan.categories[k]}' for {self.plan.ids[k]}"
        unspannable = self.unspannable(missing)
        if unspannable and self.cfg["on_exhausted"] == "fail":  # a wall-bound object no instance fits: fail at once
            return "unsatisfiable plan: " + unspannable[next(k for k in self.order if k in unspannable)]
        i = 0
        while i < len(self.order):
            if time.perf_counter() > deadline:
                return f"time budget ({self.cfg['time_budget']} s) spent at object {i + 1} of {len(self.order)}"
            k = self.order[i]
            if k in missing or k in unspannable or self.plan.parent[k] in self.dropped:  # or its support was left out
                self.drop(k, "no_model" if k in missing else "no_span" if k in unspannable else "support_dropped")
                i += 1
                continue
            culprits = self.try_place(i)
            if culprits is None:
                i += 1
                continue
            self.strikes[self.plan.ids[k]] += 1
            if self.cfg["redraw"]:  # another instance next time: a size that failed is not forced on it again
                self.shared.pop(self.model_key(k), None)
            if self.candidates >= self.cfg["candidate_budget"]:
                return f"candidate budget ({self.cfg['candidate_budget']}) spent at object {i + 1} of {len(self.order)}"
            if self.backtracks >= self.budget:
                if self.cfg["on_exhausted"] == "drop":
                    self.drop(k, "no_place")
                    i += 1
                    continue
                self.exhausted = True
                return self.exhausted_reason(k)
            i = self.backtrack(i, culprits)
        return ""

    def unspannable(self, missing: set[int]) -> dict[int, str]:
        """Objects of wall-bound categories (which never break a planned wall adjacency) planned adjacent to two facing
        walls that no training instance of their category can span (:func:`~pipeline.placement.walls.unspanned`):
        plan index -> why. The graph model plans a bathtub between the walls of the alcove it learned in a room 3 m
        wide; the search would spend every backtrack and restart on it."""
        out = {}
        for k in self.order:
            v, cat = self.plan.ids[k], self.plan.categories[k]
            if k in missing or cat not in self.checker.wall_bound:
                continue
            planned = [e.source for e in self.plan.edges if e.target == v and e.edge_type == "spatial"
                       and e.distance == "adjacent" and e.source in self.walls.ids]
            hit = unspanned(self.walls, planned, np.array([i.half[:2] for i in self.pool.by_cat[cat]]),
                            self.checker.extract_cfg["distance"], self.checker.cfg["outside"])
            if hit is not None:
                out[k] = f"{v} ({cat}) planned against {hit[0]} and {hit[1]}, {hit[2]:.2f} m apart, which no instance spans"
        return out

    def exhausted_reason(self, k: int) -> str:
        """Why a scene failed when its backtrack budget ran out: the object with no place and the check that refused
        its candidates most."""
        v = self.plan.ids[k]
        refused = self.refusals.get(v)
        why = f"; refused most by {refused.most_common(1)[0][0]}" if refused else ""
        return f"backtrack budget ({self.budget}) spent: no place for {v} ({self.plan.categories[k]}){why}"

    def unit_start(self, i: int, j: int) -> int:
        """Where object ``order[i]``'s failure backtracks to when it blames ``order[j]``: the first member of their
        chain when both are in one (the chain moves as a unit, not member by member), else ``j``."""
        unit = self.unit.get(self.order[i])
        if unit is None or self.unit.get(self.order[j]) != unit:
            return j
        return next(m for m in range(i) if self.unit.get(self.order[m]) == unit)

    def backtrack(self, i: int, culprits: set[str]) -> int:
        """Undo back to the latest placed culprit of object ``order[i]``'s failures (else the object before it; a
        culprit in its own chain: the chain's first member), rejecting that object's place; returns the position to
        go on from."""
        self.backtracks += 1
        if i == 0:  # nothing to undo: the first object tries again afresh
            self.rejected.pop(self.plan.ids[self.order[0]], None)
            return 0
        placed = [self.plan.ids[j] for j in self.order[:i]]
        earlier = [placed.index(c) for c in culprits if c in placed]
        j = max(earlier) if earlier else i - 1
        j = self.unit_start(i, j)
        u = self.plan.ids[self.order[j]]
        uk = self.room.object_ids.index(u)
        self.rejected.setdefault(u, []).append((*map(float, self.room.boxes[uk, :2]), self.culprit_half(u, i)))
        for later in self.order[j + 1:]:
            self.rejected.pop(self.plan.ids[later], None)
            self.relaxed.pop(self.plan.ids[later], None)
        self.relaxed.pop(u, None)
        self.room = with_objects(self.room, np.arange(self.fixed + j))
        return j


def broken(edge, found: dict) -> dict:
    """A broken planned edge as a record: its ends, what was planned and what extraction found instead."""
    got = [g for g in found.get((edge.source, edge.target), []) if g[0] == edge.edge_type]
    return {"source": edge.source, "target": edge.target,
            "planned": "support" if edge.edge_type == "support" else f"{edge.direction}/{edge.distance}",
            "found": ", ".join("support" if g[0] == "support" else f"{g[1]}/{g[2]}" for g in got) or "absent"}


def drop_reason(drops: list[dict], planned: int) -> str:
    """A partial scene's reason: how many of the ``planned`` objects it left out, by cause (:data:`DROP_CAUSES`)."""
    by_cause = {c: ", ".join(f"{d['id']} ({d['category']})" for d in drops if d["cause"] == c) for c in DROP_CAUSES}
    return f"dropped {len(drops)} of {planned} objects: " + "; ".join(
        f"{DROP_CAUSES[c]}: {ids}" for c, ids in by_cause.items() if ids)


def instantiate(plan: ScenePlan, room: RoomInput, order: list[int], proposer: Proposer, kit: Kit, cfg: dict,
                seed: int) -> Outcome:
    """Place the plan's objects (``order``: indices into the plan) in ``room`` (its objects stay fixed), each with
    the pose the proposer gives it and an instance of the ``kit``'s pool its checker accepts. A search that spends its
    backtrack budget starts over, up to ``cfg['restarts']`` times: attempt ``a > 0`` draws from ``(seed, a)``, so the
    first attempt is the search without restarts. Counts and seconds add up over attempts."""
    start, runs = time.perf_counter(), []
    for attempt in range(cfg["restarts"] + 1):
        s = Search(plan, room, order, proposer, kit, cfg,
                   np.random.default_rng(seed if attempt == 0 else [seed, attempt]))
        reason = s.run(time.perf_counter() + cfg["time_budget"])
        runs.append(s)
        if not s.exhausted:
            break
    ok = not reason
    if ok and s.dropped:
        reason = drop_reason(s.drops, len(order))
    total = lambda name: sum(getattr(r, name) for r in runs)
    failures = sum((Counter(r.failures) for r in runs), Counter())
    return Outcome(ok, s.room, reason, time.perf_counter() - start, total("insertions"), total("rejections"),
                   total("backtracks"), dict(failures), s.dropped, s.drops, len(runs), s.accepted,
                   [s.relaxed[v] for v in s.room.object_ids if v in s.relaxed])
