"""Evaluate one room type's graph generator (PlanIT's graph model or another): its sampled graphs against the
held-out real graphs (metrics.json)."""
from __future__ import annotations

import json
import logging
from pathlib import Path

from .. import tables
from ..evaluation.graph_model import graph_model_metrics
from ..graphs import data as graph_data
from ..graphs.files import room_graphs
from ..stage import Files

log = logging.getLogger("planit.graph_model_metrics")


def run(config: dict, inp: Files, out: Files, room_type: str, generator: str = "planit") -> dict:
    from ..learning import checkpoint
    from ..methods import graph_source

    saved = checkpoint.load(inp.model, graph_source(generator).kind).record
    vocab = graph_data.Vocab(tuple(saved["categories"]))
    _, real = room_graphs(inp.nodes, inp.edges, room_type)
    by_id = {g.room_id: g for g in real}
    train = [by_id[i] for i in saved["train_ids"] if i in by_id]
    held = [by_id[i] for i in saved["heldout_ids"] if i in by_id]
    gen = graph_data.graphs_from_tables(tables.read(inp.gen_nodes, "generated_nodes").to_pandas(),
                                        tables.read(inp.gen_edges, "generated_edges").to_pandas(), vocab)
    valid = json.loads(Path(inp.sample_summary).read_text())["valid_before_rejection"]
    sets = {"real": real, "train": train, "heldout": held, "generated": gen}
    metrics = graph_model_metrics(config, room_type, vocab, sets, saved["heldout_nll"], valid)
    tables.write_json(out.metrics, metrics)
    log.info("%s: %s", room_type, metrics["goals"])
    return metrics
