"""The string method's own instantiation (Kalojanov et al. 2019, section 6): objects placed breadth-first from the
walls, each at the relative pose its tagged cluster gives against an anchor already placed, with Monte-Carlo
repair.

An object is placed against one of its placed anchors: its support parent first, then its spatial anchors by
distance label (adjacent, proximal, distant; walls before objects), then objects it is itself an anchor of (the
cluster's pose inverted). Try ``i`` of ``placement.tries`` takes anchor ``i mod a`` and that edge's cluster of rank
``(i div a) mod k`` (clusters ranked by the tagger's voted probability); the first tries are the clusters' centres,
later ones add Gaussian noise of the cluster's spread (at least ``placement.min_jitter`` m) growing with ``i``. Each
candidate slides flush against the anchors it is planned adjacent to and back inside the walls (the search's own
:func:`~pipeline.placement.search.snap`), then must pass the project's placement checks
(:func:`~pipeline.placement.checks.check`) with relation tolerance ``placement.tolerance``. An object that no try
places is left out with the objects it supports (a partial scene, as the search's ``on_exhausted: drop``); an
object with no placed neighbour at all is put on a uniformly drawn free floor cell. No torch."""
from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass

import numpy as np

from ...graphs.data import edge_class
from ...placement.anchors import anchors_of, planned_edges
from ...placement.checks import check
from ...placement.layout import add_object, walls_of
from ...placement.plan import PlanEdge, ScenePlan
from ...placement.proposers import Grid
from ...placement.retrieval import place
from ...placement.search import Kit, Outcome, drop_reason, inside_walls, snap
from ...room import RoomInput, Walls
from .poses import anchor_frame, from_relative

Tag = tuple[np.ndarray, np.ndarray]  # a cluster's relative pose (3,) and spread (2,)


@dataclass(frozen=True)
class Placing:
    """One way to place an object: the plan edge, its ranked clusters, and whether the object is its target
    (else its anchor: the pose is inverted)."""
    edge: PlanEdge
    ranked: list[Tag]
    forward: bool


def bfs_order(plan: ScenePlan, roots: set[str]) -> list[int]:
    """Object indices breadth-first from ``roots`` (walls) along the plan's edges, an object only after its support
    parent; objects no edge reaches are started from in plan order (one whose parent is placed first; when support
    parents form a cycle or name no object, the first left, so the order always ends)."""
    pos = {v: k for k, v in enumerate(plan.ids)}
    nxt: dict[str, list[str]] = {}
    for e in plan.edges:
        nxt.setdefault(e.source, []).append(e.target)
    done: list[int] = []
    seen = set(roots)
    queue = deque(t for r in sorted(roots) for t in nxt.get(r, []))
    while len(done) < len(plan.ids):
        forced = None
        if not queue:
            left = [v for v in plan.ids if v not in seen]
            ready = [v for v in left if plan.parent[pos[v]] is None or plan.parent[pos[v]] in seen]
            forced = left[0] if not ready else None
            queue.append(ready[0] if ready else left[0])
        v = queue.popleft()
        k = pos.get(v)
        if k is None or v in seen or (v != forced and plan.parent[k] is not None and plan.parent[k] not in seen):
            continue
        seen.add(v)
        done.append(k)
        queue.extend(nxt.get(v, []))
        queue.extend(plan.ids[j] for j in range(len(plan.ids)) if plan.parent[j] == v)
    return done


def placings(v: str, plan: ScenePlan, present: set[str], walls: set[str], tags: dict) -> list[Placing]:
    """The ways to place ``v`` against nodes in ``present`` with a tagged edge (see the module for the order)."""
    def rank(e: PlanEdge) -> tuple:
        return (e.edge_type != "support", -e.weight, e.source not in walls)

    fwd = sorted((e for e in plan.edges if e.target == v and e.source in present), key=rank)
    back = [e for e in plan.edges if e.source == v and e.target in present and e.edge_type == "spatial"]
    out = [Placing(e, tags[key(e)], True) for e in fwd if key(e) in tags]
    return out + [Placing(e, tags[key(e)], False) for e in back if key(e) in tags]


def key(e: PlanEdge) -> tuple[str, str, int]:
    return e.source, e.target, edge_class(e.edge_type, e.direction, e.distance)


def pose_of(p: Placing, tag: Tag, room: RoomInput, walls: Walls) -> tuple[np.ndarray, float] | None:
    """The world centre and yaw a cluster pose gives the object (None when the other end has no frame)."""
    pose = tag[0]
    if p.forward:
        frame = anchor_frame(p.edge.source, room, walls)
        if frame is None:
            return None
        xy, yaw = from_relative(*frame, pose)
        return xy[0], float(yaw[0])
    other = anchor_frame(p.edge.target, room, walls)
    if other is None:
        return None
    yaw = other[0].yaw - pose[2]  # the target's yaw is the object's plus the pose's
    c, s = np.cos(yaw), np.sin(yaw)
    return np.asarray(other[0].origin) - np.array([c * pose[0] - s * pose[1], s * pose[0] + c * pose[1]]), float(yaw)


