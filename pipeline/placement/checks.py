"""Whether a newly placed object may stay: inside the floor, resting on its support, not colliding, and keeping its
planned relations. Every predicate is the one the rest of the pipeline uses: the filter's outline and
penetration tests (meshes via Embree) and the extraction itself for the relations, so a placed room's extracted
graph is comparable with its plan."""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import shapely

from ..extraction import extract_room
from ..geometry import boxes
from ..geometry.collision import CollisionTest, deepest_penetration
from ..geometry.polygon import outside_area
from ..room import RoomInput, door_zones_of
from .plan import PlanEdge
from .walkable import FloorKept

AREA_EPS = 1e-4  # m^2: overlaps of polygons under 1 cm^2 are numerical


@dataclass
class Verdict:
    ok: bool
    reason: str = ""
    cost: float = 0.0  # violation cost of the object's planned relations, in [0, 1]
    culprits: set[str] = field(default_factory=set)  # placed objects that caused the failure
    edge_costs: list = field(default_factory=list)  # (PlanEdge, cost) of the object's planned relations
    found: dict = field(default_factory=dict)  # the extracted edges by (source, target) (found_edges), when measured


def checks_config(config: dict) -> dict:
    """The ``instantiate.checks`` thresholds with the evaluation's penetration measure as ``confirm``: a pair the
    coarse per-attempt grid clears is measured again the way the evaluation measures it (no second measure when the
    per-attempt measure is the evaluation's)."""
    own, evaluation = config["instantiate"]["checks"], config["evaluate"]["collision"]["penetration"]
    return {**own, "confirm": None if own["penetration"] == evaluation else evaluation}


def required_support(min_support: float, support_floor: dict[str, float], category: str) -> float:
    """The share of its footprint an object of ``category`` must keep over its support: ``min_support`` (PlanIT's
    0.9), lowered to the category's floor learned from the training rooms (:mod:`pipeline.placement.support`)."""
    return min(min_support, support_floor.get(category, 1.0))


@dataclass
class Checker:
    """What the checks need besides the room: meshes (model id -> (vertices, faces)), box-only models, the model ->
    symmetry table, the extraction config (the ``extract`` section plus ``floor_contact``), the ray backend class
    and the ``instantiate.checks`` thresholds (:func:`checks_config`: with the evaluation's measure to confirm)."""
    meshes: dict
    box_models: set
    symmetry: dict
    extract_cfg: dict
    intersector: type
    cfg: dict
    support_floor: dict = field(default_factory=dict)  # category -> learned lower min_support (placement/support.py)
    wall_bound: frozenset = frozenset()  # categories whose planned wall adjacency is never broken (placement/walls.py)
    weighted: bool = False  # an object's relation cost weighs each edge by its plan weight (instantiate.weighted_relations)
    floor_kept: FloorKept | None = None  # the least walkable share a floor object may leave (placement/walkable.py)

    @cached_property
    def collision_test(self) -> CollisionTest:
        """The ``penetration`` measure at the ``collision`` limit, confirmed by ``confirm`` where given."""
        return CollisionTest.of(self.cfg["penetration"], self.cfg["collision"], self.intersector, self.cfg.get("confirm"))

    def min_support(self, category: str) -> float:
        """The share of its footprint an object of ``category`` must keep over its support."""
        return required_support(self.cfg["min_support"], self.support_floor, category)

    def meshes_of(self, room: RoomInput) -> list:
        """Each object's ``(vertices, faces)``, or None where it is measured as its box."""
        return [None if m in self.box_models else self.meshes.get(m) for m in room.model_ids]

    def extract(self, room: RoomInput, anchors: set[str] | None = None):
        """The room's relation graph; with ``anchors`` (ids), only the spatial edges from them."""
        return extract_room(room, self.meshes.get, lambda c, m: (self.symmetry.get(m, "none"), "table"),
                            self.extract_cfg, self.intersector, self.box_models, anchors)


