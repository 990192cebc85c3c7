"""Validity of a generated relation graph (PlanIT section 5's rejection rules). networkx, no torch.

A graph is rejected when it is disconnected (an object not joined to the room), cyclic among objects (a directed
cycle of object edges: refinement leaves real graphs acyclic), holds an edge type never seen between those two
categories in training, has an inconsistent chain (a chain member with no adjacent or proximal edge to another
chain member; kitchen rows mix categories), or lacks a category (nearly) every training room holds
(:func:`pipeline.room.contents.learn_contents`), or puts an object adjacent or proximal to two opposite walls
(:func:`near_opposite_walls`: no real graph of the AI2-THOR rooms does, 5 of 10,000 objects of the procedural ones;
the categories the training graphs show doing it are allowed), or breaks a link rule of the training graphs
(:func:`learn_links`: an office chair with no desk in front of it, a desk with two chairs planned in front of it).
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from ..room.contents import wilson_lower
from .data import EDGE_CLASSES, N_OBJECT_EDGES, OBJECT_EDGES, ROLES

CHAIN_ROLES = {ROLES.index("chain"), ROLES.index("hub+chain")}
NEAR = {k for k, name in enumerate(OBJECT_EDGES) if name.endswith(("adjacent", "proximal"))}
OPPOSITE = EDGE_CLASSES.index("wall_opposite")
REASONS = ("empty", "disconnected", "cyclic", "unseen_edge", "inconsistent_chain", "missing_required",
           "near_opposite_walls", "missing_link", "excess_link")
Link = tuple[int, str, str]  # (the other node's class, support | a near edge's direction, "in" | "out")


@dataclass(frozen=True)
class LinkRules:
    """What the training graphs' objects show of their near edges (:func:`learn_links`): per node class, the links
    (nearly) every one of its objects has, and the most objects of a class one object links to one way."""
    required: dict[int, frozenset[Link]] = field(default_factory=dict)
    caps: dict[tuple[int, Link], int] = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class GraphRules:
    """What a generated graph keeps to, learned from the training graphs: the (anchor class, target class, object edge
    class) triples ``seen``, the node classes every graph holds (``required``), the classes that may stand near two
    opposite walls (``opposite_ok``), the link rules and each category's largest count in one room (``caps``
    ``(categories,)``; None: no cap)."""
    seen: frozenset[tuple[int, int, int]] = frozenset()
    required: frozenset[int] = frozenset()
    opposite_ok: frozenset[int] = frozenset()
    links: LinkRules = field(default_factory=LinkRules)
    caps: np.ndarray | None = None


def node_links(node_class: list[int], edges: list[tuple[int, int, int]]) -> list[Counter[Link]]:
    """Per node: how many nodes of each class it is linked to by a support edge or an adjacent or proximal spatial
    edge of each direction, as the edge's target (``in``) or its anchor (``out``)."""
    out: list[Counter[Link]] = [Counter() for _ in node_class]
    for s, t, c in edges:
        if c == 0 or c in NEAR:
            kind = OBJECT_EDGES[c].split("/")[0]
            out[t][(node_class[s], kind, "in")] += 1
            out[s][(node_class[t], kind, "out")] += 1
    return out


def learn_links(graphs, min_share: float, cap: bool = True) -> LinkRules:
    """From the training ``graphs`` (objects with ``node_class``, ``edges`` and ``n_arch``): per object class the links
    whose share of its objects is confidently (Wilson 95% lower bound) at least ``min_share``, and, with ``cap``, each
    (class, link)'s largest count on one object."""
    objects: Counter[int] = Counter()
    having: Counter[tuple[int, Link]] = Counter()
    caps: dict[tuple[int, Link], int] = {}
    for g in graphs:
        cls = [int(c) for c in g.node_class]
        for k, links in enumerate(node_links(cls, [tuple(e) for e in g.edges.tolist()])[g.n_arch:], g.n_arch):
            objects[cls[k]] += 1
            for link, m in links.items():
                having[(cls[k], link)] += 1
                caps[(cls[k], link)] = max(caps.get((cls[k], link), 0), m)
    required: dict[int, set[Link]] = {}
    for (c, link), h in having.items():
        if wilson_lower(h, objects[c]) >= min_share:
            required.setdefault(c, set()).add(link)
    return LinkRules({c: frozenset(v) for c, v in required.items()}, caps if cap else {})


