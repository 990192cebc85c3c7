"""PlanIT's graph generative model (section 5; Li et al. 2018), in plain PyTorch, for batches of graphs.

Nodes of many graphs live in one set of tensors (``graph (N,)`` says whose each node is); the functions below work
on the *present* nodes and edges a caller passes, so teacher-forced training and sampling share them.

- node init: separate MLPs for architecture and object nodes over the one-hot features ``x``;
- propagation: ``rounds`` rounds with their own weights; forward and reverse message MLPs over
  ``[h_u, x_u, h_v, x_v, x_uv]``, summed per node, a GRU cell per round;
- readout: gated sum ``h_G = sum_v sigmoid(g(h_v, x_v)) * f(h_v, x_v)`` (2 x hidden);
- decisions: add-node (categories + stop) from ``h_G``; attributes (symmetry x superstructure class) from
  ``[h_G, category]``; add-edge logits per candidate ``[h_u, x_u, h_v, x_v, h_G] -> 2 directions x 13 types``
  with separate MLPs for object and architecture candidates, and a stop logit from ``[h_v, x_v, h_G]``.
All MLPs are Linear-LeakyReLU-Linear-LeakyReLU-Linear of width ``width`` (the paper: 384).
"""
from __future__ import annotations

import torch
from torch import nn

from ....geometry.symmetry import TYPES as SYMMETRIES
from ....graphs.data import EDGE_CLASSES, N_OBJECT_EDGES, ROLES

EDGE_FEATURES = len(EDGE_CLASSES) + 1  # one-hot class + cos(angle)
EDGE_CHOICES = 2 * N_OBJECT_EDGES  # per candidate: direction (candidate -> new, new -> candidate) x type
ATTRIBUTES = len(SYMMETRIES) * len(ROLES)


def _message(net: nn.Sequential, hx: torch.Tensor, a: torch.Tensor, b: torch.Tensor, edge_x: torch.Tensor) -> torch.Tensor:
    """``net([hx[a], hx[b], edge_x])`` per edge, with the first layer applied per node, not per edge (the same
    function: its weight splits into the node parts and the edge part; edges outnumber nodes)."""
    first, rest = net[0], net[1:]
    k = hx.shape[1]
    w = first.weight
    pre = (hx @ w[:, :k].T)[a] + (hx @ w[:, k:2 * k].T)[b] + edge_x @ w[:, 2 * k:].T + first.bias
    return rest(pre)


def mlp(inp: int, width: int, out: int) -> nn.Sequential:
    return nn.Sequential(nn.Linear(inp, width), nn.LeakyReLU(), nn.Linear(width, width), nn.LeakyReLU(),
                         nn.Linear(width, out))


