"""Sampled graphs as rows of the final graph tables (plus ``scene_id``, the architecture's room and the seed).

Generated graphs use the same nodes/edges schema as the corpus's final graphs, so statistics, scoring and
instantiation read them unchanged: the architecture nodes and edges are copied from the room they grew from;
objects get ids ``obj_00``..., their category, symmetry, superstructure role, tier and support parent (no
geometry yet: instantiation places them).
"""
from __future__ import annotations

import pandas as pd

from .... import tables
from ....geometry.symmetry import TYPES as SYMMETRIES
from ....graphs.data import EDGE_CLASSES, N_OBJECT_EDGES, ROLES, Vocab
from .sampler import Grown

ROLE_NAMES = {"none": "none", "hub": "hub", "hub+chain": "hub+chain_member", "spoke": "spoke", "chain": "chain_member"}


def _edge_fields(cls: int) -> tuple[str, str | None, str | None]:
    name = EDGE_CLASSES[cls]
    if name == "support":
        return "support", None, None
    if cls < N_OBJECT_EDGES:
        d, s = name.split("/")
        return "spatial", d, s
    return None, None, None  # architecture edges are copied from the source room


def _tiers(n_arch: int, n: int, parent: dict[int, int]) -> list[int]:
    tier = [0] * n
    for k in range(n_arch, n):
        seen, p, depth = {k}, parent.get(k), 1
        while p is not None and p not in seen and p >= n_arch:
            seen.add(p)
            depth += 1
            p = parent.get(p)
        tier[k] = depth
    return tier



def grown_rows(g: Grown, vocab: Vocab, arch_nodes: pd.DataFrame, arch_edges: pd.DataFrame, scene_id: str,
               room_type: str, seed: int) -> tuple[list[dict], list[dict]]:
    """Node and edge rows of one sampled graph. ``arch_nodes`` / ``arch_edges``: the source room's architecture
    rows of the final tables (nodes in the graph's architecture order)."""
    n_arch = g.arch.n_arch
    ids = list(g.arch.node_ids[:n_arch]) + [f"obj_{k:02d}" for k in range(len(g.node_class) - n_arch)]
    parent = {t: s for s, t, c in g.edges if c == 0}
    tier = _tiers(n_arch, len(ids), parent)
    extra = {"room_id": scene_id, "scene_id": scene_id, "source_room_id": g.arch.room_id, "sample_seed": int(seed),
             "room_type": room_type, "shard": 0}
    nodes = [dict(r, **extra) for r in tables.records(arch_nodes)]
    for k in range(n_arch, len(ids)):
        nodes.append({**extra, "node_id": ids[k], "kind": "object", "category": vocab.node_classes[g.node_class[k]],
                      "symmetry": SYMMETRIES[g.symmetry[k]], "symmetry_origin": "sampled", "tier": tier[k],
                      "parent_id": ids[parent[k]] if k in parent and parent[k] >= n_arch else None,
                      "role": ROLE_NAMES[ROLES[g.role[k]]], "group_id": None})
    edges = [dict(r, **extra) for r in tables.records(arch_edges)]
    for s, t, c in g.edges:
        kind, d, dist = _edge_fields(c)
        if kind is not None:
            edges.append({**extra, "source": ids[s], "target": ids[t], "edge_type": kind, "direction": d,
                          "distance": dist, "status": "kept", "rule": "sampled", "origin": "sampled"})
    return nodes, edges

