"""Refinement of one room's raw relation graph into a training graph (appendix A; authors' order).

Order: chains -> hubs (dataset-frequent patterns) -> double-edge resolution -> hub and chain edge
inheritance -> wall edges that are not adjacent -> statistical pruning with the keep rules ->
connectivity repair. Every raw edge stays in the output with ``status`` (kept | pruned) and the ``rule``
that decided it; edges the refinement adds have ``origin = derived``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import networkx as nx

from .superstructures import DIRECTION_PREFERENCE, Chain, Hub, node_index, room_candidates, select_hubs

ARCHITECTURE_EDGES = ("wall_adjacent", "wall_opposite", "opening")
UNIQUE_FRONT = ("none", "left-right")


@dataclass
class Stats:
    """Dataset-wide statistics the refinement reads (from the graph_statistics stage)."""
    relfreq: dict[tuple, float] = field(default_factory=dict)  # (room_type, cat_a, cat_b, direction, distance)
    hub_patterns: dict[str, set[tuple[str, str]]] = field(default_factory=dict)  # room_type -> accepted patterns
    category_area: dict[tuple[str, str], float] = field(default_factory=dict)  # (room_type, category) -> m^2


@dataclass
class Refined:
    nodes: list[dict]
    edges: list[dict]
    superstructures: list[dict]
    cyclic: bool
    repaired: int


def refine_room(nodes: list[dict], raw_edges: list[dict], stats: Stats, cfg: dict,
                candidates: tuple[list[Chain], list[Hub]] | None = None) -> Refined:
    """Refine one room. ``cfg`` is the ``refine`` config section; ``candidates`` are the room's chains and hub
    candidates as the statistics map step found them (computed here when not given)."""
    room_type = nodes[0]["room_type"] if nodes else ""
    idx = node_index(nodes)
    edges = [dict(e, status="kept", rule=None, origin="raw", group_id=None) for e in raw_edges]
    chains, hub_cands = candidates if candidates is not None else room_candidates(idx, edges, cfg)
    hubs = select_hubs(hub_cands, idx, stats.hub_patterns.get(room_type, set()))
    supers = _mark_superstructures(edges, hubs, chains)
    _resolve_double_edges(edges, idx, stats, room_type)
    _inherit_hub_edges(edges, hubs)
    _inherit_chain_edges(edges, chains)
    _decide(edges, idx, stats, room_type, cfg)
    repaired = _repair_connectivity(edges, idx, cfg)
    _break_cycles(edges, idx, stats, room_type)
    cyclic = _has_cycle(edges)
    out_nodes = _node_roles(nodes, hubs, chains)
    for e in edges:
        if e.get("room_type") is None:
            e["room_type"] = room_type
    return Refined(out_nodes, edges, supers, cyclic, repaired)


# ----------------------------------------------------------------------------------- superstructures
def _mark_superstructures(edges: list[dict], hubs: list[Hub], chains: list[Chain]) -> list[dict]:
    rows = []
    by_pair = {(e["source"], e["target"]): e for e in edges if e["edge_type"] == "spatial"}
    for k, h in enumerate(hubs):
        gid = f"hub_{k}"
        for s in h.spokes:
            by_pair[(h.hub, s)]["group_id"] = gid
            rows.append({"group_id": gid, "kind": "hub", "anchor_id": h.hub, "member_id": s, "position": None,
                         "direction": h.directions[s], "label": None})
    for k, c in enumerate(chains):
        gid = f"chain_{k}"
        for a, b in zip(c.members, c.members[1:]):
            by_pair[(a, b)]["group_id"] = gid
        for pos, m in enumerate(c.members):
            rows.append({"group_id": gid, "kind": "chain", "anchor_id": c.members[0], "member_id": m, "position": pos,
                         "direction": c.direction, "label": c.label})
    return rows


def _prune(e: dict, rule: str) -> None:
    if e["status"] == "kept":
        e["status"], e["rule"] = "pruned", rule


def _resolve_double_edges(edges: list[dict], idx: dict, stats: Stats, room_type: str) -> None:
    """A -> B and B -> A: keep one (superstructure edge; else larger -> smaller; same category: F > B > R > L)."""
    by_pair = {(e["source"], e["target"]): e for e in edges if e["edge_type"] == "spatial"}
    for (a, b), e in by_pair.items():
        back = by_pair.get((b, a))
        if back is None or a > b or e["status"] != "kept" or back["status"] != "kept":
            continue
        if (e["group_id"] is None) != (back["group_id"] is None):
            loser = back if e["group_id"] is not None else e
        elif idx[a]["category"] != idx[b]["category"]:
            size = lambda n: (stats.category_area.get((room_type, idx[n]["category"]), 0.0), idx[n]["diag"])  # noqa: E731
            loser = back if size(a) >= size(b) else e
        else:
            rank = lambda x: (DIRECTION_PREFERENCE.index(x["direction"]), x["source"])  # noqa: E731
            loser = back if rank(e) <= rank(back) else e
        _prune(loser, "double_edge")


def _derived(template: dict, source: str, target: str, rule: str, **changes) -> dict:
    e = dict(template, source=source, target=target, origin="derived", status="kept", rule=rule, group_id=None)
    e.update(changes)
    return e


def _inherit_hub_edges(edges: list[dict], hubs: list[Hub]) -> None:
    """The hub inherits its spokes' inbound edges (adjacent ones as proximal); spokes keep only the hub's
    edge and adjacent relations."""
    existing = {(e["source"], e["target"]) for e in edges}
    for h in hubs:
        spokes = set(h.spokes)
        for e in list(edges):
            if e["edge_type"] != "spatial" or e["target"] not in spokes or e["source"] in spokes or e["source"] == h.hub:
                continue
            if e["status"] == "kept" and (e["source"], h.hub) not in existing:
                dist = "proximal" if e["distance"] == "adjacent" else e["distance"]
                edges.append(_derived(e, e["source"], h.hub, "hub_inherited", distance=dist))
                existing.add((e["source"], h.hub))
            if e["distance"] != "adjacent":
                _prune(e, "spoke_inbound")


def _inherit_chain_edges(edges: list[dict], chains: list[Chain]) -> None:
    """Intermediate chain nodes drop their inbound edges and inherit those common to the chain's start and end."""
    existing = {(e["source"], e["target"]) for e in edges}
    for c in chains:
        start, end, middle = c.members[0], c.members[-1], set(c.members[1:-1])
        inbound = lambda n: {e["source"]: e for e in edges if e["target"] == n and e["edge_type"] == "spatial" and e["status"] == "kept"}  # noqa: E731
        common = set(inbound(start)) & set(inbound(end))
        template = inbound(start)
        for e in edges:
            if e["edge_type"] == "spatial" and e["target"] in middle and e["group_id"] is None and e["source"] not in common:
                _prune(e, "chain_member_inbound")
        for m in sorted(middle):
            for src in sorted(common - set(c.members)):
                if (src, m) not in existing:
                    edges.append(_derived(template[src], src, m, "chain_inherited"))
                    existing.add((src, m))


