"""Training the graph model: batched teacher forcing, Adam, early stopping on the validation NLL, checkpoints that
resume.

Every epoch draws new random node and edge orders from ``(seed, epoch)`` alone, so a run resumed from its
checkpoint continues exactly as an uninterrupted one would (same orders, same optimizer state, same weights).
The validation graphs are training rooms held back from fitting; the test rooms (the held-out split every
evaluation compares with) play no part. Scoring a set (:func:`heldout_nll`) uses one fixed order per graph. The
checkpoint (written atomically after every epoch) carries the
config hash: a checkpoint of other settings is never resumed.
"""
from __future__ import annotations

import logging
import time

import numpy as np
import torch

from ....graphs.data import Graph, Vocab, sequence
from ....learning import epochs
from ....learning.device import pick_device  # noqa: F401 (re-exported for the stages)
from ....seeding import rng_for
from .model import GraphModel
from .teacher import KINDS, make_batch, nll

log = logging.getLogger("planit.graph_model")
KIND, PROGRESS = "graph_model", "graph_model.progress"  # checkpoint kinds: the trained model, training progress


def build_model(vocab: Vocab, preset: dict) -> GraphModel:
    return GraphModel(vocab.feature_size, len(vocab.categories), preset["hidden"], preset["width"], preset["rounds"],
                      preset["message"])


Run = epochs.Run


def heldout_nll(model: GraphModel, graphs: list[Graph], vocab: Vocab, seed: int, max_edges: int, batch_size: int,
                device: str) -> np.ndarray:
    """``(len(graphs), 3)`` NLL per graph (validation or test) and decision kind, one fixed order per graph."""
    rng = rng_for(seed, "heldout-order")
    seqs = [sequence(g, rng, max_edges) for g in graphs]
    out = []
    with torch.no_grad():
        for k in range(0, len(seqs), batch_size):
            out.append(nll(model, make_batch(seqs[k:k + batch_size], vocab, device)).cpu().numpy())
    return np.concatenate(out) if out else np.zeros((0, len(KINDS)))


def mean_nll(nll: np.ndarray) -> dict:
    """Means of a :func:`heldout_nll` array: ``per_graph`` (summed over decisions) and one per decision kind."""
    return {"per_graph": float(nll.sum(1).mean()), **{k: float(nll[:, i].mean()) for i, k in enumerate(KINDS)}}


def _epoch(learner: tuple, graphs: list[Graph], vocab: Vocab, preset: dict, max_edges: int, session: epochs.Session,
           epoch: int) -> tuple[float, int]:
    """One pass of ``learner`` (model, optimiser) over the training graphs in batches; returns the mean NLL per graph
    and edges dropped."""
    model, opt = learner
    rng = rng_for(session.seed, epoch)
    order = rng.permutation(len(graphs))
    seqs = [sequence(graphs[i], rng, max_edges) for i in order]
    total, dropped = 0.0, sum(s.dropped for s in seqs)
    for k in range(0, len(seqs), preset["batch_size"]):
        part = seqs[k:k + preset["batch_size"]]
        loss = nll(model, make_batch(part, vocab, session.device)).sum(1)
        opt.zero_grad()
        loss.mean().backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), preset["clip"])
        opt.step()
        total += float(loss.detach().sum())
    return total / max(len(seqs), 1), dropped


def train(train_graphs: list[Graph], validation: list[Graph], vocab: Vocab, preset: dict, max_edges: int,
          session: epochs.Session) -> Run:
    """Fit ``train_graphs`` until the ``validation`` NLL has not improved by ``preset['min_improvement']``
    (relative) for ``preset['patience']`` epochs, or ``preset['max_epochs']``; keep the epoch of the lowest
    validation NLL (:func:`~pipeline.learning.epochs.fit`)."""
    torch.manual_seed(session.seed)
    model = build_model(vocab, preset).to(session.device)
    opt = torch.optim.Adam(model.parameters(), lr=preset["lr"])

    def epoch(n: int, best: float) -> tuple[dict, float, bool]:
        start = time.perf_counter()
        model.train()
        train_nll, dropped = _epoch((model, opt), train_graphs, vocab, preset, max_edges, session, n)
        seconds = time.perf_counter() - start
        model.eval()
        val = mean_nll(heldout_nll(model, validation, vocab, session.seed, max_edges, preset["batch_size"],
                                   session.device))
        row = {"epoch": n, "train_nll": train_nll, "validation_nll": val["per_graph"],
               **{f"validation_{k}": val[k] for k in KINDS},
               "seconds": seconds, "graphs_per_s": len(train_graphs) / max(seconds, 1e-9), "edges_dropped": dropped}
        return row, row["validation_nll"], row["validation_nll"] < best * (1 - preset["min_improvement"])

    return epochs.fit(model, opt, session, PROGRESS, preset, epoch)