class Assembly:
    """One scene's assembly state: the room so far, the counts, the dropped objects."""

    def __init__(self, plan: ScenePlan, room: RoomInput, tags: dict, kit: Kit, cfg: dict, icfg: dict,
                 rng: np.random.Generator):
        self.plan, self.room, self.walls, self.tags = plan, room, walls_of(room), tags
        self.pool, self.checker = kit
        self.cfg, self.rng, self.snap_cfg, self.mpp = cfg, rng, icfg["snap"], icfg["grid_mpp"]
        self.sym = dict(zip(plan.ids, plan.symmetry))
        self.insertions = self.rejections = self.unanchored = 0
        self.failures: dict[str, int] = {}
        self.dropped: list[str] = []
        self.drops: list[dict] = []
        self.accepted: dict = {}
        self._floor_cells: np.ndarray | None = None

    def candidate(self, k: int, inst, i: int, ways: list[Placing]) -> tuple[np.ndarray, np.ndarray] | None:
        """Try ``i``'s box and pose for object ``k`` (see the module)."""
        v, parent = self.plan.ids[k], self.plan.parent[k]
        if ways:
            p = ways[i % len(ways)]
            tag = p.ranked[(i // len(ways)) % len(p.ranked)]
            got = pose_of(p, tag, self.room, self.walls)
            if got is None:
                return None
            xy, yaw = got
            grow = i / max(self.cfg["tries"] - 1, 1)
            if i >= len(ways) * len(p.ranked):
                xy = xy + self.rng.normal(0, 1, 2) * np.maximum(tag[1].max(), self.cfg["min_jitter"]) * grow
        else:
            cells = self.free_cells()
            if not len(cells):
                return None
            xy, yaw = cells[self.rng.integers(len(cells))], float(self.rng.integers(4) * np.pi / 2)
        pk = self.room.object_ids.index(parent) if parent in self.room.object_ids else None
        support = None if pk is None else float(self.room.boxes[pk, 2] + self.room.boxes[pk, 5])
        box, _ = place(inst, xy[0], xy[1], support, yaw)
        box = snap(box, anchors_of(v, self.plan, self.room, self.walls, self.sym, inst.half[:2]), self.room, self.walls,
                   self.checker.extract_cfg, self.snap_cfg)
        if pk is None:
            box = inside_walls(box, self.walls, self.snap_cfg["gap"], self.snap_cfg["reach"])
        return place(inst, box[0], box[1], support, yaw)

    def free_cells(self) -> np.ndarray:
        """``(m, 2)`` centres of the search's candidate cells on the floor (rasterised once per scene)."""
        if self._floor_cells is None:
            grid = Grid(self.room.outline, self.mpp)
            self._floor_cells = grid.points[grid.floor]
        return self._floor_cells

    def place_one(self, k: int) -> bool:
        """Place object ``k`` within ``placement.tries``; False when none passes the checks."""
        v, cat = self.plan.ids[k], self.plan.categories[k]
        present = set(self.room.object_ids) | set(self.walls.ids)
        ways = placings(v, self.plan, present, set(self.walls.ids), self.tags)
        self.unanchored += not ways
        inst = self.pool.pick(cat, self.plan.symmetry[k], self.rng, self.plan.parent[k] is None)
        parent = self.plan.parent[k]
        pk = self.room.object_ids.index(parent) if parent in self.room.object_ids else None
        planned = planned_edges(v, self.plan, present)
        for i in range(self.cfg["tries"]):
            cand = self.candidate(k, inst, i, ways)
            if cand is None:
                continue
            room = add_object(self.room, v, cat, inst.model_id, *cand)
            verdict = check(room, len(room.object_ids) - 1, pk, set(), planned, self.cfg["tolerance"], self.checker)
            if verdict.ok:
                self.room, self.insertions = room, self.insertions + 1
                self.accepted.update(verdict.edge_costs)
                return True
            self.rejections += 1
            kind = verdict.reason.split(" ")[0]
            self.failures[kind] = self.failures.get(kind, 0) + 1
        return False

    def drop(self, k: int, cause: str) -> None:
        self.dropped.append(self.plan.ids[k])
        self.drops.append({"id": self.plan.ids[k], "category": self.plan.categories[k], "cause": cause, "check": None})

    def run(self) -> None:
        for k in bfs_order(self.plan, set(self.walls.ids)):
            if not self.pool.has(self.plan.categories[k]):
                self.drop(k, "no_model")
            elif self.plan.parent[k] in self.dropped:
                self.drop(k, "support_dropped")
            elif not self.place_one(k):
                self.drop(k, "no_place")


def assemble(plan: ScenePlan, room: RoomInput, tags: dict, kit: Kit, cfg: dict, icfg: dict,
             seed: int) -> tuple[Outcome, Walls, int]:
    """Place the plan's objects in ``room`` (its architecture) with the ``kit``'s instances and checker; ``tags``: plan
    edge key (:func:`key`) -> its clusters ranked; ``cfg``: ``strings.tagger.placement``; ``icfg``: the
    ``instantiate`` section (snapping, grid). Returns the outcome (the search's record: no backtracks), the walls and
    the objects placed with no anchor."""
    start = time.perf_counter()
    a = Assembly(plan, room, tags, kit, cfg, icfg, np.random.default_rng(seed))
    a.run()
    reason = drop_reason(a.drops, len(plan.ids)) if a.dropped else ""
    outcome = Outcome(True, a.room, reason, time.perf_counter() - start, a.insertions, a.rejections, 0, a.failures,
                      a.dropped, a.drops, 1, a.accepted)
    return outcome, a.walls, a.unanchored

