"""Relation graphs as the graph model sees them: integer node and edge classes, and decision sequences.

Pure NumPy over the final graph tables (kept edges only). A graph holds its architecture (walls, doors, windows and
the edges among them: the given start) and its objects. A *sequence* is one order of the objects with, for each,
its edges to the nodes before it: what the model decides, one object at a time (PlanIT section 5, after Li et al.
2018). Orders are drawn at random per epoch so that any partial graph can be completed; each object touches a node
before it, so the model learns to join every new object to the room (graphs come out connected).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..geometry.symmetry import TYPES as SYMMETRIES
from ..seeding import rng_for

ARCH = ("wall", "door", "window")
ROLES = ("none", "hub", "hub+chain", "spoke", "chain")  # the code's superstructure classes
DIRECTIONS = ("front", "back", "left", "right")
DISTANCES = ("adjacent", "proximal", "distant")
# object edges: support + 4 directions x 3 distances (13, what the model chooses); architecture edges (given)
OBJECT_EDGES = ("support", *(f"{d}/{s}" for d in DIRECTIONS for s in DISTANCES))
ARCH_EDGES = ("wall_adjacent/left", "wall_adjacent/right", "wall_opposite", "opening")
EDGE_CLASSES = OBJECT_EDGES + ARCH_EDGES
N_OBJECT_EDGES = len(OBJECT_EDGES)


@dataclass(frozen=True)
class Vocab:
    """Node classes of one room type: the architecture kinds, then its object categories (sorted)."""
    categories: tuple[str, ...]

    @property
    def node_classes(self) -> tuple[str, ...]:
        return ARCH + self.categories

    @property
    def feature_size(self) -> int:
        """One-hot node class, symmetry and role, plus the segment length."""
        return len(self.node_classes) + len(SYMMETRIES) + len(ROLES) + 1

    def category_index(self, category: str) -> int:
        return ARCH.__len__() + self.categories.index(category)


@dataclass
class Graph:
    """One room's graph. Nodes ``0 .. n_arch - 1`` are its architecture. ``edges (m, 3)``: source, target, class
    (index into :data:`EDGE_CLASSES`); ``angle (m,)`` wall -> wall angle (rad, 0 elsewhere)."""
    room_id: str
    node_ids: list[str]
    node_class: np.ndarray
    symmetry: np.ndarray
    role: np.ndarray
    length: np.ndarray
    n_arch: int
    edges: np.ndarray
    angle: np.ndarray
    extra: dict = field(default_factory=dict)

    @property
    def n_objects(self) -> int:
        return len(self.node_ids) - self.n_arch


def role_class(role: str | None) -> int:
    """The code's superstructure class of a refinement role (hub, spoke, chain_start, 'hub+chain_start', ...)."""
    r = str(role or "none")
    if "hub" in r:
        return ROLES.index("hub+chain") if "chain" in r else ROLES.index("hub")
    if "spoke" in r:
        return ROLES.index("spoke")
    return ROLES.index("chain") if "chain" in r else 0


def edge_class(edge_type: str, direction, distance) -> int | None:
    """Index into :data:`EDGE_CLASSES`; None for kinds the model does not know."""
    if edge_type == "support":
        return 0
    if edge_type == "spatial":
        key = f"{direction}/{distance}"
    elif edge_type == "wall_adjacent":
        key = f"wall_adjacent/{direction}"
    else:
        key = edge_type
    return EDGE_CLASSES.index(key) if key in EDGE_CLASSES else None


def vocab_of(nodes: pd.DataFrame) -> Vocab:
    """The object categories of a set of final nodes."""
    cats = nodes.loc[nodes["kind"].astype(str) == "object", "category"].astype(str)
    return Vocab(tuple(sorted(set(cats))))


def graphs_from_tables(nodes: pd.DataFrame, edges: pd.DataFrame, vocab: Vocab) -> list[Graph]:
    """One :class:`Graph` per room of the final tables (kept edges only; hanging objects, tier -1, left out)."""
    nodes = nodes[nodes["tier"].fillna(0).astype(int) >= 0]
    kept = edges[edges["status"].astype(str) == "kept"]
    by_room = dict(tuple(kept.groupby("room_id", sort=False)))
    out = []
    for room_id, g in nodes.groupby("room_id", sort=True):
        out.append(_graph(str(room_id), g, by_room.get(room_id, kept.iloc[:0]), vocab))
    return out


def _graph(room_id: str, g: pd.DataFrame, e: pd.DataFrame, vocab: Vocab) -> Graph:
    kind = g["kind"].astype(str)
    g = pd.concat([g[kind != "object"].sort_values("node_id"), g[kind == "object"].sort_values("node_id")])
    ids = g["node_id"].astype(str).tolist()
    index = {n: k for k, n in enumerate(ids)}
    cls = [ARCH.index(k) if k in ARCH else vocab.category_index(c) for k, c in zip(g["kind"].astype(str), g["category"].astype(str))]
    sym = [SYMMETRIES.index(s) if s in SYMMETRIES else 0 for s in g["symmetry"].astype(object).fillna("none")]
    rows = []
    for s, t, typ, d, dist, ang in zip(e["source"], e["target"], e["edge_type"].astype(str), e["direction"].astype(object),
                                     e["distance"].astype(object), e["angle"].astype(float).fillna(0.0)):
        c = edge_class(typ, d, dist)
        if c is not None and s in index and t in index and s != t:
            rows.append((index[s], index[t], c, ang))
    arr = np.array(rows, dtype=float).reshape(-1, 4)
    return Graph(room_id, ids, np.array(cls, np.int64), np.array(sym, np.int64),
                 np.array([role_class(r) for r in g.get("role", pd.Series([None] * len(g)))], np.int64),
                 g["length"].astype(float).fillna(0.0).to_numpy(), int((kind != "object").sum()),
                 arr[:, :3].astype(np.int64), arr[:, 3])


