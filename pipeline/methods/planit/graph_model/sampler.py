"""Sampling graphs from the graph model, many at once: each grows from a real room's architecture, in lockstep.

Per step every unfinished graph propagates, decides whether to add an object (and which), samples its attributes,
propagates again and then chooses its edges one at a time (the decisions the model was trained on). A *plan* may
force objects and edges first (completion from a partial graph); the model fills in the rest. ``temperature``
scales the logits (0: always the most likely choice).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
import torch
import torch.nn.functional as F

from ....graphs import checks as graph_checks
from ....graphs.checks import GraphRules
from ....graphs.data import ARCH, N_OBJECT_EDGES, ROLES, Graph, Vocab, features, node_features
from ....graphs.generated import Grown
from .model import EDGE_CHOICES, GraphModel
from .teacher import candidate_logits, edge_features


@dataclass
class Plan:
    """What a graph must contain: objects ``(category index, symmetry or None, role or None)`` added first, in
    order, and edges ``(object k, direction, type, object j)``, k < j: direction 0 is k -> j."""
    objects: list[tuple[int, int | None, int | None]] = field(default_factory=list)
    edges: list[tuple[int, int, int, int]] = field(default_factory=list)


@dataclass(frozen=True)
class Limits:
    """What a sampled graph may hold: at most ``max_objects`` objects and ``max_edges`` edges per new object, and,
    with ``rules`` (:class:`~pipeline.graphs.checks.GraphRules`), only edges of seen kinds, no category beyond its
    cap, no object outside ``rules.opposite_ok`` near two opposite walls."""
    max_objects: int
    max_edges: int
    rules: GraphRules | None = None


@functools.lru_cache(maxsize=8)
def _allowed(seen: frozenset, classes: int) -> torch.Tensor:
    out = torch.zeros(classes, classes, N_OBJECT_EDGES, dtype=torch.bool)
    if seen:
        idx = torch.tensor(sorted(seen))
        out[idx[:, 0], idx[:, 1], idx[:, 2]] = True
    return out


def allowed_tensor(seen: set, classes: int) -> torch.Tensor:
    """``(classes, classes, 13)`` bool from (anchor class, target class, type) triples (cached: sampling calls it
    once per batch with the same set)."""
    return _allowed(frozenset(seen), classes)


def _pick(logits: torch.Tensor, temperature: float, gen: torch.Generator) -> torch.Tensor:
    if temperature <= 0:
        return logits.argmax(1)
    return torch.multinomial(F.softmax(logits / temperature, 1), 1, generator=gen)[:, 0]


class _State:
    """Growing node and edge tensors of the graphs being sampled (nodes of all graphs interleaved)."""

    def __init__(self, model: GraphModel, archs: list[Graph], vocab: Vocab, allowed: torch.Tensor | None = None,
                 opposite_ok: set | None = None):
        self.model, self.vocab, self.allowed = model, vocab, allowed
        self.opposite_ok = opposite_ok  # node classes that may stand near two opposite walls (None: any)
        self.grown = [Grown(g, g.node_class[:g.n_arch].tolist(), g.symmetry[:g.n_arch].tolist(),
                            g.role[:g.n_arch].tolist(), []) for g in archs]
        xs = [torch.as_tensor(node_features(g, vocab)[:g.n_arch]) for g in archs]
        self.x = torch.cat(xs)
        self.graph = torch.cat([torch.full((g.n_arch,), b) for b, g in enumerate(archs)])
        self.local = torch.cat([torch.arange(g.n_arch) for g in archs])
        self.is_arch = torch.ones(len(self.x), dtype=torch.bool)
        self.first = np.cumsum([0] + [g.n_arch for g in archs])[:-1]  # global index of each graph's node 0
        self.index = [list(range(f, f + g.n_arch)) for f, g in zip(self.first, archs)]  # local -> global
        self.h = model.init_nodes(self.x, self.is_arch)
        src, dst, ex = [], [], []
        for b, g in enumerate(archs):
            keep = (g.edges[:, 0] < g.n_arch) & (g.edges[:, 1] < g.n_arch) if len(g.edges) else np.zeros(0, bool)
            src += (self.first[b] + g.edges[keep, 0]).tolist()
            dst += (self.first[b] + g.edges[keep, 1]).tolist()
            ex.append(edge_features(g.edges[keep, 2], g.angle[keep]))
            self.grown[b].edges += [tuple(map(int, r)) for r in g.edges[keep]]
        self.src, self.dst = torch.tensor(src, dtype=torch.long), torch.tensor(dst, dtype=torch.long)
        self.edge_x = torch.as_tensor(np.concatenate(ex))

    def propagate(self, graphs: torch.Tensor) -> torch.Tensor:
        """Propagate within ``graphs``; returns their readouts ``(B, 2H)`` (rows of other graphs are zero)."""
        on = torch.zeros(len(self.grown), dtype=torch.bool)
        on[graphs] = True
        present = torch.nonzero(on[self.graph])[:, 0]
        live = on[self.graph[self.src]]
        self.h = self.model.propagate(self.h, self.x, present, self.src[live], self.dst[live], self.edge_x[live])
        return self.model.readout(self.h, self.x, present, self.graph, len(self.grown))

    def add_node(self, b: int, cls: int, sym: int, role: int) -> int:
        g = self.grown[b]
        g.node_class.append(cls)
        g.symmetry.append(sym)
        g.role.append(role)
        xt = torch.as_tensor(features(self.vocab, [cls], [sym], [role], 0.0))
        new = len(self.x)
        self.x = torch.cat([self.x, xt])
        self.graph = torch.cat([self.graph, torch.tensor([b])])
        self.local = torch.cat([self.local, torch.tensor([len(self.index[b])])])
        self.is_arch = torch.cat([self.is_arch, torch.tensor([False])])
        self.h = torch.cat([self.h, self.model.init_nodes(xt, torch.tensor([False]))])
        self.index[b].append(new)
        return new

    def add_edge(self, b: int, s_local: int, t_local: int, cls: int) -> None:
        self.grown[b].edges.append((s_local, t_local, cls))
        self.src = torch.cat([self.src, torch.tensor([self.index[b][s_local]])])
        self.dst = torch.cat([self.dst, torch.tensor([self.index[b][t_local]])])
        self.edge_x = torch.cat([self.edge_x, torch.as_tensor(edge_features(np.array([cls]), np.zeros(1)))])


@torch.no_grad()
def sample(model: GraphModel, vocab: Vocab, archs: list[Graph], seed: int, temperature: float, limits: Limits,
           plans: list[Plan] | None = None) -> list[Grown]:
    """One graph per architecture in ``archs`` (only their architecture is used), grown in one batch. With the
    ``limits``' rules, edges of unseen (anchor class, target class, type) triples are never proposed, no category is
    chosen once a graph holds its cap (a plan's forced objects may exceed it), no object outside the rules'
    ``opposite_ok`` classes is put adjacent or proximal to two opposite walls; edges that would close a cycle among
    objects or give an object a second support parent never are; and every new object takes at least one edge when
    it can (as in training, where each object touches a node before it)."""
    gen = torch.Generator().manual_seed(int(seed))
    rules, max_objects, max_edges = limits.rules, limits.max_objects, limits.max_edges
    st = _State(model, archs, vocab, None if rules is None else allowed_tensor(set(rules.seen), len(vocab.node_classes)),
                None if rules is None else set(rules.opposite_ok))
    caps = None if rules is None else rules.caps
    plans = plans or [Plan() for _ in archs]
    n_objects = [0] * len(archs)
    counts = torch.zeros(len(archs), model.categories, dtype=torch.long)
    limit = None if caps is None else torch.as_tensor(caps, dtype=torch.long)
    active = list(range(len(archs)))
    while active:
        act = torch.tensor(active)
        hg = st.propagate(act)
        logits = model.add_node(hg[act])
        if limit is not None:
            logits[:, :model.categories] = logits[:, :model.categories].masked_fill(counts[act] >= limit, float("-inf"))
        cats = _pick(logits, temperature, gen).tolist()
        attrs = _pick(model.attributes(torch.cat([hg[act], F.one_hot(torch.tensor(cats).clamp(max=model.categories - 1),
                                                                      model.categories).float()], 1)), temperature, gen)
        adding = []
        for b, cat, attr in zip(active, cats, attrs.tolist()):
            k = n_objects[b]
            if k < len(plans[b].objects):
                cat, sym, role = plans[b].objects[k]
                attr = (sym if sym is not None else attr // len(ROLES)) * len(ROLES) + (role if role is not None else attr % len(ROLES))
            if cat >= model.categories or k >= max_objects:
                continue
            st.add_node(b, len(ARCH) + cat, attr // len(ROLES), attr % len(ROLES))
            n_objects[b] += 1
            counts[b, cat] += 1
            adding.append(b)
        active = adding
        if adding:
            _edges(st, torch.tensor(adding), plans, n_objects, temperature, max_edges, gen)
    return st.grown


def _edges(st: _State, graphs: torch.Tensor, plans: list[Plan], n_objects: list[int], temperature: float,
           max_edges: int, gen: torch.Generator) -> None:
    """Choose the edges of each graph's newest object (forced ones first), one decision at a time."""
    model = st.model
    hg = st.propagate(graphs)
    width = max(len(st.index[b]) for b in graphs.tolist())
    present = torch.nonzero(torch.isin(st.graph, graphs))[:, 0]
    new = torch.tensor([st.index[b][-1] for b in graphs.tolist()])
    base, stop = candidate_logits(model, st.h, st, present, (graphs, new), hg, width)
    if st.allowed is not None:
        base = base.masked_fill(~_seen_mask(st, graphs, present, new, width), float("-inf"))
    chosen = torch.zeros(len(graphs), width, EDGE_CHOICES)
    forced = [[e for e in plans[b].edges if e[3] == n_objects[b] - 1] for b in graphs.tolist()]
    open_ = [True] * len(graphs)
    for step in range(max_edges + 1):
        logits = model.decide_edges(base, stop, chosen)
        logits[:, :-1] = logits[:, :-1].masked_fill(_order_mask(st, graphs, width).reshape(len(graphs), -1), float("-inf"))
        if step == 0:  # every object joins the graph (training orders are connected): no stop before one edge
            can = torch.isfinite(logits[:, :-1]).any(1)
            logits[:, -1] = torch.where(can, torch.full_like(logits[:, -1], float("-inf")), logits[:, -1])
        pick = _pick(logits, temperature, gen).tolist()
        for r, b in enumerate(graphs.tolist()):
            if not open_[r]:
                continue
            n_arch = st.grown[b].arch.n_arch
            me = len(st.index[b]) - 1
            if step < len(forced[r]):
                k, d, cls, _ = forced[r][step]
                code = ((n_arch + k) * 2 + d) * N_OBJECT_EDGES + cls
            elif pick[r] == width * EDGE_CHOICES or step == max_edges:
                open_[r] = False
                continue
            else:
                code = pick[r]
            u, rest = divmod(code, EDGE_CHOICES)
            d, cls = divmod(rest, N_OBJECT_EDGES)
            chosen[r, u, rest] = 1.0
            st.add_edge(b, u, me, cls) if d == 0 else st.add_edge(b, me, u, cls)
        if not any(open_):
            return


def _seen_mask(st: _State, graphs, present, new, width) -> torch.Tensor:
    """``(G, width, 26)``: which (candidate, direction, type) joins categories that such an edge joined in training."""
    cls = st.x[:, :len(st.vocab.node_classes)].argmax(1)
    new_of = torch.full((len(st.grown),), -1, dtype=torch.long)
    new_of[graphs] = new
    row_of = torch.full((len(st.grown),), -1, dtype=torch.long)
    row_of[graphs] = torch.arange(len(graphs))
    cand = present[new_of[st.graph[present]] >= 0]
    cu, cv = cls[cand], cls[new_of[st.graph[cand]]]
    mask = torch.zeros(len(graphs), width, EDGE_CHOICES, dtype=torch.bool)
    mask[row_of[st.graph[cand]], st.local[cand]] = torch.cat([st.allowed[cu, cv], st.allowed[cv, cu]], 1)
    return mask


def _order_mask(st: _State, graphs, width) -> torch.Tensor:
    """``(G, width, 26)`` choices that would break what real graphs never break: a directed cycle among objects, a
    second support parent, or a second edge between the same two nodes (a final graph joins a pair once)."""
    mask = torch.zeros(len(graphs), width, 2, N_OBJECT_EDGES, dtype=torch.bool)
    for r, b in enumerate(graphs.tolist()):
        g = st.grown[b]
        n_arch, me = g.arch.n_arch, len(g.node_class) - 1
        down, up, has_parent = {me}, {me}, set()
        for _s, t, c in g.edges:
            if c == 0:
                has_parent.add(t)
        changed = True
        while changed:  # descendants and ancestors of the new object among objects
            changed = False
            for s, t, c in g.edges:
                if c < N_OBJECT_EDGES and s >= n_arch and t >= n_arch:
                    if s in down and t not in down:
                        down.add(t)
                        changed = True
                    if t in up and s not in up:
                        up.add(s)
                        changed = True
        for u in down - {me}:
            mask[r, u, 0, :] = True  # u -> me would close a cycle
        for u in up - {me}:
            mask[r, u, 1, :] = True  # me -> u would close a cycle
        for s, t, _c in g.edges:  # a pair already joined: no second edge either way
            u = s if t == me else t if s == me else None
            if u is not None and u < width:
                mask[r, u] = True
        if me in has_parent:
            mask[r, :, 0, 0] = True  # me has its support parent
        for u in has_parent:
            if u < width:
                mask[r, u, 1, 0] = True
        if st.opposite_ok is not None and g.node_class[me] not in st.opposite_ok:
            for u in _opposite_of_near(g, me):
                mask[r, u, 0, sorted(graph_checks.NEAR)] = True
    return mask.reshape(len(graphs), width, EDGE_CHOICES)


def _opposite_of_near(g: Grown, me: int) -> set[int]:
    """The walls opposite a wall that already has an adjacent or proximal edge to object ``me``."""
    near = graph_checks.near_walls(g.node_class, g.edges).get(me, set())
    return {t if s in near else s for s, t, c in g.edges if c == graph_checks.OPPOSITE and (s in near or t in near)}