def support_shares(children: np.ndarray, parents: np.ndarray) -> np.ndarray:
    """``(m,)`` share of each child's footprint over its parent's (boxes ``(m, 7)`` each), vectorised."""
    c, p = (shapely.polygons(boxes.footprint_corners(b[:, 0], b[:, 1], b[:, 3], b[:, 4], b[:, 6]))
            for b in (np.asarray(children, float).reshape(-1, 7), np.asarray(parents, float).reshape(-1, 7)))
    return shapely.area(shapely.intersection(c, p)) / np.maximum(shapely.area(c), 1e-12)


def centred_shares(half: np.ndarray, support_half: np.ndarray) -> np.ndarray:
    """``(n, m)`` share of the footprint of each of the half extents ``half (m, >= 2)`` (m) over a support of each of
    ``support_half (n, >= 2)``, centred on its top and square to it, the better of the two square turns: what
    :func:`support_shares` measures for such a place (the overlap of two centred rectangles), in closed form."""
    h, s = np.asarray(half, float)[None, :, :2], np.asarray(support_half, float)[:, None, :2]
    area = np.maximum(h.prod(-1), 1e-12)
    out: np.ndarray = np.maximum(np.minimum(h, s).prod(-1), np.minimum(h[..., ::-1], s).prod(-1)) / area
    return out


def fits_on(half: np.ndarray, support_half: np.ndarray, least: float) -> np.ndarray:
    """``(n, m)`` bool: a footprint of each of the half extents ``half (m, >= 2)`` (m), centred on a support of each of
    ``support_half (n, >= 2)`` and square to it either way, keeps at least ``least`` of its area over it
    (:func:`centred_shares`): the best any place on the support can do for it turned square."""
    out: np.ndarray = centred_shares(half, support_half) >= least - 1e-9
    return out


def support_share(child: np.ndarray, parent: np.ndarray) -> float:
    """Share of the child's footprint over the parent's (boxes ``(7,)``)."""
    return float(support_shares(child[None], parent[None])[0])


def collision(room: RoomInput, k: int, related: set[int], checker: Checker) -> tuple[int, float] | None:
    """The placed object object ``k`` penetrates deepest beyond ``checks.collision`` (meshes where both have one,
    else boxes), ignoring ``related`` (its support parent and children); None when it collides with none."""
    depth = np.zeros((len(room.boxes),) * 2)
    row = boxes.penetration_depths(room.boxes)[k]
    row[list(related)] = 0.0
    depth[k], depth[:, k] = row, row
    objs = {"meshes": checker.meshes_of(room), "poses": room.poses}
    hit = deepest_penetration(depth, objs, checker.collision_test)
    return None if hit is None else (hit[1] if hit[0] == k else hit[0], hit[2])


def edge_cost(planned: PlanEdge, found: dict) -> float:
    """0 when extraction finds the planned edge; 0.5 for a spatial edge found with another distance; else 1."""
    got = found.get((planned.source, planned.target), [])
    if planned.edge_type == "support":
        return 0.0 if any(g[0] == "support" for g in got) else 1.0
    spatial = [g for g in got if g[0] == "spatial"]
    if any(g[1] == planned.direction and g[2] == planned.distance for g in spatial):
        return 0.0
    return 0.5 if any(g[1] == planned.direction for g in spatial) else 1.0


def found_edges(edges: list[dict]) -> dict:
    """Extracted edge rows by (source, target): lists of (edge_type, direction, distance)."""
    out: dict = {}
    for e in edges:
        out.setdefault((e["source"], e["target"]), []).append((e["edge_type"], e.get("direction"), e.get("distance")))
    return out


def blocks_door(room: RoomInput, corners: np.ndarray, depth: float) -> bool:
    """Whether a floor footprint ``corners (4, 2)`` covers more than 1 cm^2 of the zone ``depth`` m deep inside any
    door of the room (0: no zone)."""
    zones = door_zones_of(room, depth)
    if not len(zones):
        return False
    overlap = shapely.area(shapely.intersection(shapely.polygons(zones), shapely.Polygon(corners)))
    return bool((overlap > AREA_EPS).any())