# ----------------------------------------------------------------------------------- keep / prune rules
def _decide(edges: list[dict], idx: dict, stats: Stats, room_type: str, cfg: dict) -> None:
    mode = cfg["pruning"]
    scale = {"full": 1.0, "half": 0.5, "none": 0.0}[mode]
    for e in edges:
        if e["status"] != "kept" or e["rule"] is not None:
            continue
        t = e["edge_type"]
        a, b = idx.get(e["source"]), idx.get(e["target"])
        if t == "support":
            e["rule"] = "keep_support"
        elif t in ARCHITECTURE_EDGES:
            e["rule"] = "keep_architecture"
        elif a["kind"] != "object":
            if e["distance"] == "adjacent":
                e["rule"] = "keep_wall_adjacent"
            else:
                _prune(e, "wall_not_adjacent")
        elif e["group_id"] is not None:
            e["rule"] = "keep_superstructure"
        elif a["symmetry"] in UNIQUE_FRONT and e["direction"] == "front" and e["distance"] == "proximal":
            e["rule"] = "keep_unique_front_proximal"
        elif e["distance"] == "adjacent" and a["category"] == b["category"]:
            e["rule"] = "keep_same_category_adjacent"
        elif mode == "none":
            e["rule"] = "no_pruning"
        else:
            freq = stats.relfreq.get((room_type, a["category"], b["category"], e["direction"], e["distance"]), 0.0)
            if freq >= scale * cfg["thresholds"][e["distance"]]:
                e["rule"] = "frequent"
            else:
                _prune(e, "infrequent")


