"""Teacher forcing over batches of graphs: every graph's decisions replayed in lockstep, one event at a time.

A graph's *events* are, per object in its order, an add-node event (category and attributes) and an add-edges
event (its edges, one decision each, then stop: all from one propagation, each decision seeing the edges chosen
before it); a final add-node event says stop. Event ``e`` of every graph in the batch runs together: one
propagation over the union of their present nodes and edges, then each graph's decisions. The negative
log-likelihood is summed per graph and per kind of decision.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
import torch.nn.functional as F

from ....graphs.data import ARCH, N_OBJECT_EDGES, ROLES, Sequence, Vocab, node_features
from .model import EDGE_CHOICES, EDGE_FEATURES, GraphModel

ADD, EDGES = 0, 1
KINDS = ("add_node", "attributes", "add_edge")


@dataclass
class Batch:
    x: torch.Tensor          # (N, F) node features, nodes of graph b in their decision order
    is_arch: torch.Tensor    # (N,) bool
    graph: torch.Tensor      # (N,) which graph
    local: torch.Tensor      # (N,) position within its graph
    appear: torch.Tensor     # (N,) first event at which the node is present
    src: torch.Tensor        # (M,) edges, global node indices
    dst: torch.Tensor
    edge_x: torch.Tensor     # (M, EDGE_FEATURES)
    edge_appear: torch.Tensor
    kind: torch.Tensor       # (B, E) ADD, EDGES or -1 (no more events)
    new: torch.Tensor        # (B, E) EDGES events: the node being connected (global)
    add_target: torch.Tensor   # (B, E) category index, or categories (stop)
    attr_target: torch.Tensor  # (B, E) symmetry x role class
    dec_graph: torch.Tensor    # (R,) edge decisions: graph, event, target ((local * 2 + dir) * 13 + type; -1 stop)
    dec_event: torch.Tensor
    dec_target: torch.Tensor
    chosen_row: torch.Tensor   # (Q,) edges chosen before each decision: decision row, choice code
    chosen_code: torch.Tensor
    width: int               # largest graph of the batch (nodes)


def edge_features(cls: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """``(m, EDGE_FEATURES)``: one-hot class and, for wall -> wall edges, the cosine of their angle."""
    out = np.zeros((len(cls), EDGE_FEATURES), np.float32)
    out[np.arange(len(cls)), cls] = 1
    out[:, -1] = np.where(cls >= N_OBJECT_EDGES, np.cos(angle), 0.0)
    return out


def _events(seq: Sequence, n_cats: int, base: int, b: int, decisions: list, chosen: list) -> tuple[list, np.ndarray, list]:
    """One graph's event rows (kind, new, add target, attribute target), node appear events and object edges;
    appends its edge decisions and the choices before each to ``decisions`` and ``chosen``."""
    g, n_arch = seq.graph, seq.graph.n_arch
    pos = np.empty(len(seq.order), np.int64)
    pos[seq.order] = np.arange(len(seq.order))
    appear = np.zeros(len(seq.order), np.int64)
    rows, edges = [], []
    for p, node in enumerate(seq.order[n_arch:]):
        me = n_arch + p
        rows.append((ADD, -1, int(g.node_class[node]) - len(ARCH), int(g.symmetry[node]) * len(ROLES) + int(g.role[node])))
        appear[me] = len(rows)
        rows.append((EDGES, base + me, -1, -1))
        codes = [(int(pos[u]) * 2 + int(d)) * N_OBJECT_EDGES + int(c) for u, d, c in seq.links[p]]
        for j, code in enumerate(codes + [-1]):
            chosen += [(len(decisions), c) for c in codes[:j]]
            decisions.append((b, len(rows) - 1, code))
        for u, d, c in seq.links[p]:
            s, t = (pos[u], me) if d == 0 else (me, pos[u])
            edges.append((base + s, base + t, c, 0.0, len(rows)))
    rows.append((ADD, -1, n_cats, -1))
    return rows, appear, edges


def make_batch(seqs: list[Sequence], vocab: Vocab, device: str = "cpu") -> Batch:
    """Tensors for a batch of sequences (architecture edges present from the start)."""
    n_cats = len(vocab.categories)
    xs, arch, graph, local, appear, edges, events = [], [], [], [], [], [], []
    decisions: list[tuple[int, int, int]] = []  # (graph, event row, edge code or -1)
    chosen: list[tuple[int, int]] = []  # (decision, an edge code chosen before it)
    base = 0
    for b, seq in enumerate(seqs):
        g, n = seq.graph, len(seq.order)
        xs.append(node_features(g, vocab)[seq.order])
        arch.append(np.arange(n) < g.n_arch)
        graph.append(np.full(n, b))
        local.append(np.arange(n))
        rows, app, obj_edges = _events(seq, n_cats, base, b, decisions, chosen)
        appear.append(app)
        events.append(rows)
        both_arch = (g.edges[:, 0] < g.n_arch) & (g.edges[:, 1] < g.n_arch) if len(g.edges) else np.zeros(0, bool)
        for (s, t, c), a in zip(g.edges[both_arch], g.angle[both_arch]):  # architecture nodes keep their positions
            edges.append((base + s, base + t, c, a, 0))
        edges += obj_edges
        base += n
    e = np.array(edges, dtype=float).reshape(-1, 5)
    ev = np.full((len(seqs), max(len(r) for r in events), 4), -1, np.int64)
    for b, rows in enumerate(events):
        ev[b, :len(rows)] = rows
    dec = np.array(decisions, np.int64).reshape(-1, 3)
    ch = np.array(chosen, np.int64).reshape(-1, 2)
    t = lambda a, dt=torch.long: torch.as_tensor(np.asarray(a), dtype=dt, device=device)  # noqa: E731
    cls = e[:, 2].astype(np.int64)
    return Batch(t(np.concatenate(xs), torch.float32), t(np.concatenate(arch), torch.bool), t(np.concatenate(graph)),
                 t(np.concatenate(local)), t(np.concatenate(appear)), t(e[:, 0].astype(np.int64)), t(e[:, 1].astype(np.int64)),
                 t(edge_features(cls, e[:, 3]), torch.float32), t(e[:, 4].astype(np.int64)),
                 t(ev[:, :, 0]), t(ev[:, :, 1]), t(ev[:, :, 2]), t(ev[:, :, 3]),
                 t(dec[:, 0]), t(dec[:, 1]), t(dec[:, 2]), t(ch[:, 0]), t(ch[:, 1]), max(len(s.order) for s in seqs))


def nll(model: GraphModel, batch: Batch) -> torch.Tensor:
    """``(B, 3)`` negative log-likelihood per graph of its add-node, attribute and add-edge decisions."""
    n_graphs, n_events = batch.kind.shape
    out = torch.zeros(n_graphs, len(KINDS), device=batch.x.device)
    h = torch.zeros(len(batch.x), model.hidden, device=batch.x.device)
    everyone = torch.arange(len(batch.x), device=batch.x.device)
    for e in range(n_events):
        kind = batch.kind[:, e]
        active = kind >= 0
        arriving = (batch.appear == e) & active[batch.graph]
        if arriving.any():
            h = h.index_put((everyone[arriving],), model.init_nodes(batch.x[arriving], batch.is_arch[arriving]))
        present = everyone[(batch.appear <= e) & active[batch.graph]]
        live = (batch.edge_appear <= e) & active[batch.graph[batch.src]]
        h = model.propagate(h, batch.x, present, batch.src[live], batch.dst[live], batch.edge_x[live])
        hg = model.readout(h, batch.x, present, batch.graph, n_graphs)
        out = out + _add_nll(model, batch, hg, kind, e) + _edge_nll(model, batch, h, hg, kind, e, present)
    return out


def _add_nll(model, batch, hg, kind, e) -> torch.Tensor:
    out = torch.zeros(len(kind), len(KINDS), device=hg.device)
    adds = torch.nonzero(kind == ADD)[:, 0]
    if not len(adds):
        return out
    target = batch.add_target[adds, e]
    out = out.index_put((adds, torch.zeros_like(adds)), F.cross_entropy(model.add_node(hg[adds]), target, reduction="none"))
    real = adds[target < model.categories]
    if len(real):
        onehot = F.one_hot(batch.add_target[real, e], model.categories).float()
        logits = model.attributes(torch.cat([hg[real], onehot], 1))
        out = out.index_put((real, torch.ones_like(real)), F.cross_entropy(logits, batch.attr_target[real, e], reduction="none"))
    return out


def _edge_nll(model, batch, h, hg, kind, e, present) -> torch.Tensor:
    out = torch.zeros(len(kind), len(KINDS), device=h.device)
    graphs = torch.nonzero(kind == EDGES)[:, 0]
    if not len(graphs):
        return out
    base, stop = candidate_logits(model, h, batch, present, (graphs, batch.new[graphs, e]), hg, batch.width)
    rows = torch.nonzero(batch.dec_event == e)[:, 0]
    row_of = torch.full((len(kind),), -1, dtype=torch.long, device=h.device)
    row_of[graphs] = torch.arange(len(graphs), device=h.device)
    which = row_of[batch.dec_graph[rows]]
    chosen = torch.zeros(len(rows), batch.width * EDGE_CHOICES, device=h.device)
    slot = torch.full((len(batch.dec_graph),), -1, dtype=torch.long, device=h.device)
    slot[rows] = torch.arange(len(rows), device=h.device)
    mine = slot[batch.chosen_row] >= 0
    chosen[slot[batch.chosen_row[mine]], batch.chosen_code[mine]] = 1.0
    logits = model.decide_edges(base[which], stop[which], chosen.view(len(rows), batch.width, EDGE_CHOICES))
    target = batch.dec_target[rows]
    target = torch.where(target >= 0, target, torch.full_like(target, logits.shape[1] - 1))
    loss = F.cross_entropy(logits, target, reduction="none")
    return out.index_put((batch.dec_graph[rows], torch.full_like(rows, 2)), loss, accumulate=True)


def candidate_logits(model, h: torch.Tensor, nodes, present: torch.Tensor, newest: tuple[torch.Tensor, torch.Tensor],
                     hg: torch.Tensor, width: int) -> tuple[torch.Tensor, torch.Tensor]:
    """Base add-edge logits ``(len(graphs), width, 26)`` of each graph's new node, ``newest`` = (graphs, their new
    node): every present node of the graph but the new one is a candidate (-inf elsewhere); and the base stop logits
    ``(len(graphs),)``. ``nodes``: the batch's node tensors (``x``, ``is_arch``, ``graph``, ``local``: a teacher
    batch or the sampler's state); ``h``: their states, ``hg``: the graphs' readouts."""
    graphs, new = newest
    x, is_arch, graph, local = nodes.x, nodes.is_arch, nodes.graph, nodes.local
    new_of = torch.full((len(hg),), -1, dtype=torch.long, device=h.device)
    new_of[graphs] = new
    cand = present[(new_of[graph[present]] >= 0) & (present != new_of[graph[present]])]
    row_of = torch.full((len(hg),), -1, dtype=torch.long, device=h.device)
    row_of[graphs] = torch.arange(len(graphs), device=h.device)
    dense = torch.full((len(graphs), width, EDGE_CHOICES), float("-inf"), device=h.device)
    if len(cand):
        logits = model.edge_logits(h, x, cand, new_of[graph[cand]], hg[graph[cand]], is_arch)
        dense = dense.index_put((row_of[graph[cand]], local[cand]), logits)
    return dense, model.stop_logit(h, x, new, hg[graphs])
