"""Placing a planned graph's objects one at a time with backtracking (PlanIT section 6, Appendix B).

Each object samples a location from the proposer's density (a product over its placed anchors, masked to the
floor or its support's top, minus squares around the points already rejected), an orientation, and a model; it
slides flush against the anchors it must be adjacent to, then must pass :func:`~pipeline.placement.checks.check`.
After its sample budget, the search backtracks to the nearest earlier object that caused one of its failures (or
the one before it) and that object is placed afresh elsewhere. The relation tolerance stays 0 for the first
quarter of the backtrack budget, then grows as ``((b - B/4) / (3B/4)) ** 1.5``; with ``keep_relations``, a candidate
that breaks some of its relations within that tolerance is kept only when the object's remaining samples find none
that keeps them all (the cheapest such candidate is taken). With ``early_backtrack``, an object at zero
tolerance whose planned bands share no free cell backtracks at once instead of spending its samples. A scene fails, with its reason,
when the backtrack or candidate budget runs out (or the time budget, a safety net: the one outcome a machine's
speed can change), or an object's category has no training instance; with
``on_exhausted: drop``, such an object is left out instead (with the objects it supports) and the search goes on.
A scene whose backtrack budget runs out starts over from scratch with a fresh seed, at most ``restarts`` times (each
attempt with its own budgets); its counts add up over the attempts.
"""
from __future__ import annotations

import logging
import time
from collections import Counter
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..room import RoomInput, Walls
from ..geometry import raster
from ..geometry.boxes import SIDE_NORMALS, SIDES, footprint_corners, rotation
from ..geometry.frames import Frame
from .checks import Checker, check
from .layout import add_object, box_frame, wall_frame, with_objects
from .order import chains
from .plan import PlanEdge, ScenePlan
from .poses import PoseRules
from .proposers import RelationPrior
from .retrieval import ModelPool, place

log = logging.getLogger("planit.instantiate")


@dataclass
class Anchor:
    """A placed node with a planned spatial edge to the object being placed."""
    node: str
    frame: Frame
    symmetry: str
    direction: str
    distance: str
    obj: int | None = None  # index among the room's objects
    wall: int | None = None  # index among the room's walls
    target_half: tuple[float, float] = (0.0, 0.0)  # half extents (x, y) of the object being placed


class Proposer(Protocol):
    def density(self, room: RoomInput, walls: Walls, category: str, anchors: list[Anchor], points: np.ndarray) -> np.ndarray:
        """``(m,)`` unnormalised density of the object's centre at ``points (m, 2)``."""

    def orientation(self, room: RoomInput, walls: Walls, category: str, symmetry: str, xy: np.ndarray,
                    rng: np.random.Generator) -> float:
        """A yaw (rad) for an object of the category centred at ``xy``."""


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

    @property
    def status(self) -> str:
        return "failed" if not self.ok else "partial" if self.dropped else "placed"


DROP_CAUSES = {"no_place": "no place once the backtrack budget was spent", "no_model": "no training instance",
               "support_dropped": "support dropped"}
SCORED = ("placed", "partial")  # the statuses of scenes that hold a room to score (a partial one lacks what it dropped)


class Grid:
    """Candidate centres: cell centres over the room's bounding square at ``mpp``, and those on the floor."""

    def __init__(self, outline: np.ndarray, mpp: float):
        lo, hi = outline.min(0), outline.max(0)
        self.mpp = mpp
        self.size = int(np.ceil((hi - lo).max() / mpp)) + 2
        self.centre = (lo + hi) / 2
        xs, ys = raster.pixel_centres(self.size, mpp, self.centre)
        self.points = np.stack(np.meshgrid(xs, ys), -1).reshape(-1, 2)
        self.floor = raster.fill_polygon(outline, self.size, mpp, self.centre).reshape(-1)


