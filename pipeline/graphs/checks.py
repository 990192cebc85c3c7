"""Validity of a generated relation graph (PlanIT section 5's rejection rules). networkx, no torch.

A graph is rejected when it is disconnected (an object not joined to the room), cyclic among objects (a directed
cycle of object edges: refinement leaves real graphs acyclic), holds an edge type never seen between those two
categories in training, has an inconsistent chain (a chain member with no adjacent or proximal edge to another
chain member; kitchen rows mix categories), or lacks a category (nearly) every training room holds
(:func:`pipeline.room.contents.learn_contents`), or puts an object adjacent or proximal to two opposite walls
(:func:`near_opposite_walls`: no real graph of the AI2-THOR rooms does, 5 of 10,000 objects of the procedural ones;
the categories the training graphs show doing it are allowed).
"""
from __future__ import annotations

import networkx as nx

from .data import EDGE_CLASSES, N_OBJECT_EDGES, OBJECT_EDGES, ROLES

CHAIN_ROLES = {ROLES.index("chain"), ROLES.index("hub+chain")}
NEAR = {k for k, name in enumerate(OBJECT_EDGES) if name.endswith(("adjacent", "proximal"))}
OPPOSITE = EDGE_CLASSES.index("wall_opposite")
REASONS = ("empty", "disconnected", "cyclic", "unseen_edge", "inconsistent_chain", "missing_required",
           "near_opposite_walls")


def seen_triples(graphs) -> set[tuple[int, int, int]]:
    """(anchor class, target class, edge class) of every object edge in ``graphs`` (objects with ``node_class``
    and ``edges``)."""
    out = set()
    for g in graphs:
        cls = list(g.node_class)
        out |= {(cls[s], cls[t], c) for s, t, c in g.edges if c < N_OBJECT_EDGES}
    return out


def problems(node_class: list[int], role: list[int], edges: list[tuple[int, int, int]], n_arch: int,
             seen: set[tuple[int, int, int]], required: set[int] | frozenset[int] = frozenset(),
             opposite_ok: set[int] | frozenset[int] = frozenset()) -> list[str]:
    """The rejection reasons of one graph (empty: valid). ``edges`` rows (source, target, class); ``required``: node
    classes every graph must hold; ``opposite_ok``: node classes that may stand near two opposite walls."""
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
    return out


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
