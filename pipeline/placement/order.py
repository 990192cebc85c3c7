"""The order objects are placed in (PlanIT section 6): topological, depth-first, the most constrained first (C_in,
weights adjacent 3 : proximal 2 : distant 1), then the most constraining (C_out: C_in times the expected
footprint area^0.8 over the inclusive descendants); a hub's spokes right after it; a chain as one unit; supported
(second-tier) objects after every floor object; an object before the facing partner the plan puts against a wall
(:func:`facing_first`, a departure)."""
from __future__ import annotations

from collections.abc import Sequence
from itertools import combinations

import networkx as nx
import numpy as np

from ..room import Walls
from .plan import ScenePlan
from .walls import PARALLEL_COS

AREA_POWER = 0.8


def constraint_scores(plan: ScenePlan, mean_area: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """``C_in (n,)`` and ``C_out (n,)`` of the plan's objects."""
    n = len(plan.ids)
    pos = {v: k for k, v in enumerate(plan.ids)}
    c_in = np.zeros(n)
    children: list[set[int]] = [set() for _ in range(n)]
    for e in plan.edges:
        if e.target in pos:
            c_in[pos[e.target]] += e.weight
            if e.source in pos:
                children[pos[e.source]].add(pos[e.target])
    size = np.array([mean_area.get(c, 0.25) for c in plan.categories]) ** AREA_POWER
    c_out = np.zeros(n)
    for v in range(n):
        seen, stack = {v}, [v]
        while stack:
            for u in children[stack.pop()] - seen:
                seen.add(u)
                stack.append(u)
        c_out[v] = sum(c_in[u] * size[u] for u in seen)
    return c_in, c_out


def chains(plan: ScenePlan) -> list[list[int]]:
    """Chains as lists of object indices in chain order: components of chain-role objects joined by spatial
    edges, each started at a member no other member points to."""
    member = {k for k, r in enumerate(plan.role) if "chain" in r}
    pos = {v: k for k, v in enumerate(plan.ids)}
    nxt: dict[int, set[int]] = {k: set() for k in member}
    for e in plan.edges:
        s, t = pos.get(e.source), pos.get(e.target)
        if e.edge_type == "spatial" and s in member and t in member:
            nxt[s].add(t)
    out, done = [], set()
    for start in sorted(member, key=lambda k: (any(k in v for v in nxt.values()), k)):
        if start in done:
            continue
        unit, stack = [], [start]
        while stack:
            k = stack.pop()
            if k in done:
                continue
            done.add(k)
            unit.append(k)
            stack += sorted(nxt[k] - done, reverse=True)
            stack += sorted({s for s, ts in nxt.items() if k in ts} - done, reverse=True)
        out.append(unit)
    return out


def facing_first(plan: ScenePlan, partners: dict[tuple[str, str], float], walls: Walls) -> list[tuple[int, int]]:
    """``(first, then)`` pairs of the plan's floor objects: an object whose category faces the other's in the
    training rooms (``partners``: (partner category, object category) -> share, :func:`~pipeline.placement.facing.
    learn_facing_partners`) goes before that partner when the plan puts the partner adjacent to one of ``walls`` and
    the object adjacent to none, with no planned edge to an object of the partner's category (an office chair
    planned at its own desk faces that one) and no planned path from the partner to it.
    Placed first, the object is drawn facing the partner's wall (``FacingPartner``'s stand-in) and the partner, back to
    its wall, slides along it onto the object's line (``Centred``); placed second, a wall edge holding it beside another
    wall (a sofa's end 0.2 m from a side wall) keeps it off the partner's line. Not when the plan puts the partner
    adjacent to two walls that meet (a corner): the corner holds its place along each wall, so it goes first and the
    object faces it where it stands."""
    pos = {v: k for k, v in enumerate(plan.ids)}
    graph = nx.DiGraph([(pos[e.source], pos[e.target]) for e in plan.edges if e.source in pos and e.target in pos])
    graph.add_nodes_from(range(len(plan.ids)))
    normal = dict(zip(walls.ids, walls.normal))
    at_wall: dict[int, list[str]] = {}
    for e in plan.edges:
        if e.source in normal and e.target in pos and e.edge_type == "spatial" and e.distance == "adjacent":
            at_wall.setdefault(pos[e.target], []).append(e.source)
    cornered = {k for k, ids in at_wall.items() if any(abs(normal[a] @ normal[b]) < PARALLEL_COS for a, b in
                                                      combinations(ids, 2))}
    floor = [k for k, parent in enumerate(plan.parent) if parent is None]
    joined = lambda k, cat: any(plan.categories[u] == cat for u in nx.all_neighbors(graph, k))
    return [(k, j) for k in floor if k not in at_wall for j in floor if j in at_wall and j not in cornered
            and (plan.categories[j], plan.categories[k]) in partners
            and not joined(k, plan.categories[j]) and not nx.has_path(graph, j, k)]


def placement_order(plan: ScenePlan, mean_area: dict[str, float], constrained: bool = True,
                    rng: np.random.Generator | None = None, first: Sequence[tuple[int, int]] = ()) -> list[int]:
    """Object indices in placement order. ``constrained=False`` (the ablation): a seeded random order that keeps
    only floor objects before supported ones. ``first``: ``(first, then)`` pairs placed in that order as if ``then``
    were planned with an edge from ``first`` (:func:`facing_first`)."""
    n = len(plan.ids)
    tier2 = np.array([t >= 2 for t in plan.tier], bool)
    if not constrained:
        rng = rng or np.random.default_rng(0)
        return [int(k) for k in rng.permutation(np.flatnonzero(~tier2))] + [int(k) for k in rng.permutation(np.flatnonzero(tier2))]
    c_in, c_out = constraint_scores(plan, mean_area)
    pos = {v: k for k, v in enumerate(plan.ids)}
    anchors: list[set[int]] = [set() for _ in range(n)]
    spokes: list[list[int]] = [[] for _ in range(n)]
    for e in plan.edges:
        s, t = pos.get(e.source), pos.get(e.target)
        if s is not None and t is not None:
            anchors[t].add(s)
            if "hub" in plan.role[s] and plan.role[t] == "spoke":
                spokes[s].append(t)
    for k, j in first:
        anchors[j].add(k)
    unit_of = {k: u for u in chains(plan) for k in u}
    order: list[int] = []
    placed_at: dict[int, int] = {}
    for phase in (np.flatnonzero(~tier2), np.flatnonzero(tier2)):
        pending = set(int(k) for k in phase)
        while pending:
            ready = [v for v in pending if not (anchors[v] & pending)] or sorted(pending)  # a cycle: break it
            v = max(ready, key=lambda k: (max((placed_at.get(a, -1) for a in anchors[k]), default=-1), c_in[k], c_out[k], -k))
            batch = unit_of.get(v, [v])
            for u in batch:
                batch = batch + [s for s in spokes[u] if s not in batch]
            for u in batch:
                if u in pending:
                    pending.discard(u)
                    placed_at[u] = len(order)
                    order.append(u)
    return order
