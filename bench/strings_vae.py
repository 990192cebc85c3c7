"""The string VAE (issue 31, item 3) on a pipeline run's trained models: per room type, milliseconds per sampled
graph in batches, the share valid before rejection under each decoder mask (grammar, syntax, none), the rejections,
interpolation (32 codes on a straight path between two held-out rooms' codes, decoded greedily in the first room's
architecture under the config's mask: the share of points giving a valid graph) and, from the run's metrics.json files, each graph metric
of the string VAE beside PlanIT's graph model's (the goal: within 1.2x on every room type).

    .venv/bin/python bench/strings_vae.py [--room-types bedroom ...] [--graphs 200] [--pairs 5]

Run it in a pipeline run's folder: it reads results/graph_model/<type>/{planit,strings}/ and
results/graphs/ingested/ (the config's strings.sample settings otherwise).
"""
from __future__ import annotations

import json
import time
from collections import Counter
from pathlib import Path

import numpy as np
import torch

from pipeline import config as planit_config
from pipeline.graphs.files import room_graphs
from pipeline.methods.strings import rooms as R, sample as decoding
from pipeline.methods.strings.fit import rooms_of
from pipeline.methods.strings.train import room_strings

from common import arguments, report

RUN = Path("results")  # the pipeline run in the current folder
METRICS = ("node_count_tv", "category_kl", "edge_type_kl", "degree_mmd")


def draw(net, tokens, vocab, held, rules, n, cfg, mask: str, seed: int) -> tuple[int, Counter, float]:
    """Valid graphs of ``n`` drawn at once with the decoder's ``mask``, the rejections, seconds."""
    gen = torch.Generator().manual_seed(seed)
    rooms = [held[i % len(held)] for i in range(n)]
    start = time.perf_counter()
    z = decoding.prior_codes(n, net.to_mu.out_features, gen)
    masker = R.masker(tokens, n, rules, mask)
    rows = decoding.decode(net, z, R.prefixes(rooms, vocab, tokens), tokens, (cfg["max_length"], cfg["temperature"], gen),
                           masker)
    seconds = time.perf_counter() - start
    judged = R.verdicts(rows, rooms, tokens, vocab, rules, masker)
    return sum(g is not None for g, _ in judged), Counter(b for _, bad in judged for b in bad), seconds


def interpolation(net, tokens, vocab, held, rules, cfg, pairs: int) -> float:
    """Share of 32-point paths' codes (between two held-out rooms) that decode greedily to a valid graph."""
    rng = np.random.default_rng(0)
    texts = room_strings(rooms_of(held, vocab), None)
    mu = decoding.encode_means(net, [t for t, _ in texts], tokens, cfg["max_length"])
    valid = []
    for _ in range(pairs):
        a, b = rng.choice(len(held), 2, replace=False)
        z = decoding.path_codes(mu[a], mu[b], 32)
        masker = R.masker(tokens, 32, rules, cfg["mask"])
        rows = decoding.decode(net, z, R.prefixes([held[a]] * 32, vocab, tokens), tokens,
                               (cfg["max_length"], 0.0, torch.Generator().manual_seed(0)), masker)
        valid += [g is not None for g, _ in R.verdicts(rows, [held[a]] * 32, tokens, vocab, rules, masker)]
    return round(float(np.mean(valid)), 3)


def room_type_figures(room_type: str, graphs: int, pairs: int, config: dict) -> dict:
    torch.set_num_threads(1)
    cfg = config["strings"]["sample"]
    model = RUN / "graph_model" / room_type / "strings" / "model.pt"
    rec, vocab, tokens, net = R.load_model(model)
    _, all_graphs = room_graphs(RUN / "graphs/ingested/nodes.parquet", RUN / "graphs/ingested/edges.parquet", room_type)
    by_id = {g.room_id: g for g in all_graphs}
    held = [by_id[i] for i in rec["heldout_ids"]]
    rules = R.Rules([by_id[i] for i in rec["train_ids"] + rec["validation_ids"]], vocab, cfg["grammar"],
                    config["graph_model"]["sample"]["contents"])
    out = {}
    for mask in ("grammar", "syntax", "none"):
        ok, reasons, seconds = draw(net, tokens, vocab, held, rules, graphs, cfg, mask, 1)
        out[f"mask_{mask}"] = {"valid": round(ok / graphs, 3), "ms_per_graph": round(1000 * seconds / graphs, 2),
                               "rejections": dict(reasons.most_common())}
    out["interpolation_valid"] = interpolation(net, tokens, vocab, held, rules, cfg, pairs)
    ratios = {}
    for gen in ("planit", "strings"):
        m = json.loads((RUN / "graph_model" / room_type / gen / "metrics.json").read_text())
        ratios[gen] = {k: m["ratio_to_floor"][k] for k in METRICS} | {"valid_before_rejection": m["valid_before_rejection"],
                                                                      "novelty": m.get("novelty")}
    out["metrics_ratio_to_floor"] = ratios
    out["within_1.2x_of_planit"] = {k: (ratios["strings"][k] is not None and ratios["planit"][k] is not None
                                        and ratios["strings"][k] <= 1.2 * ratios["planit"][k]) for k in METRICS}
    return out


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--room-types", nargs="+", default=["bedroom", "living", "office", "kitchen", "bathroom"])
    ap.add_argument("--graphs", type=int, default=200)
    ap.add_argument("--pairs", type=int, default=5)
    args = ap.parse_args()
    config = planit_config.load(None)
    report({t: room_type_figures(t, args.graphs, args.pairs, config) for t in args.room_types}, args.workdir, "strings_vae")


if __name__ == "__main__":
    main()