def anchors_of(v: str, plan: ScenePlan, room: RoomInput, walls: Walls, sym: dict[str, str],
               half: tuple[float, float] = (0.0, 0.0)) -> list[Anchor]:
    """The placed objects and walls with a planned spatial edge to ``v`` (whose half extents are ``half``)."""
    obj = {o: k for k, o in enumerate(room.object_ids)}
    wall = {w: k for k, w in enumerate(walls.ids)}
    out = []
    for e in plan.edges:
        if e.target != v or e.edge_type != "spatial":
            continue
        if e.source in obj:
            k = obj[e.source]
            out.append(Anchor(e.source, box_frame(room.boxes[k]), sym.get(e.source, "none"), e.direction, e.distance, obj=k, target_half=half))
        elif e.source in wall:
            k = wall[e.source]
            out.append(Anchor(e.source, wall_frame(walls, k), "none", e.direction, e.distance, wall=k, target_half=half))
    return out


def planned_edges(v: str, plan: ScenePlan, present: set[str]) -> list[PlanEdge]:
    """Planned support and spatial edges between ``v`` and nodes already present (objects or walls)."""
    return [e for e in plan.edges if (e.target == v and e.source in present) or (e.source == v and e.target in present)]


def side_plane(a: Anchor, room: RoomInput) -> tuple[np.ndarray, np.ndarray]:
    """Point on and outward normal of the anchor's side named by its edge direction (world)."""
    if a.wall is not None:
        return np.array(a.frame.origin), rotation(a.frame.yaw) @ SIDE_NORMALS[0]
    b = room.boxes[a.obj]
    s = SIDES.index(a.direction)
    normal = rotation(b[6]) @ SIDE_NORMALS[s]
    return b[:2] + normal * (b[4] if s < 2 else b[3]), normal


def snap(box: np.ndarray, anchors: list[Anchor], room: RoomInput, gaps: dict, reach: float) -> np.ndarray:
    """Slide ``box (7,)`` along the normal of each anchor side it is planned adjacent or proximal to (walls first)
    until its footprint's gap to the side lies in ``gaps[distance] = (lo, hi)`` m, when the slide is under
    ``reach`` m and the box is on the side's outer half-space (or across a wall)."""
    box = box.copy()
    for a in sorted((a for a in anchors if a.distance in gaps), key=lambda a: a.wall is None):
        point, normal = side_plane(a, room)
        d = float(((footprint_corners(*box[[0, 1, 3, 4, 6]])[0] - point) @ normal).min())
        lo, hi = gaps[a.distance]
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


def tolerance(backtracks: int, budget: int) -> float:
    """Violation cost allowed after ``backtracks`` of ``budget`` (0 for the first quarter, then growing)."""
    start = budget / 4
    return 0.0 if backtracks < start else min(1.0, ((backtracks - start) / max(budget - start, 1e-9)) ** 1.5)


def _in_box(points: np.ndarray, b: np.ndarray, inset=(0.0, 0.0), least: float = 0.0) -> np.ndarray:
    """``(m,)`` points inside box ``b (7,)``'s footprint shrunk by ``inset`` (x, y) m in its frame, each half extent
    kept >= ``least`` m; for boxes ``b (k, 7)``, ``(k, m)``."""
    boxes = np.asarray(b, float).reshape(-1, 7)
    local = (points[None] - boxes[:, None, :2]) @ rotation(boxes[:, 6])  # (k, m, 2)
    inside = np.abs(local) <= np.maximum(boxes[:, 3:5] - np.asarray(inset, float), least)[:, None, :]
    out = inside[..., 0] & inside[..., 1]
    return out if np.ndim(b) == 2 else out[0]


