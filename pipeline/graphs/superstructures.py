"""Hub-and-spoke and chain superstructures of one room's relation graph (paper §4.3, appendix A.1).

Nodes are dicts with ``node_id``, ``kind``, ``category``, ``model_id``, ``symmetry``, ``diag`` (footprint
diagonal), ``cx``, ``cy``; edges are dicts of the ``edges`` table.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

DIRECTION_PREFERENCE = ("front", "back", "right", "left")


def node_index(nodes: list[dict]) -> dict[str, dict]:
    """Node rows by id, each with its footprint diagonal ``diag`` added."""
    out = {}
    for n in nodes:
        n = dict(n)
        n["diag"] = 2.0 * math.hypot(n["hx"], n["hy"])
        out[n["node_id"]] = n
    return out


def fits_symmetry(symmetry: str, directions: set[str], count: int) -> bool:
    """Whether spokes in ``directions`` are invariant under a hub's symmetry group (authors' rules)."""
    d = directions
    if symmetry == "radial":
        return count > 1
    if symmetry == "left-right":
        return {"left", "right"} <= d
    if symmetry == "front-back":
        return {"front", "back"} <= d
    if symmetry == "rotational-2":
        return {"left", "right"} <= d or {"front", "back"} <= d
    if symmetry == "rotational-4":
        return len(d) >= 2
    if symmetry == "corner-left":
        return {"front", "left"} <= d or {"back", "right"} <= d
    if symmetry == "corner-right":
        return {"front", "right"} <= d or {"back", "left"} <= d
    return False  # none: a unique front never makes a hub


@dataclass
class Hub:
    hub: str
    spokes: list[str]
    directions: dict[str, str]  # spoke -> direction from the hub


@dataclass
class Chain:
    members: list[str]  # start ... end
    direction: str
    label: str  # adjacent | proximal


def hub_candidates(nodes: dict[str, dict], edges: list[dict], cfg: dict, exclude: dict[str, int] | None = None) -> list[Hub]:
    """Every (hub, spoke category) arrangement that fits the hub's symmetry, before the dataset-wide check.

    Spokes: at least two objects of one other category reached by adjacent or proximal spatial edges,
    none larger than the hub (``hub_min_size_ratio``); nodes sharing a chain (``exclude``: node -> chain
    index) are not each other's spokes.
    """
    exclude = exclude or {}
    by_anchor: dict[tuple[str, str], dict[str, str]] = {}
    for e in edges:
        if e["edge_type"] != "spatial" or e["distance"] not in ("adjacent", "proximal"):
            continue
        a, t = nodes.get(e["source"]), nodes.get(e["target"])
        if a is None or t is None or a["kind"] != "object" or a["category"] == t["category"]:
            continue
        if a["diag"] < cfg["hub_min_size_ratio"] * t["diag"]:
            continue
        if a["node_id"] in exclude and exclude.get(t["node_id"]) == exclude[a["node_id"]]:
            continue
        by_anchor.setdefault((a["node_id"], t["category"]), {})[t["node_id"]] = e["direction"]
    hubs = []
    for (hub, _), spokes in sorted(by_anchor.items()):
        if len(spokes) >= 2 and fits_symmetry(nodes[hub]["symmetry"], set(spokes.values()), len(spokes)):
            hubs.append(Hub(hub, sorted(spokes), spokes))
    return hubs


def room_candidates(nodes: dict[str, dict], edges: list[dict], cfg: dict) -> tuple[list["Chain"], list[Hub]]:
    """A room's chains and hub candidates (spokes never chain-mates of their hub): what the statistics map step
    writes and refinement reads."""
    spatial = [e for e in edges if e["edge_type"] == "spatial"]
    chains = find_chains(nodes, spatial, cfg)
    return chains, hub_candidates(nodes, spatial, cfg, {m: k for k, c in enumerate(chains) for m in c.members})


def select_hubs(candidates: list[Hub], nodes: dict[str, dict], accepted: set[tuple[str, str]]) -> list[Hub]:
    """Keep candidates whose (hub category, spoke category) pattern is frequent dataset-wide; a node is
    hub or spoke of at most one hub (larger hubs with more spokes first)."""
    chosen: list[Hub] = []
    used: set[str] = set()
    order = sorted(candidates, key=lambda h: (-len(h.spokes), -nodes[h.hub]["diag"], h.hub))
    for h in order:
        pattern = (nodes[h.hub]["category"], nodes[h.spokes[0]]["category"])
        if pattern not in accepted or h.hub in used or used & set(h.spokes):
            continue
        chosen.append(h)
        used |= {h.hub, *h.spokes}
    return chosen


def find_chains(nodes: dict[str, dict], edges: list[dict], cfg: dict) -> list[Chain]:
    """Adjacent chains of similar-size objects and proximal chains of one model, greedy longest first.

    A chain follows spatial edges of one direction and distance label; consecutive displacements must be
    collinear (unit dot >= ``chain_collinearity``). Ties prefer front > back > right > left.
    """
    lo, hi = cfg["chain_size_ratio"]
    succ: dict[tuple[str, str], dict[str, list[str]]] = {}
    for e in edges:
        if e["edge_type"] != "spatial" or e["distance"] not in ("adjacent", "proximal"):
            continue
        a, t = nodes.get(e["source"]), nodes.get(e["target"])
        if a is None or t is None or a["kind"] != "object" or t["kind"] != "object":
            continue
        if e["distance"] == "adjacent" and not lo < a["diag"] / max(t["diag"], 1e-9) < hi:
            continue
        if e["distance"] == "proximal" and a["model_id"] != t["model_id"]:
            continue
        succ.setdefault((e["direction"], e["distance"]), {}).setdefault(a["node_id"], []).append(t["node_id"])
    candidates = []
    for (direction, label), graph in succ.items():
        for start in sorted(graph):
            path = _longest_walk(start, graph, nodes, cfg["chain_collinearity"])
            if len(path) >= cfg["chain_min_length"]:
                candidates.append(Chain(path, direction, label))
    candidates.sort(key=lambda c: (-len(c.members), DIRECTION_PREFERENCE.index(c.direction), c.label, c.members))
    chosen: list[Chain] = []
    used: set[str] = set()
    for c in candidates:
        if used & set(c.members):
            continue
        chosen.append(c)
        used |= set(c.members)
    return chosen


def _longest_walk(start: str, graph: dict[str, list[str]], nodes: dict[str, dict], min_dot: float) -> list[str]:
    """Longest collinear simple walk from ``start`` (depth-first; chains are short)."""
    best = [start]

    def pos(n: str) -> np.ndarray:
        return np.array([nodes[n]["cx"], nodes[n]["cy"]])

    def walk(path: list[str], heading: np.ndarray | None) -> None:
        nonlocal best
        if len(path) > len(best):
            best = list(path)
        for nxt in graph.get(path[-1], []):
            if nxt in path:
                continue
            step = pos(nxt) - pos(path[-1])
            norm = np.linalg.norm(step)
            if norm == 0:
                continue
            step = step / norm
            if heading is not None and float(step @ heading) < min_dot:
                continue
            walk(path + [nxt], step)

    walk([start], None)
    return best
