"""Relation graphs as strings (issue 31, items 1-2) on a run's final graphs: per room type, tokens per string, the
token vocabulary, strings per graph, the time to write and read one, and how many held-out real graphs the training split's grammar
accepts (the rejection a perfect generator would still meet).

    .venv/bin/python bench/strings.py [--room-types bedroom living ...] [--orders 20]

Reads results/graphs/ingested/{nodes,edges}.parquet and results/splits/<type>.parquet of a pipeline run.
"""
from __future__ import annotations

import time

import numpy as np

from pipeline.graphs.files import read_split, room_graphs
from pipeline.methods.strings.grammar import DETAILS, learn_grammar
from pipeline.methods.strings.serialize import parse, serialize, string_graph, tokens

from common import ROOT, arguments, report

RUN = ROOT / "results"


def room_type_figures(room_type: str, orders: int) -> dict:
    vocab, graphs = room_graphs(RUN / "graphs/ingested/nodes.parquet", RUN / "graphs/ingested/edges.parquet", room_type)
    split = read_split(RUN / f"splits/{room_type}.parquet")
    strings = {g.room_id: string_graph(g, vocab) for g in graphs}
    train = [s for r, s in strings.items() if split.get(r) in ("fit", "validation")]
    held = [s for r, s in strings.items() if split.get(r) == "heldout"]
    grammars = {d: learn_grammar(train, d) for d in DETAILS}
    rng, texts, start = np.random.default_rng(0), [], time.perf_counter()
    for g in train:
        texts += [serialize(g, rng) for _ in range(orders)]
    seconds = time.perf_counter() - start
    start = time.perf_counter()
    back = [parse(t) for t in texts]
    parse_seconds = time.perf_counter() - start
    toks = [tokens(t) for t in texts]
    per_graph = [len(set(texts[k * orders:(k + 1) * orders])) for k in range(len(train))]
    return {"train_graphs": len(train), "heldout_graphs": len(held), "strings": len(texts),
            "distinct_strings_per_graph_mean": round(float(np.mean(per_graph)), 2),
            "tokens_per_string_mean": round(float(np.mean([len(t) for t in toks])), 1),
            "tokens_per_string_max": max(len(t) for t in toks), "vocabulary": len({t for ts in toks for t in ts}),
            "edges_read_back": int(sum(len(b.edges) for b in back)), "edges_written": int(orders * sum(len(g.edges) for g in train)),
            "ms_per_string_serialize": round(1000 * seconds / len(texts), 3),
            "ms_per_string_parse": round(1000 * parse_seconds / len(texts), 3),
            "heldout_valid_under_training_grammar": {d: round(float(np.mean([gr.valid(g) for g in held])), 3)
                                                     for d, gr in grammars.items()},
            "train_valid_under_training_grammar": {d: round(float(np.mean([gr.valid(g) for g in train])), 3)
                                                   for d, gr in grammars.items()}}


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--room-types", nargs="+", default=["bedroom", "living", "office", "kitchen", "bathroom"])
    ap.add_argument("--orders", type=int, default=20)
    args = ap.parse_args()
    report({t: room_type_figures(t, args.orders) for t in args.room_types}, args.workdir, "strings")


if __name__ == "__main__":
    main()