class Search:
    """One scene's search state."""

    def __init__(self, plan: ScenePlan, room: RoomInput, walls: Walls, order: list[int], proposer: Proposer,
                 pool: ModelPool, checker: Checker, cfg: dict, rng: np.random.Generator, poses: PoseRules | None = None):
        self.plan, self.walls, self.order, self.poses = plan, walls, order, poses
        self.proposer, self.pool, self.checker, self.cfg, self.rng = proposer, pool, checker, cfg, rng
        self.fixed = len(room.object_ids)  # objects given (completion) are never moved
        self.room = room
        self.grid = Grid(room.outline, cfg["grid_mpp"])
        sn = cfg["snap"]
        self.gaps = {"adjacent": (sn["gap"], sn["gap"]), "proximal": tuple(sn["proximal"])}
        self.sym = dict(zip(plan.ids, plan.symmetry)) | {o: "none" for o in room.object_ids if o not in plan.ids}
        self.rejected: dict[str, list[tuple[float, float]]] = {}
        self.shared: dict[tuple, object] = {}
        self.unit = {}
        self.backtracks = self.rejections = self.insertions = self.candidates = 0
        self.failures: dict[str, int] = {}
        self.dropped: list[str] = []
        self.drops: list[dict] = []  # why each was dropped (``drop``)
        self.refusals: dict[str, Counter] = {}  # plan id -> rejections by check (``nowhere`` included)
        self.accepted: dict = {}  # PlanEdge -> cost when its later end was last placed
        self.exhausted = False  # the backtrack budget ran out (the one failure a restart may cure)
        self._free = None  # the last free_floor: (room boxes and grow, cells)

    def model_for(self, k: int):
        """The instance for object ``k``: spokes of one hub share one, chain members copy their chain's; a floor node
        with planned spatial edges takes one that stood on the floor (:meth:`ModelPool.pick`)."""
        cat, key = self.plan.categories[k], ("own", k)
        if self.plan.role[k] == "spoke":
            hubs = [e.source for e in self.plan.edges if e.target == self.plan.ids[k] and e.source in self.plan.ids
                    and "hub" in self.plan.role[self.plan.index(e.source)]]
            key = ("spoke", hubs[0] if hubs else None, cat)
        elif k in self.unit:
            key = ("chain", self.unit[k], cat)
        if key not in self.shared:
            v = self.plan.ids[k]
            grounded = self.plan.parent[k] is None and any(
                e.edge_type == "spatial" and v in (e.source, e.target) for e in self.plan.edges)
            self.shared[key] = self.pool.pick(cat, self.plan.symmetry[k], self.rng, grounded)
        return self.shared[key]

    def occupied(self, grow: float) -> np.ndarray:
        """``(cells,)`` candidate centres inside a placed floor object's footprint grown by ``grow`` m."""
        b = self.room.boxes.reshape(-1, 7)
        floor = b[b[:, 2] - b[:, 5] < self.cfg["checks"]["collision"] + 0.05]
        return _in_box(self.grid.points, floor, (-grow, -grow)).any(0)

    def free_floor(self, half) -> np.ndarray:
        """``(cells,)`` candidate centres on the floor and off the placed floor objects grown by the smaller of an
        object's half extents ``half (2,)`` (a fresh array; the last one is kept, as an object's samples ask again)."""
        grow = float(min(half))
        key = (self.room.boxes.tobytes(), grow)
        if self._free is None or self._free[0] != key:
            self._free = (key, self.grid.floor & ~self.occupied(grow))
        return self._free[1].copy()

    def free_top(self, pk: int, inset, half) -> np.ndarray:
        """``(cells,)`` candidate centres on placed object ``pk``'s top shrunk by ``inset (2,)`` m (each half extent
        kept >= half a cell), with ``free_support`` off the footprints (grown by the smaller of ``half (2,)``) of the
        objects already standing on it."""
        pb = self.room.boxes[pk]
        top = _in_box(self.grid.points, pb, inset, self.grid.mpp / 2)
        if not self.cfg["free_support"]:
            return top
        b = self.room.boxes.reshape(-1, 7)
        on = np.abs(b[:, 2] - b[:, 5] - (pb[2] + pb[5])) < self.cfg["checks"]["collision"] + 0.05
        on[pk] = False
        return top & ~_in_box(self.grid.points, b[on], (-float(min(half)),) * 2).any(0) if on.any() else top

    def band_cells(self, anchors: list[Anchor], half) -> np.ndarray:
        """``(cells,)`` :meth:`free_floor` cells inside every anchor's planned band
        (:class:`~pipeline.placement.proposers.RelationPrior`, no softness)."""
        return self.free_floor(half) & (RelationPrior().density(self.room, self.walls, "", anchors, self.grid.points) > 0)

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

    def propose(self, k: int, half: float):
        """A candidate box and pose for object ``k``, or None when no location has mass left. A supported object
        turns first (to its support's axes) so that its footprint can be kept on the support's top."""
        v, cat, sym = self.plan.ids[k], self.plan.categories[k], self.plan.symmetry[k]
        inst = self.model_for(k)
        anchors = anchors_of(v, self.plan, self.room, self.walls, self.sym, inst.half[:2])
        parent = self.plan.parent[k]
        pk = self.room.object_ids.index(parent) if parent in self.room.object_ids else None
        if pk is None:  # on the floor, off the floor objects' footprints
            mask, yaw = self.free_floor(inst.half[:2]), None
        else:
            pb = self.room.boxes[pk]
            yaw = self.proposer.orientation(self.room, self.walls, cat, sym, pb[:2], self.rng)
            turns = int(np.round((yaw - pb[6]) / (np.pi / 2)))
            yaw = float(pb[6] + turns * np.pi / 2)
            inset = inst.half[:2][::-1] if turns % 2 else inst.half[:2]
            mask = self.free_top(pk, inset, inst.half[:2])
        for x, y in self.rejected.get(v, []):
            mask &= (np.abs(self.grid.points[:, 0] - x) > half) | (np.abs(self.grid.points[:, 1] - y) > half)
        if not mask.any():
            return None
        p = self.proposer.density(self.room, self.walls, cat, anchors, self.grid.points) * mask
        if not np.isfinite(p).all() or p.sum() <= 0:
            p = mask.astype(float)
        cell = self.rng.choice(len(p), p=p / p.sum())
        xy = self.grid.points[cell] + self.rng.uniform(-0.5, 0.5, 2) * self.grid.mpp
        if yaw is None and self.poses is not None:  # a learned rule first: no network call where one applies
            yaw = self.poses.yaw(self.room, cat, anchors, xy)
        if yaw is None:
            yaw = self.proposer.orientation(self.room, self.walls, cat, sym, xy, self.rng)
        support = None if pk is None else float(self.room.boxes[pk, 2] + self.room.boxes[pk, 5])
        box, _ = place(inst, xy[0], xy[1], support, yaw)
        box = snap(box, anchors, self.room, self.gaps, self.cfg["snap"]["reach"])
        if pk is None:
            box = inside_walls(box, self.walls, self.cfg["snap"]["gap"], self.cfg["snap"]["reach"])
        box, pose = place(inst, box[0], box[1], support, yaw)
        return xy, box, pose, inst.model_id, pk

    def try_place(self, k: int) -> set[str] | None:
        """Place object ``k`` within its sample budget: None on success, else the culprits of its failures."""
        v = self.plan.ids[k]
        culprits: set[str] = set()
        budget = max(self.cfg["min_samples"], self.cfg["samples"] - self.backtracks // 5)
        half = min(self.cfg["reject_half"] * self.cfg["reject_growth"] ** self.backtracks, self.cfg["reject_max_half"])
        tol = tolerance(self.backtracks, self.cfg["max_backtracks"])
        blocked = self.nowhere(k, tol)
        if blocked is not None:
            log.debug("%s %s: no free cell in every planned band", self.plan.scene_id, v)
            self.failures["nowhere"] = self.failures.get("nowhere", 0) + 1
            self.refusals.setdefault(v, Counter())["nowhere"] += 1
            return blocked
        best = None  # with relaxed relations: the cheapest acceptable candidate so far (room, verdict)
        for _ in range(budget):
            if self.candidates >= self.cfg["candidate_budget"]:
                break
            cand = self.propose(k, half)
            if cand is None:  # no free cell left for it (not a rejection: no candidate was drawn)
                self.refusals.setdefault(v, Counter())["no_cell"] += 1
                break
            self.candidates += 1
            xy, box, pose, model, pk = cand
            room = add_object(self.room, v, self.plan.categories[k], model, box, pose)
            present = set(self.room.object_ids) | set(self.walls.ids)
            verdict = check(room, len(room.object_ids) - 1, None if pk is None else pk, set(),
                            planned_edges(v, self.plan, present), tol, self.checker)
            if verdict.ok and (verdict.cost == 0 or not self.cfg["keep_relations"]):
                return self.accept(room, verdict)
            if verdict.ok:
                best = min(best or (room, verdict), (room, verdict), key=lambda rv: rv[1].cost)
                continue
            self.rejections += 1
            log.debug("%s %s (%s) at %.2f, %.2f: %s", self.plan.scene_id, v, self.plan.categories[k], box[0], box[1], verdict.reason)
            kind = verdict.reason.split(" ")[0]
            self.failures[kind] = self.failures.get(kind, 0) + 1
            self.refusals.setdefault(v, Counter())[kind] += 1
            self.rejected.setdefault(v, []).append((float(xy[0]), float(xy[1])))
            culprits |= verdict.culprits
        return culprits if best is None else self.accept(*best)

    def accept(self, room: RoomInput, verdict) -> None:
        """Keep a candidate's room and the costs of its planned relations (the edges' loss records)."""
        self.room = room
        self.insertions += 1
        self.accepted.update(verdict.edge_costs)
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
        i = 0
        while i < len(self.order):
            if time.perf_counter() > deadline:
                return f"time budget ({self.cfg['time_budget']} s) spent at object {i + 1} of {len(self.order)}"
            k = self.order[i]
            if k in missing or self.plan.parent[k] in self.dropped:  # no model, or its support was left out
                self.drop(k, "no_model" if k in missing else "support_dropped")
                i += 1
                continue
            culprits = self.try_place(k)
            if culprits is None:
                i += 1
                continue
            if self.candidates >= self.cfg["candidate_budget"]:
                return f"candidate budget ({self.cfg['candidate_budget']}) spent at object {i + 1} of {len(self.order)}"
            if self.backtracks >= self.cfg["max_backtracks"]:
                if self.cfg["on_exhausted"] == "drop":
                    self.drop(k, "no_place")
                    i += 1
                    continue
                self.exhausted = True
                return f"backtrack budget ({self.cfg['max_backtracks']}) spent: no place for {self.plan.ids[k]} ({self.plan.categories[k]})"
            i = self.backtrack(i, culprits)
        return ""

    def backtrack(self, i: int, culprits: set[str]) -> int:
        """Undo back to the latest placed culprit of object ``order[i]``'s failures (else the object before it),
        rejecting that object's place; returns the position to go on from."""
        self.backtracks += 1
        if i == 0:  # nothing to undo: the first object tries again afresh
            self.rejected.pop(self.plan.ids[self.order[0]], None)
            return 0
        placed = [self.plan.ids[j] for j in self.order[:i]]
        earlier = [placed.index(c) for c in culprits if c in placed]
        j = max(earlier) if earlier else i - 1
        u = self.plan.ids[self.order[j]]
        uk = self.room.object_ids.index(u)
        self.rejected.setdefault(u, []).append(tuple(map(float, self.room.boxes[uk, :2])))
        for later in self.order[j + 1:]:
            self.rejected.pop(self.plan.ids[later], None)
        self.room = with_objects(self.room, np.arange(self.fixed + j))
        return j


def drop_reason(drops: list[dict], planned: int) -> str:
    """A partial scene's reason: how many of the ``planned`` objects it left out, by cause (:data:`DROP_CAUSES`)."""
    by_cause = {c: ", ".join(f"{d['id']} ({d['category']})" for d in drops if d["cause"] == c) for c in DROP_CAUSES}
    return f"dropped {len(drops)} of {planned} objects: " + "; ".join(
        f"{DROP_CAUSES[c]}: {ids}" for c, ids in by_cause.items() if ids)


def instantiate(plan: ScenePlan, room: RoomInput, walls: Walls, order: list[int], proposer: Proposer, pool: ModelPool,
                checker: Checker, cfg: dict, seed: int, poses: PoseRules | None = None) -> Outcome:
    """Place the plan's objects (``order``: indices into the plan) in ``room`` (its objects stay fixed); a floor
    object's orientation follows the learned ``poses`` where one applies, else the proposer's. A search that
    spends its backtrack budget starts over, up to ``cfg['restarts']`` times: attempt ``a > 0`` draws from
    ``(seed, a)``, so the first attempt is the search without restarts. Counts and seconds add up over attempts."""
    start, runs = time.perf_counter(), []
    for attempt in range(cfg["restarts"] + 1):
        s = Search(plan, room, walls, order, proposer, pool, checker, cfg,
                   np.random.default_rng(seed if attempt == 0 else [seed, attempt]), poses)
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
                   total("backtracks"), dict(failures), s.dropped, s.drops, len(runs), s.accepted)