def features(vocab: Vocab, node_class, symmetry, role, length) -> np.ndarray:
    """``(n, vocab.feature_size)`` float32 node features from ``(n,)`` arrays: one-hot class, symmetry, role, then
    the length (m)."""
    node_class = np.asarray(node_class, np.int64)
    n, c, s = len(node_class), len(vocab.node_classes), len(SYMMETRIES)
    x = np.zeros((n, vocab.feature_size), np.float32)
    x[np.arange(n), node_class] = 1
    x[np.arange(n), c + np.asarray(symmetry, np.int64)] = 1
    x[np.arange(n), c + s + np.asarray(role, np.int64)] = 1
    x[:, -1] = length
    return x


def node_features(graph: Graph, vocab: Vocab) -> np.ndarray:
    """:func:`features` of every node of a graph."""
    return features(vocab, graph.node_class, graph.symmetry, graph.role, graph.length)


@dataclass
class Sequence:
    """One order of a graph's objects as decisions. ``order (n,)``: node indices, architecture first. Per object
    position p (0-based among objects): ``links[p]`` ``(k, 3)`` rows (earlier node, direction 0: earlier -> new,
    1: new -> earlier, object edge class), in the order they are decided; edges beyond ``max_edges`` are dropped
    and counted in ``dropped``."""
    graph: Graph
    order: np.ndarray
    links: list[np.ndarray]
    dropped: int


def connected_order(graph: Graph, rng: np.random.Generator) -> np.ndarray:
    """A random order of the objects in which each touches (by an edge, either way) a node before it, where the
    graph allows (refined graphs are connected): the next object is drawn among those touching the nodes so far."""
    n = len(graph.node_ids)
    touch: list[set[int]] = [set() for _ in range(n)]
    for s, t, _ in graph.edges:
        touch[s].add(t)
        touch[t].add(s)
    placed = set(range(graph.n_arch))
    left = set(range(graph.n_arch, n))
    order = []
    while left:
        frontier = sorted(k for k in left if touch[k] & placed) or sorted(left)
        k = frontier[int(rng.integers(len(frontier)))]
        order.append(k)
        placed.add(k)
        left.discard(k)
    return np.array(order, np.int64)


def sequence(graph: Graph, rng: np.random.Generator, max_edges: int) -> Sequence:
    """A random connected object order (:func:`connected_order`) and, for each object, a random order of its
    edges to the nodes before it."""
    objects = connected_order(graph, rng)
    order = np.concatenate([np.arange(graph.n_arch), objects]).astype(np.int64)
    position = np.empty(len(order), np.int64)
    position[order] = np.arange(len(order))
    src, dst, cls = graph.edges.T if len(graph.edges) else (np.zeros(0, np.int64),) * 3
    links, dropped = [], 0
    for node in objects:
        earlier_src = (dst == node) & (position[src] < position[node]) & (cls < N_OBJECT_EDGES)
        earlier_dst = (src == node) & (position[dst] < position[node]) & (cls < N_OBJECT_EDGES)
        rows = np.concatenate([np.column_stack([src[earlier_src], np.zeros(earlier_src.sum(), np.int64), cls[earlier_src]]),
                               np.column_stack([dst[earlier_dst], np.ones(earlier_dst.sum(), np.int64), cls[earlier_dst]])])
        rows = rows[rng.permutation(len(rows))]
        dropped += max(0, len(rows) - max_edges)
        links.append(rows[:max_edges].astype(np.int64))
    return Sequence(graph, order, links, dropped)


def split_heldout(room_ids: list[str], fraction: float, seed: int,
                  stream: str = "heldout") -> tuple[list[str], list[str]]:
    """A seeded split of room ids into (train, held-out); at least one room in each when there are two or more.
    ``stream`` tells independent splits of one seed apart (the validation split of the training ids uses another)."""
    ids = sorted(room_ids)
    rng = rng_for(seed, stream)
    perm = rng.permutation(len(ids))
    k = int(round(fraction * len(ids)))
    k = min(max(k, 1 if len(ids) > 1 else 0), max(len(ids) - 1, 0))
    held = {ids[i] for i in perm[:k]}
    return [i for i in ids if i not in held], [i for i in ids if i in held]


SPLITS = ("fit", "validation", "heldout")


def room_splits(room_ids: list[str], heldout_fraction: float, validation_fraction: float, seed: int) -> dict[str, str]:
    """Seeded split of a room type's rooms: room id -> fit | validation | heldout. The held-out rooms are the test
    rooms of every learner and of the evaluation; the validation rooms come out of the rest."""
    rest, held = split_heldout(room_ids, heldout_fraction, seed)
    fit, validation = split_heldout(rest, validation_fraction, seed, stream="validation")
    return {**{r: "fit" for r in fit}, **{r: "validation" for r in validation}, **{r: "heldout" for r in held}}
