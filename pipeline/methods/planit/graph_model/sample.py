"""Sample relation graphs of one room type from PlanIT's trained graph model: from scratch in held-out rooms'
architectures, or completing a partial graph given as a YAML spec. Invalid graphs are resampled (a budget); the ones
still invalid are counted, never returned."""
from __future__ import annotations

import logging
from collections import Counter
from pathlib import Path

import torch

from ....errors import InputError
from ....graphs import checks as graph_checks, data as graph_data
from ....graphs.data import ARCH
from ....graphs.generated import contents_of, graph_rows, link_rules, resample
from ....learning import checkpoint
from ....seeding import seed_of
from . import train
from .sampler import sample
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


def sample_room_type(config: dict, model: Path, graphs: list, nodes: Path, edges: Path, room_type: str,
                     spec: Path | None = None, count: int | None = None, threads: int = 1,
                     prefix: str | None = None) -> tuple[list, list, dict]:
    """``count`` (default ``graph_model.sample.graphs``) valid graphs as generated_nodes / generated_edges rows, and
    a summary of the sampling; with ``spec``, graphs that complete that partial graph. ``graphs``: the room type's
    final graphs (``nodes``, ``edges``: their tables, whose architecture rows the sampled graphs copy); scene ids
    are ``<prefix>_<k>`` (default ``gen_<room type>``)."""
    sc = config["graph_model"]["sample"]
    torch.set_num_threads(threads)
    saved, vocab, net = load_model(model)
    by_id = {g.room_id: g for g in graphs}
    held = [by_id[i] for i in saved["heldout_ids"] if i in by_id]
    seen = {tuple(t) for t in saved["seen"]}
    heldout_ids = set(saved["heldout_ids"])
    train_graphs = [g for g in graphs if g.room_id not in heldout_ids]
    caps, required = contents_of(train_graphs, vocab, sc["contents"])
    opposite_ok = graph_checks.opposite_classes(train_graphs)
    links = link_rules(train_graphs, sc["contents"])
    plan = None
    if spec is not None:
        plan, arch_from = load_spec(spec, room_type, vocab)
        if arch_from and arch_from not in by_id:
            raise InputError(f"{spec}: architecture.room: no room '{arch_from}' of type {room_type} in {nodes}")
        held = [by_id[arch_from]] if arch_from else held
        seen |= _plan_triples(plan)  # what the spec asks for is allowed, seen in training or not
    if not held:
        raise InputError(f"{model}: none of its held-out rooms is in {nodes}; retrain (snakemake --forcerun train_graph_model)")
    n = count or sc["graphs"]
    base_seed = seed_of(config["seed"], room_type, Path(spec).name if spec else "")
    kept, first_try, reasons = _sample_valid(net, vocab, held, n, sc, (seen, caps, required, opposite_ok, links), plan, base_seed,
                                             saved["max_edges"], room_type)
    rows_n, rows_e = graph_rows(kept, vocab, nodes, edges, room_type, prefix or f"gen_{room_type}")
    summary = {"room_type": room_type, "requested": n, "written": len(kept), "failed_after_budget": n - len(kept),
               "valid_before_rejection": round(first_try / max(n, 1), 4), "rejections": dict(reasons),
               "temperature": sc["temperature"], "spec": Path(spec).name if spec else None}
    log.info("%s", summary)
    return rows_n, rows_e, summary


def _plan_triples(plan) -> set[tuple[int, int, int]]:
    cls = [len(ARCH) + c for c, _, _ in plan.objects]
    return {(cls[k], cls[j], c) if d == 0 else (cls[j], cls[k], c) for k, d, c, j in plan.edges}


def _sample_valid(net, vocab, held, n, sc, rules, plan, base_seed, max_edges, room_type) -> tuple[dict, int, Counter]:
    """Graph index -> (valid graph, seed); how many were valid at the first try; rejections by reason. A graph that
    fails the checks is sampled again, up to ``resample_budget`` times. ``rules``: the seen edge triples, the count
    caps and the required classes (:func:`contents_of`), the classes the training graphs show near two opposite
    walls and their link rules (:func:`link_rules`)."""
    seen, caps, required, opposite_ok, links = rules

    def draw(part: list[int], seed: int) -> list:
        grown = sample(net, vocab, [held[i % len(held)] for i in part], seed, sc["temperature"], sc["max_objects"],
                       max_edges, [plan] * len(part) if plan else None, seen, caps, opposite_ok)
        return [(g, graph_checks.problems(g.node_class, g.role, g.edges, g.arch.n_arch, seen, required, opposite_ok,
                                          links))
                for g in grown]

    return resample(n, sc["resample_budget"], sc["batch_size"], base_seed, draw, f"sample {room_type}")
