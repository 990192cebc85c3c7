"""Sample relation graphs of one room type from PlanIT's trained graph model: from scratch in held-out rooms'
architectures, or completing a partial graph given as a YAML spec. Invalid graphs are resampled (a budget); the ones
still invalid are counted, never returned."""
from __future__ import annotations

import logging
from collections import Counter
from dataclasses import replace
from pathlib import Path

import torch

from ....errors import InputError
from ....graphs import checks as graph_checks, data as graph_data
from ....graphs.data import ARCH
from ....graphs.generated import graph_rows, graph_rules, resample
from ....learning import checkpoint
from ....seeding import seed_of
from ...interface import GraphRequest
from . import train
from .sampler import Limits, sample
from .spec import load_spec

log = logging.getLogger("planit.sample_graphs")


def load_model(path: Path):
    """The model file's record, vocabulary and rebuilt model (weights loaded, on the CPU, eval mode)."""
    ckpt = checkpoint.load(path, train.KIND)
    saved = ckpt.record
    vocab = graph_data.Vocab(tuple(saved["categories"]))
    model = train.build_model(vocab, saved["preset"])
    model.load_state_dict(ckpt.state["model"])
    model.eval()
    return saved, vocab, model


def sample_room_type(config: dict, request: GraphRequest, threads: int = 1) -> tuple[list, list, dict]:
    """The request's ``count`` (default ``graph_model.sample.graphs``) valid graphs as generated_nodes /
    generated_edges rows, and a summary of the sampling; with its ``spec``, graphs that complete that partial graph;
    scene ids ``<prefix>_<k>`` (default ``gen_<room type>``)."""
    model, graphs, nodes, room_type, spec = request.model, request.graphs, request.nodes, request.room_type, request.spec
    sc = config["graph_model"]["sample"]
    torch.set_num_threads(threads)
    saved, vocab, net = load_model(model)
    by_id = {g.room_id: g for g in graphs}
    held = [by_id[i] for i in saved["heldout_ids"] if i in by_id]
    heldout_ids = set(saved["heldout_ids"])
    train_graphs = [g for g in graphs if g.room_id not in heldout_ids]
    rules = graph_rules(train_graphs, vocab, sc["contents"])  # seen: also in the model's own training graphs
    rules = replace(rules, seen=frozenset(tuple(t) for t in saved["seen"]) & rules.seen)
    plan = None
    if spec is not None:
        plan, arch_from = load_spec(spec, room_type, vocab)
        if arch_from and arch_from not in by_id:
            raise InputError(f"{spec}: architecture.room: no room '{arch_from}' of type {room_type} in {nodes}")
        held = [by_id[arch_from]] if arch_from else held
        rules = replace(rules, seen=rules.seen | _plan_triples(plan))  # what the spec asks for is allowed
    if not held:
        raise InputError(f"{model}: none of its held-out rooms is in {nodes}; retrain (snakemake --forcerun train_graph_model)")
    n = request.count or sc["graphs"]
    base_seed = seed_of(config["seed"], room_type, Path(spec).name if spec else "")
    limits = Limits(sc["max_objects"], saved["max_edges"], rules)
    draw = lambda rooms, seed: sample(net, vocab, rooms, seed, sc["temperature"], limits,
                                      [plan] * len(rooms) if plan else None)
    kept, first_try, reasons = _sample_valid(draw, held, n, sc, rules,
                                             (base_seed, room_type))
    rows_n, rows_e = graph_rows(kept, vocab, nodes, request.edges, room_type, request.prefix or f"gen_{room_type}")
    summary = {"room_type": room_type, "requested": n, "written": len(kept), "failed_after_budget": n - len(kept),
               "valid_before_rejection": round(first_try / max(n, 1), 4), "rejections": dict(reasons),
               "temperature": sc["temperature"], "spec": Path(spec).name if spec else None}
    log.info("%s", summary)
    return rows_n, rows_e, summary


def _plan_triples(plan) -> set[tuple[int, int, int]]:
    cls = [len(ARCH) + c for c, _, _ in plan.objects]
    return {(cls[k], cls[j], c) if d == 0 else (cls[j], cls[k], c) for k, d, c, j in plan.edges}


def _sample_valid(draw, held: list, n: int, sc: dict, rules, seeding: tuple[int, str]) -> tuple[dict, int, Counter]:
    """Graph index -> (valid graph, seed); how many were valid at the first try; rejections by reason. ``draw(rooms,
    seed)`` grows one graph in each room's architecture (the held-out rooms in turn); a graph that breaks the training
    graphs' ``rules`` (:func:`~pipeline.graphs.checks.problems`) is drawn again, up to ``resample_budget`` times.
    ``seeding``: the base seed and the room type."""
    base_seed, room_type = seeding

    def checked(part: list[int], seed: int) -> list:
        grown = draw([held[i % len(held)] for i in part], seed)
        return [(g, graph_checks.problems(g.node_class, g.role, g.edges, g.arch.n_arch, rules)) for g in grown]

    return resample(n, sc["resample_budget"], sc["batch_size"], base_seed, checked, f"sample {room_type}")