# ----------------------------------------------------------------------------------- connectivity
def _kept_graph(edges: list[dict], idx: dict) -> nx.DiGraph:
    g = nx.DiGraph()
    g.add_nodes_from(idx)
    g.add_edges_from((e["source"], e["target"]) for e in edges if e["status"] == "kept")
    return g


def _reachable(g: nx.DiGraph, idx: dict) -> set[str]:
    roots = [n for n, v in idx.items() if v["kind"] != "object"]
    seen = set(roots)
    for r in roots:
        seen |= nx.descendants(g, r)
    return seen


def _repair_connectivity(edges: list[dict], idx: dict, cfg: dict) -> int:
    """Make every object reachable from the architecture with the cheapest pruned paths (appendix A.3).

    Tiers: adjacent and support edges only, then proximal, then distant; within a tier, paths that
    create no cycle first. Proximal edges may not run from a much smaller object to a larger one of
    another category (unless from a wall), and no edge whose reverse is kept may come back (that would undo
    double-edge resolution). Objects still unreachable get a distant edge from the nearest wall.
    """
    cc = cfg["connectivity"]
    repaired = 0
    kept = _kept_graph(edges, idx)
    reach = _reachable(kept, idx)
    # roots of the unreachable part first: reaching them makes their kept descendants reachable, cycle-free
    missing = sorted((n for n, v in idx.items() if v["kind"] == "object" and n not in reach),
                     key=lambda n: (any(p not in reach for p in kept.predecessors(n)), n))
    tiers = [("support", "adjacent"), ("support", "adjacent", "proximal"), ("support", "adjacent", "proximal", "distant")]
    for target in missing:
        if target in reach:
            continue
        path = None
        for allow_cycles in (False, True):  # any acyclic path beats every cycle-creating one
            for allowed in tiers:
                path = _cheapest_path(edges, idx, (kept, reach), target, (allowed, allow_cycles), cc)
                if path:
                    break
            if path:
                break
        if path:
            for e in path:
                e["status"], e["rule"] = "kept", "connectivity"
        else:
            wall = _nearest_wall(idx, target)
            e = {k: None for k in edges[0]} if edges else {}
            e.update(room_id=idx[target]["room_id"], room_type=idx[target]["room_type"], source=wall, target=target,
                     edge_type="spatial", direction="front", distance="distant", origin="derived", status="kept",
                     rule="connectivity_fallback", group_id=None)
            edges.append(e)
        repaired += 1
        kept = _kept_graph(edges, idx)
        reach = _reachable(kept, idx)
    return repaired


def _cheapest_path(edges: list[dict], idx: dict, sofar: tuple, target: str, tier: tuple,
                   cc: dict) -> list[dict] | None:
    """The cheapest pruned edges that join ``target`` to what ``sofar`` (the kept graph, the nodes it reaches) reaches,
    among the ``tier``'s (edge kinds allowed, whether a path may close a cycle); None: none."""
    (kept, reach), (allowed, allow_cycles) = sofar, tier
    g = nx.DiGraph()
    costs = cc["costs"]
    for e in edges:
        if e["status"] == "kept":
            continue
        kind = "support" if e["edge_type"] == "support" else e["distance"]
        if kind not in allowed or e["edge_type"] not in ("spatial", "support"):
            continue
        a, b = idx[e["source"]], idx[e["target"]]
        if (kind == "proximal" and a["kind"] == "object" and a["category"] != b["category"]
                and a["diag"] < cc["smaller_to_larger_ratio"] * b["diag"]):
            continue
        if kept.has_edge(e["target"], e["source"]):
            continue
        if not allow_cycles and (e["target"] in reach or nx.has_path(kept, e["target"], e["source"])):
            continue
        w = costs[kind] + (max(e["gap"] or 0.0, 0.0) if kind == "distant" else 0.0)
        if not g.has_edge(e["source"], e["target"]) or g[e["source"]][e["target"]]["w"] > w:
            g.add_edge(e["source"], e["target"], w=w, edge=e)
    sources = sorted(n for n in reach if n in g)  # sorted: set order would follow PYTHONHASHSEED
    if target not in g or not sources:
        return None
    try:
        _, nodes = nx.multi_source_dijkstra(g, sources, target, weight="w")
    except nx.NetworkXNoPath:
        return None
    return [g[u][v]["edge"] for u, v in zip(nodes, nodes[1:])]


