"""Generated relation graphs, whatever generator grew them: the graph over node positions (:class:`Grown`), the
plausible contents learned from the training graphs that a generator keeps to, and the graphs as rows of the final
graph tables (plus ``scene_id``, the architecture's room and the seed).

Generated graphs use the same nodes/edges schema as the corpus's final graphs, so statistics, scoring and
instantiation read them unchanged: the architecture nodes and edges are copied from the room they grew from;
objects get ids ``obj_00``..., their category, symmetry, superstructure role, tier and support parent (no
geometry yet: instantiation places them). Pure NumPy and pandas.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from .. import tables
from ..geometry.symmetry import TYPES as SYMMETRIES
from ..log import progress
from ..room.contents import learn_contents
from . import checks as graph_checks
from .data import ARCH, EDGE_CLASSES, N_OBJECT_EDGES, ROLES, Graph, Vocab


@dataclass
class Grown:
    """A sampled graph over node positions: the architecture's nodes first (``arch.n_arch``), then the objects;
    ``edges`` rows (source, target, class), architecture edges included."""
    arch: Graph
    node_class: list[int]
    symmetry: list[int]
    role: list[int]
    edges: list[tuple[int, int, int]]


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


def contents_of(train: list, vocab, cfg: dict) -> tuple[np.ndarray | None, set[int]]:
    """From the training graphs (``train``): each category's largest count in one room as ``(categories,)`` caps
    (None when ``cfg['cap_counts']`` is off, or without training graphs) and the node classes of the required
    categories (:func:`pipeline.room.contents.learn_contents` with ``cfg['required_share']``: none above 1, which no
    Wilson bound reaches)."""
    learned = learn_contents([[vocab.node_classes[c] for c in g.node_class[g.n_arch:]] for g in train],
                             cfg["required_share"])
    cats = vocab.node_classes[len(ARCH):]
    caps = np.array([learned["max_count"].get(c, 0) for c in cats]) if cfg["cap_counts"] and train else None
    return caps, {vocab.node_classes.index(c) for c in learned["required"]}


def link_rules(train: list, cfg: dict) -> graph_checks.LinkRules:
    """The training graphs' link rules (:func:`pipeline.graphs.checks.learn_links` at ``cfg['required_share']``) a
    sampled graph keeps to: ``cfg['links']`` ``all``, ``required`` (no caps) or ``none``."""
    if cfg["links"] == "none":
        return graph_checks.LinkRules()
    return graph_checks.learn_links(train, cfg["required_share"], cfg["links"] == "all")


def graph_rules(train: list, vocab, cfg: dict) -> graph_checks.GraphRules:
    """Everything a sampled graph keeps to, from the training graphs (``cfg``: ``graph_model.sample.contents``): seen
    edge triples (those that join at least ``min_edge_share`` of their target category's objects), required classes
    and count caps (:func:`contents_of`), the classes seen near two opposite walls and the link rules
    (:func:`link_rules`)."""
    caps, required = contents_of(train, vocab, cfg)
    return graph_checks.GraphRules(frozenset(graph_checks.seen_triples(train, cfg["min_edge_share"])), frozenset(required),
                                   frozenset(graph_checks.opposite_classes(train)), link_rules(train, cfg), caps)


def resample(n: int, budget: int, batch_size: int, base_seed: int, draw: Callable, desc: str) -> tuple[dict, int, Counter]:
    """``n`` graphs drawn in batches, each rejected one drawn again up to ``budget`` times: graph index -> (valid
    graph, seed), how many were valid at the first try, rejections by reason. ``draw(part, seed)`` gives a graph and
    its rejection reasons (none: valid) for each graph index of ``part``; a batch's seed follows from ``base_seed``,
    the try and the batch alone."""
    kept, first_try, reasons = {}, 0, Counter()
    pending = list(range(n))
    for attempt in range(budget + 1):
        for k in progress(range(0, len(pending), batch_size), desc=f"{desc}, try {attempt + 1}"):
            part = pending[k:k + batch_size]
            seed = base_seed + 1_000_003 * attempt + k
            for i, (g, bad) in zip(part, draw(part, seed)):
                reasons.update(bad)
                first_try += attempt == 0 and not bad
                if not bad:
                    kept[i] = (g, seed)
        pending = [i for i in pending if i not in kept]
        if not pending:
            break
    return kept, first_try, reasons


def graph_rows(kept: dict, vocab, nodes: Path, edges: Path, room_type: str, prefix: str) -> tuple[list[dict], list[dict]]:
    """The kept graphs as generated_nodes / generated_edges rows, architecture copied from their rooms."""
    flt = [("room_type", "=", room_type)]
    arch_rows = _architecture_rows(tables.read(nodes, "final_nodes", filters=flt).to_pandas(),
                                   tables.read(edges, "final_edges", filters=flt).to_pandas())
    rows_n, rows_e = [], []
    for i in sorted(kept):
        g, seed = kept[i]
        an, ae = arch_rows[g.arch.room_id]
        nn_, ee = grown_rows(g, vocab, an, ae, f"{prefix}_{i:05d}", room_type, seed)
        rows_n += nn_
        rows_e += ee
    return rows_n, rows_e


def _architecture_rows(node_df, edge_df) -> dict:
    """Per room: its architecture node rows (in the graph's order) and its kept architecture edges."""
    out = {}
    arch_e = edge_df[edge_df["edge_type"].astype(str).isin(["wall_adjacent", "wall_opposite", "opening"])
                     & (edge_df["status"].astype(str) == "kept")]
    by_room = dict(tuple(arch_e.groupby("room_id", sort=False)))
    for room, g in node_df[node_df["kind"].astype(str) != "object"].groupby("room_id", sort=False):
        out[room] = (g.sort_values("node_id"), by_room.get(room, arch_e.iloc[:0]))
    return out