class GraphModel(nn.Module):
    """``features``: node feature size; ``categories``: object categories (add-node has one more: stop)."""

    def __init__(self, features: int, categories: int, hidden: int, width: int, rounds: int, message: int) -> None:
        super().__init__()
        self.features, self.categories, self.hidden, self.rounds = features, categories, hidden, rounds
        node = hidden + features
        self.init_arch, self.init_object = mlp(features, width, hidden), mlp(features, width, hidden)
        self.forward_msg = nn.ModuleList(mlp(2 * node + EDGE_FEATURES, width, message) for _ in range(rounds))
        self.reverse_msg = nn.ModuleList(mlp(2 * node + EDGE_FEATURES, width, message) for _ in range(rounds))
        self.update = nn.ModuleList(nn.GRUCell(2 * message, hidden) for _ in range(rounds))
        self.gate, self.project = nn.Linear(node, 2 * hidden), nn.Linear(node, 2 * hidden)
        self.add_node = mlp(2 * hidden, width, categories + 1)
        self.attributes = mlp(2 * hidden + categories, width, ATTRIBUTES)
        self.edge_object = mlp(2 * node + 2 * hidden, width, EDGE_CHOICES)
        self.edge_arch = mlp(2 * node + 2 * hidden, width, EDGE_CHOICES)
        self.stop = mlp(node + 2 * hidden, width, 1)
        # the edge decisions of one new node share one propagation; each sees the edges already chosen
        self.chosen_adjust = nn.Linear(2 * EDGE_CHOICES, EDGE_CHOICES)
        self.stop_adjust = nn.Linear(EDGE_CHOICES + 1, 1)

    def init_nodes(self, x: torch.Tensor, is_arch: torch.Tensor) -> torch.Tensor:
        """Initial states ``(k, hidden)`` of new nodes from their features ``x (k, F)``."""
        return torch.where(is_arch[:, None], self.init_arch(x), self.init_object(x))

    def propagate(self, h: torch.Tensor, x: torch.Tensor, nodes: torch.Tensor, src: torch.Tensor, dst: torch.Tensor,
                  edge_x: torch.Tensor) -> torch.Tensor:
        """``rounds`` rounds of message passing among ``nodes (P,)`` over edges ``src -> dst`` (global node indices,
        both present); returns ``h`` with those nodes' states updated."""
        local = torch.full((len(h),), -1, dtype=torch.long, device=h.device)
        local[nodes] = torch.arange(len(nodes), device=h.device)
        s, d = local[src], local[dst]
        hp, xp = h[nodes], x[nodes]
        for t in range(self.rounds):
            hx = torch.cat([hp, xp], 1)
            fwd = _message(self.forward_msg[t], hx, s, d, edge_x)
            rev = _message(self.reverse_msg[t], hx, d, s, edge_x)
            agg = torch.zeros(len(nodes), 2 * fwd.shape[1], device=h.device, dtype=h.dtype)
            agg = agg.index_add(0, d, torch.cat([fwd, torch.zeros_like(fwd)], 1))
            agg = agg.index_add(0, s, torch.cat([torch.zeros_like(rev), rev], 1))
            hp = self.update[t](agg, hp)
        return h.index_put((nodes,), hp)

    def readout(self, h: torch.Tensor, x: torch.Tensor, nodes: torch.Tensor, graph: torch.Tensor, n_graphs: int) -> torch.Tensor:
        """Gated sum per graph ``(n_graphs, 2 hidden)`` over ``nodes``; ``graph (N,)`` each node's graph."""
        hx = torch.cat([h[nodes], x[nodes]], 1)
        val = torch.sigmoid(self.gate(hx)) * self.project(hx)
        return torch.zeros(n_graphs, val.shape[1], device=h.device, dtype=h.dtype).index_add(0, graph[nodes], val)

    def edge_logits(self, h: torch.Tensor, x: torch.Tensor, cand: torch.Tensor, new: torch.Tensor, hg: torch.Tensor,
                    is_arch: torch.Tensor) -> torch.Tensor:
        """``(k, 2 x 13)`` logits of each candidate ``cand (k,)`` for its graph's new node ``new (k,)``; ``hg (k, 2H)``."""
        inp = torch.cat([h[cand], x[cand], h[new], x[new], hg], 1)
        return torch.where(is_arch[cand][:, None], self.edge_arch(inp), self.edge_object(inp))

    def stop_logit(self, h: torch.Tensor, x: torch.Tensor, new: torch.Tensor, hg: torch.Tensor) -> torch.Tensor:
        return self.stop(torch.cat([h[new], x[new], hg], 1))[:, 0]

    def decide_edges(self, base: torch.Tensor, stop: torch.Tensor, chosen: torch.Tensor) -> torch.Tensor:
        """``(R, width * 26 + 1)`` logits of R edge decisions from their node's ``base (R, width, 26)`` candidate
        logits (-inf: no candidate) and ``stop (R,)`` logit, given the edges ``chosen (R, width, 26)`` (0/1) before
        them: an edge already chosen cannot be chosen again; the rest shift by a learned function of what was
        chosen to that candidate and in total."""
        total = chosen.sum(1, keepdim=True)
        shift = self.chosen_adjust(torch.cat([chosen, total.expand_as(chosen)], 2))
        logits = torch.where(chosen > 0, torch.full_like(base, float("-inf")), base + shift)
        stop = stop + self.stop_adjust(torch.cat([total[:, 0], total[:, 0].sum(1, keepdim=True)], 1))[:, 0]
        return torch.cat([logits.reshape(len(base), -1), stop[:, None]], 1)
