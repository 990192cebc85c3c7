"""Plausible contents of sampled graphs, with and without the rules learned from the training graphs
(``graph_model.sample.contents``: count caps at sampling, required categories as a validity check): how many
sampled graphs hold a category more often than any training room (or never seen) or lack a required one, and the
category KL of the sampled objects against the held-out real graphs' (with and without the rules).

    .venv/bin/python bench/contents.py [--room-types bedroom living ...] [--graphs 300]

Reads the final graphs and trained graph models of a pipeline run (make pipeline first); samples on 2 threads.
"""
from __future__ import annotations

import copy

from pipeline import config as config_mod
from pipeline.evaluation.distributions import category_kl
from pipeline.graphs.data import ARCH
from pipeline.graphs.files import room_graphs
from pipeline.methods.interface import GraphRequest
from pipeline.methods.planit.graph_model.sample import load_model, sample_room_type
from pipeline.room.contents import implausible, learn_contents

from common import ROOT, arguments, report

RUN = ROOT / "results"


def sampled_categories(config: dict, room_type: str, count: int) -> tuple[list[list[str]], dict]:
    """Each sampled graph's object categories, and the sampling summary."""
    nodes, edges = RUN / "graphs/ingested/nodes.parquet", RUN / "graphs/ingested/edges.parquet"
    _, graphs = room_graphs(nodes, edges, room_type)
    request = GraphRequest(RUN / f"graph_model/{room_type}/planit/model.pt", graphs, nodes, edges, room_type,
                           count=count)
    rows, _, summary = sample_room_type(config, request, threads=2)
    rooms: dict = {}
    for r in rows:
        if r["kind"] == "object":
            rooms.setdefault(r["room_id"], []).append(r["category"])
    return list(rooms.values()), summary


def real_categories(room_type: str) -> tuple[list[list[str]], list[list[str]]]:
    """Object categories of the training graphs and of the held-out graphs (the graph model's split)."""
    _, graphs = room_graphs(RUN / "graphs/ingested/nodes.parquet", RUN / "graphs/ingested/edges.parquet", room_type)
    saved, vocab, _ = load_model(RUN / f"graph_model/{room_type}/planit/model.pt")
    held = set(saved["heldout_ids"])
    cats = lambda g: [vocab.node_classes[c] for c in g.node_class[g.n_arch:] if c >= len(ARCH)]  # noqa: E731
    return [cats(g) for g in graphs if g.room_id not in held], [cats(g) for g in graphs if g.room_id in held]


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--room-types", nargs="+", default=["bedroom", "living", "office", "kitchen", "bathroom"])
    ap.add_argument("--graphs", type=int, default=300)
    args = ap.parse_args()
    config = config_mod.load(ROOT / "config" / "config.yaml")
    off = copy.deepcopy(config)
    off["graph_model"]["sample"]["contents"] = {"cap_counts": False, "required_share": 2.0, "links": "none", "min_edge_share": 0.0}
    result = {"graphs": args.graphs}
    for room_type in args.room_types:
        train, held = real_categories(room_type)
        learned = learn_contents(train, config["graph_model"]["sample"]["contents"]["required_share"])
        for name, cfg in (("rules", config), ("no_rules", off)):
            rooms, summary = sampled_categories(cfg, room_type, args.graphs)
            bad = [implausible(r, learned) for r in rooms]
            result[f"{room_type}_{name}"] = {
                "excess": sum(bool(e) for e, _ in bad), "missing": sum(bool(m) for _, m in bad), "graphs": len(rooms),
                "category_kl_vs_heldout": round(category_kl([c for r in held for c in r], [c for r in rooms for c in r]), 4),
                "valid_before_rejection": summary["valid_before_rejection"], "rejections": summary["rejections"]}
        result[f"{room_type}_required"] = learned["required"]
    report(result, args.workdir, "contents")


if __name__ == "__main__":
    main()
