"""The edge tagger (Kalojanov et al. 2019, section 6): a bidirectional LSTM reads a room's string; at each bond token,
its state and the edge's label (class and which way it runs) go through a small MLP to one logit per relative-pose
cluster, masked to the clusters of the edge's triple (:mod:`.poses`). A graph's edges are tagged by voting: the
softmax of several random strings of the graph averaged per edge. Training draws new strings of every fit room each
epoch from ``(seed, epoch)`` and stops when the validation accuracy stops rising (``learning/epochs.py``: resumes
exactly)."""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import torch
from torch import nn

from ...graphs.data import N_OBJECT_EDGES
from ...learning import epochs
from ...seeding import rng_for
from .poses import Clusters, Triple
from .serialize import StringGraph, read_string, room_string
from .vocab import TokenVocab

KIND, PROGRESS = "edge_tagger", "edge_tagger.progress"
Edge = tuple[int, int, int]  # source, target, edge class (graph nodes)


@dataclass(frozen=True)
class Room:
    """A room as the tagger sees it: its string graph, architecture size, each edge's triple and (training rooms)
    cluster label (global index)."""
    graph: StringGraph
    n_arch: int
    triples: dict[Edge, Triple]
    labels: dict[Edge, int]


@dataclass
class Example:
    """One string of a room: its text and per tagged edge the graph edge, bond token index, label code (edge class
    x 2 + forward), cluster range ``[lo, hi)`` and label (-1 unknown)."""
    text: str
    edges: list[Edge]
    bond: list[int]
    code: list[int]
    lo: list[int]
    hi: list[int]
    label: list[int]


def example(room: Room, clusters: Clusters, rng: np.random.Generator | None) -> Example:
    """One string of ``room`` (a random order with ``rng``) and its edges with a known triple."""
    text, atoms = room_string(room.graph, room.n_arch, rng)
    reader = read_string(text)
    ex = Example(text, [], [], [], [], [], [])
    for (ps, pt, c), bond in zip(reader.edges, reader.bond_at):
        e = (atoms[ps], atoms[pt], c)
        t = room.triples.get(e)
        if c >= N_OBJECT_EDGES or t not in clusters.offset:
            continue
        lo = clusters.offset[t]
        ex.edges.append(e)
        ex.bond.append(bond)
        ex.code.append(2 * c + int(ps < pt))
        ex.lo.append(lo)
        ex.hi.append(lo + len(clusters.centres[t]))
        ex.label.append(room.labels.get(e, -1))
    return ex


class EdgeTagger(nn.Module):
    def __init__(self, n_tokens: int, n_clusters: int, embed: int, hidden: int, layers: int):
        super().__init__()
        self.embed = nn.Embedding(n_tokens, embed, padding_idx=0)
        self.lstm = nn.LSTM(embed, hidden, layers, batch_first=True, bidirectional=True)
        self.code = nn.Embedding(2 * N_OBJECT_EDGES, embed)
        self.head = nn.Sequential(nn.Linear(2 * hidden + embed, hidden), nn.ReLU(), nn.Linear(hidden, n_clusters))

    def forward(self, x: torch.Tensor, lengths: torch.Tensor, row: torch.Tensor, pos: torch.Tensor,
                code: torch.Tensor, lo: torch.Tensor, hi: torch.Tensor) -> torch.Tensor:
        """Masked logits ``(items, clusters)``: item ``i`` is the bond token at column ``pos[i]`` of string
        ``row[i]`` of ``x (B, T)``; only its clusters ``[lo[i], hi[i])`` are finite."""
        packed = nn.utils.rnn.pack_padded_sequence(self.embed(x), lengths.cpu(), batch_first=True, enforce_sorted=False)
        h, _ = self.lstm(packed)
        h, _ = nn.utils.rnn.pad_packed_sequence(h, batch_first=True, total_length=x.shape[1])
        logits = self.head(torch.cat([h[row, pos], self.code(code)], 1))
        k = torch.arange(logits.shape[1], device=logits.device)
        return logits.masked_fill((k < lo[:, None]) | (k >= hi[:, None]), float("-inf"))


def build_model(tokens: TokenVocab, clusters: int, preset: dict) -> EdgeTagger:
    return EdgeTagger(len(tokens), max(clusters, 1), preset["embed"], preset["hidden"], preset["layers"])


def _batch(examples: list[Example], tokens: TokenVocab, device: str) -> tuple[torch.Tensor, ...]:
    """The token rows, their lengths and the flattened items (row, column, code, lo, hi, label) of ``examples``."""
    x = torch.from_numpy(tokens.encode([e.text for e in examples])).to(device)
    items = np.array([(r, b + 1, c, lo, hi, y) for r, e in enumerate(examples)
                      for b, c, lo, hi, y in zip(e.bond, e.code, e.lo, e.hi, e.label)], np.int64).reshape(-1, 6)
    cols = torch.from_numpy(items).to(device).unbind(1)
    return (x, (x != 0).sum(1), *cols)