def link_problems(node_class: list[int], edges: list[tuple[int, int, int]], n_arch: int, rules: LinkRules) -> list[str]:
    """``missing_link`` when an object lacks a link its class requires, ``excess_link`` when it links to more objects
    of a class one way than any training object of its class (a link never seen is the unseen-edge rule's)."""
    out = []
    links = node_links(node_class, edges)[n_arch:]
    if any(not rules.required.get(node_class[k], frozenset()) <= set(lk) for k, lk in enumerate(links, n_arch)):
        out.append("missing_link")
    if any(m > rules.caps.get((node_class[k], link), m) for k, lk in enumerate(links, n_arch) for link, m in lk.items()):
        out.append("excess_link")
    return out


def seen_triples(graphs, share: float = 0.0) -> set[tuple[int, int, int]]:
    """(anchor class, target class, edge class) of the object edges in ``graphs`` (objects with ``node_class``,
    ``edges`` and ``n_arch``) of which the graphs hold at least ``share`` edges per object of the target class (0:
    every kind seen; an object joined twice by one kind counts twice)."""
    edges: Counter = Counter()
    objects: Counter = Counter()
    for g in graphs:
        cls = list(g.node_class)
        edges.update((cls[s], cls[t], c) for s, t, c in g.edges if c < N_OBJECT_EDGES)
        objects.update(cls[g.n_arch:])
    return {t for t, n in edges.items() if n >= share * objects[t[1]]}


def problems(node_class: list[int], role: list[int], edges: list[tuple[int, int, int]], n_arch: int,
             rules: GraphRules) -> list[str]:
    """The rejection reasons of one graph (empty: valid) under the training graphs' ``rules`` (their count caps are
    the sampler's). ``edges`` rows (source, target, class)."""
    seen, required, opposite_ok = rules.seen, rules.required, rules.opposite_ok
    out = [] if len(node_class) > n_arch else ["empty"]  # every real room holds an object
    n = len(node_class)
    undirected = nx.Graph()
    undirected.add_nodes_from(range(n))
    undirected.add_edges_from((s, t) for s, t, _ in edges)
    if n and not nx.is_connected(undirected):
        out.append("disconnected")
    objects = nx.DiGraph()
    objects.add_edges_from((s, t) for s, t, c in edges if c < N_OBJECT_EDGES and s >= n_arch and t >= n_arch)
    if not nx.is_directed_acyclic_graph(objects):
        out.append("cyclic")
    if any(c < N_OBJECT_EDGES and (node_class[s], node_class[t], c) not in seen for s, t, c in edges):
        out.append("unseen_edge")
    if not _chains_consistent(node_class, role, edges, n_arch):
        out.append("inconsistent_chain")
    if not set(required) <= set(node_class[n_arch:]):
        out.append("missing_required")
    if any(node_class[k] not in opposite_ok for k in near_opposite_walls(node_class, edges)):
        out.append("near_opposite_walls")
    return out + link_problems(node_class, edges, n_arch, rules.links)


def near_walls(node_class: list[int], edges: list[tuple[int, int, int]]) -> dict[int, set[int]]:
    """Object -> the walls (node class 0) with an adjacent or proximal edge to it."""
    out: dict[int, set[int]] = {}
    for s, t, c in edges:
        if c in NEAR and node_class[s] == 0:
            out.setdefault(t, set()).add(s)
    return out


def near_opposite_walls(node_class: list[int], edges: list[tuple[int, int, int]]) -> list[int]:
    """The objects with adjacent or proximal edges from two walls that the architecture calls opposite."""
    opposite = {(s, t) for s, t, c in edges if c == OPPOSITE} | {(t, s) for s, t, c in edges if c == OPPOSITE}
    return sorted(k for k, ws in near_walls(node_class, edges).items()
                  if any((a, b) in opposite for a in ws for b in ws if a != b))


def opposite_classes(graphs) -> set[int]:
    """The node classes the ``graphs`` show near two opposite walls (a generated graph may place only these so)."""
    return {int(g.node_class[k]) for g in graphs
            for k in near_opposite_walls(g.node_class.tolist(), [tuple(e) for e in g.edges.tolist()])}


def _chains_consistent(node_class, role, edges, n_arch) -> bool:
    members = {k for k in range(n_arch, len(node_class)) if role[k] in CHAIN_ROLES}
    linked = set()
    for s, t, c in edges:
        if c in NEAR and s in members and t in members:
            linked |= {s, t}
    return members == linked
