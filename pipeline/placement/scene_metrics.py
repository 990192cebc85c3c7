"""How a placed room compares with its plan: the planned edges its extracted graph holds again (graph
consistency), the unplanned ones, the violation cost, and the objects that collide. Same predicates as the
search's checks (:mod:`pipeline.placement.checks`)."""
from __future__ import annotations

import json
from collections import Counter

import numpy as np

from ..room import RoomInput
from .checks import Checker, collision, edge_cost, found_edges
from .plan import ScenePlan


def consistency(plan: ScenePlan, room: RoomInput, walls_ids: list[str], checker: Checker, dropped=(),
                accepted: dict | None = None) -> dict:
    """Counts over the planned edges whose two ends are in the room or among the ``dropped`` plan ids (a partial
    scene's edges to what it left out are edges not found), and the lost ones by cause (:func:`plan_loss`;
    ``accepted``: the search's cost of each edge when it was placed)."""
    present = set(room.object_ids) | set(walls_ids)
    counted = present | set(dropped)
    edges = checker.extract(room).edges
    found = found_edges(edges)
    planned = [e for e in plan.edges if e.source in counted and e.target in counted]
    costs = np.array([edge_cost(e, found) for e in planned])
    pairs = {(e.source, e.target) for e in planned}
    objects = set(room.object_ids)
    extra = [e for e in edges if e["edge_type"] in ("support", "spatial") and (e["source"], e["target"]) not in pairs
             and (e["source"] in objects or e["target"] in objects)]
    loss = plan_loss(planned, costs, found, set(dropped), accepted or {})
    return {"planned_edges": len(planned), "found_edges": int((costs == 0).sum()), "plan_loss": json.dumps(loss),
            "consistency": float((costs == 0).mean()) if len(costs) else 1.0,
            "violation": float(costs.mean()) if len(costs) else 0.0, "unplanned_edges": len(extra),
            "unplanned_adjacent": sum(e["edge_type"] == "support" or e.get("distance") == "adjacent" for e in extra)}


def relation_of(edge) -> str:
    """An edge's relation for the loss tables: support, or its spatial distance label."""
    return "support" if edge.edge_type == "support" else str(edge.distance)


def plan_loss(planned: list, costs: np.ndarray, found: dict, dropped: set, accepted: dict) -> dict:
    """Relation -> counts of its ``planned`` edges: ``planned``, and for those not found (cost > 0) when the search
    lost them (``unplaced``: an end dropped; ``relaxed``: accepted with a cost; ``lost_later``: accepted intact, broken
    after) and what extraction finds instead (``distance``, ``direction``, ``absent``)."""
    out: dict = {}
    for e, c in zip(planned, costs):
        row = out.setdefault(relation_of(e), Counter())
        row["planned"] += 1
        if c == 0:
            continue
        row["unplaced" if {e.source, e.target} & dropped else "relaxed" if accepted.get(e, 0.0) > 0 else "lost_later"] += 1
        got = [g for g in found.get((e.source, e.target), []) if g[0] == e.edge_type]
        row["distance" if any(g[1] == e.direction for g in got) else "direction" if got else "absent"] += 1
    return {k: dict(v) for k, v in sorted(out.items())}


def colliding_objects(room: RoomInput, parents: dict[str, str | None], checker: Checker) -> int:
    """Objects that penetrate another (not their support or what they support) deeper than ``checks.collision``."""
    ids = room.object_ids
    count = 0
    for k, o in enumerate(ids):
        related = {j for j, u in enumerate(ids) if parents.get(u) == o or parents.get(o) == u}
        count += collision(room, k, related, checker) is not None
    return count
