"""Room graphs sampled as strings: each string starts with a held-out room's architecture (forced), the VAE writes
the objects; a string that does not parse, breaks the training grammar or fails the checks every generated graph
passes (``graphs/checks.py``, and the plausible contents learned from the training graphs) is rejected, counted by
reason and sampled again (a budget). Kept graphs become generated_nodes / generated_edges rows like PlanIT's."""
from __future__ import annotations

import logging
from collections import Counter
from pathlib import Path

import numpy as np
import torch

from ...errors import InputError
from ...graphs import checks as graph_checks
from ...graphs.data import ARCH, Graph, Vocab
from ...graphs.generated import Grown, graph_rows, graph_rules, resample
from ...learning import checkpoint
from ...seeding import seed_of
from ..interface import GraphRequest
from . import sample as decoding, train
from .grammar import Grammar, learn_grammar
from .serialize import StringError, arch_prefix, parse, string_graph
from .vocab import EOS, TokenVocab

log = logging.getLogger("planit.sample_graphs")


def load_model(path: Path):
    """The checkpoint's record, graph vocabulary, token vocabulary and rebuilt VAE (eval mode, CPU)."""
    ckpt = checkpoint.load(path, train.KIND)
    rec = ckpt.record
    tokens = TokenVocab(tuple(rec["tokens"]))
    model = train.build_model(tokens, rec["preset"])
    model.load_state_dict(ckpt.state["model"])
    model.eval()
    return rec, Vocab(tuple(rec["categories"])), tokens, model


class Rules:
    """What a sampled graph must keep to, learned from the training graphs: the grammar, the seen edge triples, the
    count caps and required classes, the classes seen near two opposite walls, each category's usual symmetry; and
    the seen triples, caps and required categories by name, as the decoder's mask reads them."""

    def __init__(self, train_graphs: list[Graph], vocab: Vocab, detail: str, contents: dict):
        self.grammar: Grammar = learn_grammar([string_graph(g, vocab) for g in train_graphs], detail)
        self.graph = graph_rules(train_graphs, vocab, contents)
        self.seen, self.caps, self.required = self.graph.seen, self.graph.caps, self.graph.required
        names = vocab.node_classes
        self.seen_names = {(names[a], names[b], c) for a, b, c in self.seen}
        self.caps_by_name = {} if self.caps is None else {c: int(k) for c, k in zip(vocab.categories, self.caps)}
        self.required_names = {names[c] for c in self.required}
        tally: dict[int, Counter] = {}
        for g in train_graphs:
            for c, s in zip(g.node_class[g.n_arch:], g.symmetry[g.n_arch:]):
                tally.setdefault(int(c), Counter())[int(s)] += 1
        self.symmetry = {c: t.most_common(1)[0][0] for c, t in tally.items()}


def to_grown(text: str, room: Graph, vocab: Vocab, rules: Rules) -> tuple[Grown | None, list[str]]:
    """The graph of one decoded string in ``room``'s architecture, or None and the reasons it is rejected."""
    try:
        sg = parse(text)
    except StringError:
        return None, ["unparsable"]
    n_arch = room.n_arch
    _, order = arch_prefix(string_graph(room, vocab), n_arch)
    names = sg.names[n_arch:]
    if any(n in ARCH or n not in vocab.node_classes for n in names):
        return None, ["unknown_object"]
    if not rules.grammar.valid(sg):
        return None, ["grammar"]
    node = [*order, *range(n_arch, n_arch + len(names))]  # parsed atom -> node of the grown graph
    cls = [*room.node_class[:n_arch].tolist(), *(vocab.node_classes.index(n) for n in names)]
    edges = [(node[s], node[t], int(c)) for s, t, c in sg.edges.tolist()]
    bad = graph_checks.problems(cls, [0] * len(cls), edges, n_arch, rules.graph)
    counts = np.bincount(np.array(cls[n_arch:], int) - len(ARCH), minlength=len(vocab.categories))
    if rules.caps is not None and (counts[:len(rules.caps)] > rules.caps).any():
        bad.append("excess_contents")
    if bad:
        return None, bad
    sym = [*room.symmetry[:n_arch].tolist(), *(rules.symmetry.get(c, 0) for c in cls[n_arch:])]
    return Grown(room, cls, sym, [0] * len(cls), edges), []