def _nearest_wall(idx: dict, target: str) -> str:
    t = idx[target]
    walls = [n for n in idx.values() if n["kind"] == "wall"]
    return min(walls, key=lambda w: math.hypot(w["cx"] - t["cx"], w["cy"] - t["cy"]))["node_id"]


# weakest first: which kept edge a cycle gives up (superstructure and support edges never)
BREAKABLE = ("frequent", "no_pruning", "connectivity", "hub_inherited", "chain_inherited", "keep_unique_front_proximal",
             "keep_same_category_adjacent")


def _break_cycles(edges: list[dict], idx: dict, stats: Stats, room_type: str) -> None:
    """Prune the weakest edge of each remaining cycle among objects, when its target stays reachable.

    Weakness: rule order in ``BREAKABLE``, then lower relation frequency, then longer gap. Cycles whose
    every edge is a superstructure or support edge, or whose edges all carry reachability, stay (counted).
    """
    for _ in range(len(edges)):  # each round prunes one kept edge or returns
        g = _object_graph(edges)
        try:
            cycle = nx.find_cycle(g)
        except nx.NetworkXNoCycle:
            return
        def weakness(e: dict) -> tuple:
            a, b = idx[e["source"]], idx[e["target"]]
            freq = stats.relfreq.get((room_type, a["category"], b["category"], e["direction"], e["distance"]), 0.0)
            return (BREAKABLE.index(e["rule"]), freq, -(e["gap"] or 0.0))
        candidates = sorted((g[u][v]["e"] for u, v in cycle if g[u][v]["e"]["rule"] in BREAKABLE), key=weakness)
        for e in candidates:
            e["status"] = "pruned"
            if e["target"] in _reachable(_kept_graph(edges, idx), idx):
                e["rule"] = "cycle_break"
                break
            e["status"] = "kept"
        else:
            return  # nothing on this cycle can go: a documented cyclic case


def _object_graph(edges: list[dict]) -> nx.DiGraph:
    """Kept edges other than architecture ones (each carries its row as ``e``): where cycles matter."""
    g = nx.DiGraph()
    g.add_edges_from((e["source"], e["target"], {"e": e}) for e in edges
                     if e["status"] == "kept" and e["edge_type"] not in ARCHITECTURE_EDGES)
    return g


def _has_cycle(edges: list[dict]) -> bool:
    return not nx.is_directed_acyclic_graph(_object_graph(edges))


def _node_roles(nodes: list[dict], hubs: list[Hub], chains: list[Chain]) -> list[dict]:
    role, group = {}, {}
    for k, h in enumerate(hubs):
        role[h.hub], group[h.hub] = "hub", f"hub_{k}"
        for s in h.spokes:
            role[s], group[s] = "spoke", f"hub_{k}"
    for k, c in enumerate(chains):
        for pos, m in enumerate(c.members):
            r = "chain_start" if pos == 0 else "chain_end" if pos == len(c.members) - 1 else "chain_member"
            role[m] = r if m not in role else f"{role[m]}+{r}"
            group.setdefault(m, f"chain_{k}")
    return [dict(n, role=role.get(n["node_id"], "none"), group_id=group.get(n["node_id"])) for n in nodes]