def relation_cost(room: RoomInput, planned: list[PlanEdge], checker: Checker) -> tuple[float, set[str], list[float], dict]:
    """Mean cost of ``planned`` edges (each between the new object and a node already in the room) on the room's
    extracted graph (weighted by the edges' plan weights, adjacent 3 : proximal 2 : distant 1, when
    ``checker.weighted``; PlanIT splits it evenly), the objects at the other end of the edges not found exactly, each
    edge's cost, and the extracted edges (:func:`found_edges`)."""
    if not planned:
        return 0.0, set(), [], {}
    found = found_edges(checker.extract(room, anchors={e.source for e in planned}).edges)
    costs = [edge_cost(e, found) for e in planned]
    objects = set(room.object_ids)
    blame = {n for e, c in zip(planned, costs) if c > 0 for n in (e.source, e.target) if n in objects}
    weights = [e.weight if checker.weighted else 1.0 for e in planned]
    return float(np.average(costs, weights=weights)), blame, costs, found


def check(room: RoomInput, k: int, parent: int | None, children: set[int], planned: list[PlanEdge],
          tolerance: float, checker: Checker) -> Verdict:
    """Verdict on object ``k`` of ``room`` (cheap tests first; the mesh collision test after the relations when
    ``checks.relations_first``: most candidates break a relation, and the mesh test is the dearer). ``tolerance``: the
    violation cost allowed now; an object may never break all of its relations fully."""
    me = room.object_ids[k]
    corners = boxes.footprint_corners(*room.boxes[k, [0, 1, 3, 4, 6]])[0]
    if parent is None:
        outside = float(outside_area(room.outline, corners[None], checker.cfg["outside"])[0])
        if outside > AREA_EPS:  # the evaluation's out-of-bounds test, with the check's own margin
            return Verdict(False, f"outside the floor ({outside * 1e4:.0f} cm^2 beyond a {checker.cfg['outside']} m margin)")
        if blocks_door(room, corners, checker.cfg["door_clearance"]):
            return Verdict(False, "blocks a door's clearance")
    elif support_share(room.boxes[k], room.boxes[parent]) < checker.min_support(room.categories[k]):
        return Verdict(False, "overhangs its support", culprits={room.object_ids[parent]})
    related = children | ({parent} if parent is not None else set())
    if not checker.cfg["relations_first"]:
        hit = collision(room, k, related, checker)
        if hit is not None:
            return collides(room, hit)
    cost, blame, costs, found = relation_cost(room, planned, checker)
    blame.discard(me)
    if cost > tolerance or (cost >= 1.0 and planned):
        return Verdict(False, f"violates its relations (cost {cost:.2f})", cost, blame)
    if room.categories[k] in checker.wall_bound and leaves_wall(me, set(room.object_ids), planned, costs):
        return Verdict(False, "leaves its planned wall", cost, blame)
    if checker.cfg["relations_first"]:
        hit = collision(room, k, related, checker)
        if hit is not None:
            return collides(room, hit)
    if parent is None and checker.floor_kept is not None:
        closed = checker.floor_kept.closes(room, k)
        if closed is not None:
            return Verdict(False, f"closes the floor off from the door (walkable share {closed[0]:.2f} -> {closed[1]:.2f})", cost)
    return Verdict(True, cost=cost, edge_costs=list(zip(planned, costs)), found=found)


def leaves_wall(me: str, objects: set[str], planned: list[PlanEdge], costs: list[float]) -> bool:
    """Whether object ``me`` breaks a planned "adjacent" edge from a wall (a source that is no object: openings
    source no spatial edge)."""
    return any(c > 0 for e, c in zip(planned, costs) if e.target == me and e.source not in objects
               and e.edge_type == "spatial" and e.distance == "adjacent")


def collides(room: RoomInput, hit: tuple[int, float]) -> Verdict:
    return Verdict(False, f"collides with {room.object_ids[hit[0]]} by {hit[1]:.3f} m", culprits={room.object_ids[hit[0]]})
