"""Generated vs real relation graphs: distribution distances, novelty and uniqueness. NumPy and networkx only.

Every distance is reported beside its *sampling floor*: the same distance between two disjoint sets of real graphs
of the sizes compared (held-out vs a sample of training graphs), since small sets differ by chance alone.
Graphs are anything with ``node_class``, ``role``, ``n_arch`` and ``edges`` rows (source, target, class): the
:class:`~pipeline.graphs.data.Graph` of real or generated tables alike.
"""
from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from typing import Any, cast

import networkx as nx
import numpy as np

from ..graphs.data import N_OBJECT_EDGES, ROLES, Graph
from . import distributions


def _objects(g: Graph) -> list[int]:
    return list(np.asarray(g.node_class)[g.n_arch:])


def count_distance(real: Sequence[Graph], gen: Sequence[Graph]) -> float:
    """Total variation distance between the object-count histograms (:func:`.distributions.count_distance`)."""
    return distributions.count_distance([len(_objects(g)) for g in real], [len(_objects(g)) for g in gen])


def category_kl(real: Sequence[Graph], gen: Sequence[Graph]) -> float:
    """The rooms' category KL (:func:`.distributions.category_kl`) over the graphs' object classes."""
    return distributions.category_kl([c for g in real for c in _objects(g)], [c for g in gen for c in _objects(g)])


def edge_type_kl(real: Sequence[Graph], gen: Sequence[Graph]) -> float:
    """The same KL over the types of the object edges."""
    def types(gs: Sequence[Graph]) -> list[int]:
        return [int(c) for g in gs for _, _, c in g.edges if c < N_OBJECT_EDGES]
    return distributions.category_kl(types(real), types(gen))


def _degree_hist(g: Graph, bins: int = 12) -> np.ndarray:
    deg: Counter[int] = Counter()
    for s, t, _ in g.edges:
        deg[s] += 1
        deg[t] += 1
    d = [min(deg[k], bins - 1) for k in range(g.n_arch, len(g.node_class))]
    h = np.bincount(d, minlength=bins).astype(float)
    return cast(np.ndarray, h / max(h.sum(), 1))


def degree_mmd(real: Sequence[Graph], gen: Sequence[Graph], sigma: float = 0.5) -> float:
    """Squared MMD between the object-degree histograms of two sets, Gaussian kernel (GraphRNN's measure)."""
    x, y = np.array([_degree_hist(g) for g in real]), np.array([_degree_hist(g) for g in gen])

    def k(a: np.ndarray, b: np.ndarray) -> float:
        d2 = ((a[:, None, :] - b[None, :, :]) ** 2).sum(-1)
        return cast(float, np.exp(-d2 / (2 * sigma ** 2)).mean())
    return float(k(x, x) + k(y, y) - 2 * k(x, y))


def structure_counts(gs: Sequence[Graph]) -> dict[str, Any]:
    """Hubs and chain members per graph (superstructure roles)."""
    roles = Counter(ROLES[r] for g in gs for r in np.asarray(g.role)[g.n_arch:])
    n = max(len(gs), 1)
    return {"hubs_per_graph": (roles["hub"] + roles["hub+chain"]) / n,
            "chain_members_per_graph": (roles["chain"] + roles["hub+chain"]) / n}


def distances(real: Sequence[Graph], gen: Sequence[Graph]) -> dict[str, Any]:
    """Generated vs real graphs: object-count TV, category and edge-type KL, degree MMD."""
    return {"node_count_tv": count_distance(real, gen), "category_kl": category_kl(real, gen),
            "edge_type_kl": edge_type_kl(real, gen), "degree_mmd": degree_mmd(real, gen)}


def to_nx(g: Graph) -> nx.DiGraph:
    """A graph's furnishing as a labelled digraph for isomorphism: the objects (label: category) and one node per
    architecture kind (every wall merged into one 'wall' node, likewise doors and windows), edges labelled by their
    types (architecture -> architecture edges left out). Architectures differ from room to room, so comparing them
    would make every graph 'novel'; what is compared is the arrangement."""
    cls, n_arch = [int(c) for c in g.node_class], g.n_arch
    node = lambda k: ("arch", cls[k]) if k < n_arch else k  # noqa: E731
    out = nx.DiGraph()
    out.add_nodes_from((node(k), {"c": cls[k]}) for k in range(len(cls)))
    labels: dict[tuple[Any, Any], list[int]] = {}
    for s, t, c in g.edges:
        if s < n_arch and t < n_arch:
            continue
        labels.setdefault((node(int(s)), node(int(t))), []).append(int(c))
    out.add_edges_from((a, b, {"c": str(sorted(cs))}) for (a, b), cs in labels.items())
    return out


def _key(g: nx.DiGraph) -> str:
    import warnings

    with warnings.catch_warnings():  # networkx 3.5 notes that its directed hashes changed: we compare within a run
        warnings.simplefilter("ignore", UserWarning)
        return cast(str, nx.weisfeiler_lehman_graph_hash(g, node_attr="c", edge_attr="c", iterations=3))


def _same(a: nx.DiGraph, b: nx.DiGraph) -> bool:
    match = lambda x, y: x["c"] == y["c"]  # noqa: E731
    return cast(bool, nx.is_isomorphic(a, b, node_match=match, edge_match=match))


def novelty_uniqueness(gen: Sequence[Graph], train: Sequence[Graph]) -> dict[str, Any]:
    """Share of generated graphs isomorphic (labels included) to no training graph, and share of distinct ones
    among the generated: WL hashes first, the exact check only within a hash bucket."""
    buckets: dict[str, list[nx.DiGraph]] = {}
    for g in train:
        n = to_nx(g)
        buckets.setdefault(_key(n), []).append(n)
    novel = 0
    distinct: list[tuple[str, nx.DiGraph]] = []
    for g in gen:
        n = to_nx(g)
        key = _key(n)
        if not any(_same(n, t) for t in buckets.get(key, [])):
            novel += 1
        if not any(k == key and _same(n, m) for k, m in distinct):
            distinct.append((key, n))
    return {"novelty": novel / max(len(gen), 1), "uniqueness": len(distinct) / max(len(gen), 1)}