def sample_room_type(config: dict, request: GraphRequest, threads: int = 1) -> tuple[list, list, dict]:
    """The request's ``count`` (default ``strings.sample.graphs``) valid graphs in held-out rooms' architectures (in
    turn) as generated_nodes / generated_edges rows, and a summary (valid before rejection, rejections by reason)."""
    if request.spec is not None:
        raise InputError(f"{request.spec}: the strings graph generator does not complete partial graphs (PlanIT's does)")
    model, graphs, room_type = request.model, request.graphs, request.room_type
    sc = config["strings"]["sample"]
    torch.set_num_threads(threads)
    rec, vocab, tokens, net = load_model(model)
    by_id = {g.room_id: g for g in graphs}
    held = [by_id[i] for i in rec["heldout_ids"] if i in by_id]
    if not held:
        raise InputError(f"{model}: none of its held-out rooms is in {request.nodes}; retrain it")
    rules = Rules([by_id[i] for i in rec["train_ids"] + rec["validation_ids"] if i in by_id], vocab, sc["grammar"],
                  config["graph_model"]["sample"]["contents"])
    n = request.count or sc["graphs"]
    seed = seed_of(config["seed"], room_type, "strings")
    kept, first_try, reasons = _sample_valid((net, tokens, vocab), held, n, sc, rules, (seed, room_type))
    rows_n, rows_e = graph_rows(kept, vocab, request.nodes, request.edges, room_type,
                                request.prefix or f"strings_{room_type}")
    summary = {"room_type": room_type, "generator": "strings", "requested": n, "written": len(kept),
               "failed_after_budget": n - len(kept), "valid_before_rejection": round(first_try / max(n, 1), 4),
               "rejections": dict(reasons), "temperature": sc["temperature"], "spec": None}
    log.info("%s", summary)
    return rows_n, rows_e, summary


def prefixes(rooms: list[Graph], vocab: Vocab, tokens: TokenVocab) -> list[list[int]]:
    """Each room's forced prefix as token indices: its architecture's string and ``.``."""
    return [tokens.encode([arch_prefix(string_graph(g, vocab), g.n_arch)[0] + "."])[0, 1:-1].tolist() for g in rooms]


def masker(tokens: TokenVocab, n: int, rules: Rules, mask: str) -> decoding.Syntax | None:
    """The decoder's mask for ``n`` strings (``strings.sample.mask``: none, syntax, grammar)."""
    if mask == "none":
        return None
    if mask == "syntax":
        return decoding.Syntax(tokens, n, arch_tokens(tokens))
    return decoding.Syntax(tokens, n, arch_tokens(tokens), rules.grammar, rules.caps_by_name, rules.seen_names,
                           rules.required_names)


def arch_tokens(tokens: TokenVocab) -> set[int]:
    """The architecture's atoms: a room's string holds them in its forced prefix only."""
    return {k for k, t in enumerate(tokens.tokens) if t.startswith("[") and t[1:-1] in ARCH}


def verdicts(rows: np.ndarray, rooms: list[Graph], tokens: TokenVocab, vocab: Vocab, rules: Rules,
             syntax: decoding.Syntax | None) -> list[tuple[Grown | None, list[str]]]:
    """Each decoded row's graph in its room, or None and why it is rejected (``dead_end``: the mask left no token to
    draw; ``unfinished``: no end token within the length; else :func:`to_grown`'s reasons)."""
    dead, eos = syntax.dead if syntax is not None else set(), tokens.index[EOS]
    return [(None, ["dead_end"]) if r in dead else (None, ["unfinished"]) if eos not in row
            else to_grown(tokens.decode(row), room, vocab, rules) for r, (room, row) in enumerate(zip(rooms, rows))]


def _sample_valid(decoder: tuple, held: list[Graph], n: int, sc: dict, rules: Rules,
                  seeding: tuple[int, str]) -> tuple[dict, int, Counter]:
    """Graph index -> (valid Grown, seed); how many were valid at the first try; rejections by reason
    (:func:`verdicts`), drawn again up to the resample budget (:func:`~pipeline.graphs.generated.resample`).
    ``decoder``: the VAE, its token and node vocabularies; ``seeding``: the base seed and the room type."""
    net, tokens, vocab = decoder
    seed, room_type = seeding

    def draw(part: list[int], s: int) -> list:
        gen = torch.Generator().manual_seed(s)
        rooms = [held[i % len(held)] for i in part]
        z = decoding.prior_codes(len(part), net.to_mu.out_features, gen)
        syntax = masker(tokens, len(part), rules, sc["mask"])
        rows = decoding.decode(net, z, prefixes(rooms, vocab, tokens), tokens, (sc["max_length"], sc["temperature"], gen),
                               syntax)
        return verdicts(rows, rooms, tokens, vocab, rules, syntax)

    return resample(n, sc["resample_budget"], sc["batch_size"], seed, draw, f"strings {room_type}")