def probabilities(model: EdgeTagger, examples: list[Example], tokens: TokenVocab, batch_size: int) -> list[np.ndarray]:
    """Each example's ``(items, clusters)`` cluster probabilities."""
    model.eval()
    out = []
    with torch.no_grad():
        for k in range(0, len(examples), batch_size):
            part = examples[k:k + batch_size]
            x, lengths, row, pos, code, lo, hi, _ = _batch(part, tokens, "cpu")
            p = torch.softmax(model(x, lengths, row, pos, code, lo, hi), 1).numpy() if len(row) else np.zeros((0, 1))
            sizes = np.cumsum([0] + [len(e.edges) for e in part])
            out += [p[a:b] for a, b in zip(sizes[:-1], sizes[1:])]
    return out


def vote(model: EdgeTagger, room: Room, clusters: Clusters, tokens: TokenVocab, strings: int, seed: int,
         batch_size: int = 64) -> dict[Edge, np.ndarray]:
    """Per edge with a known triple: its clusters' (global indices) probabilities averaged over ``strings`` random
    strings of the room (the canonical one when 1)."""
    rng = rng_for(seed, "tagger-votes") if strings > 1 else None
    examples = [example(room, clusters, rng) for _ in range(strings)]
    total: dict[Edge, np.ndarray] = {}
    for ex, p in zip(examples, probabilities(model, examples, tokens, batch_size)):
        for e, row in zip(ex.edges, p):
            total[e] = total.get(e, 0) + row
    return {e: p / strings for e, p in total.items()}


def accuracy(model: EdgeTagger, rooms: list[Room], clusters: Clusters, tokens: TokenVocab, strings: int,
             seed: int) -> dict:
    """Voted tagging accuracy over the rooms' labelled edges; and over those whose triple has several clusters
    (where the tagger has a choice), with the majority cluster's accuracy there for comparison."""
    hit = n = hit_multi = n_multi = major = 0
    for room in rooms:
        for e, p in vote(model, room, clusters, tokens, strings, seed).items():
            y = room.labels.get(e)
            if y is None:
                continue
            t = room.triples[e]
            ok = int(np.argmax(p)) == y
            hit, n = hit + ok, n + 1
            if len(clusters.centres[t]) > 1:
                hit_multi, n_multi = hit_multi + ok, n_multi + 1
                major += y == clusters.offset[t]
    return {"edges": n, "accuracy": hit / max(n, 1), "edges_with_choice": n_multi,
            "accuracy_with_choice": hit_multi / max(n_multi, 1), "majority_with_choice": major / max(n_multi, 1)}


def _epoch(learner: tuple, examples: list[Example], tokens: TokenVocab, preset: dict, session: epochs.Session,
           epoch: int) -> float:
    """One pass of ``learner`` (model, optimiser) in random batches; the mean cross-entropy per tagged edge."""
    model, opt = learner
    gen = torch.Generator().manual_seed(int(session.seed) * 100_019 + epoch)
    order = torch.randperm(len(examples), generator=gen).tolist()
    total = count = 0.0
    model.train()
    for k in range(0, len(order), preset["batch_size"]):
        x, lengths, row, pos, code, lo, hi, y = _batch([examples[i] for i in order[k:k + preset["batch_size"]]],
                                                       tokens, session.device)
        if not len(row):
            continue
        loss = nn.functional.cross_entropy(model(x, lengths, row, pos, code, lo, hi), y, reduction="sum")
        opt.zero_grad()
        (loss / len(row)).backward()
        opt.step()
        total, count = total + float(loss.detach()), count + len(row)
    return total / max(count, 1)


def train(fit: list[Room], validation: list[Room], clusters: Clusters, tokens: TokenVocab, preset: dict,
          session: epochs.Session):
    """Fit the tagger; keep the epoch of the best validation accuracy (voted over ``preset['votes']`` strings;
    :func:`~pipeline.learning.epochs.fit`). Returns the model (best epoch), the history and the best epoch."""
    torch.manual_seed(session.seed)
    model = build_model(tokens, clusters.size, preset).to(session.device)
    opt = torch.optim.Adam(model.parameters(), lr=preset["lr"])

    def epoch(n: int, best: float) -> tuple[dict, float, bool]:
        start = time.perf_counter()
        rng = rng_for(session.seed, n)
        examples = [example(r, clusters, rng) for r in fit for _ in range(preset["strings_per_room"])]
        loss = _epoch((model, opt), examples, tokens, preset, session, n)
        seconds = time.perf_counter() - start
        val = accuracy(model.cpu(), validation, clusters, tokens, preset["votes"], session.seed)
        model.to(session.device)
        row = {"epoch": n, "train_loss": loss, "validation_accuracy": val["accuracy"],
               "validation_accuracy_with_choice": val["accuracy_with_choice"], "seconds": seconds}
        return row, -val["accuracy"], -val["accuracy"] < best

    run = epochs.fit(model, opt, session, PROGRESS, preset, epoch)
    return run.model.cpu(), run.history, run.best_epoch
