"""Graph model speed on one core: the batched trainer against batch-of-one training of the same model in the same
run (graphs/s), and sampling time per graph, one graph at a time and batched.

    .venv/bin/python bench/graph_model.py [--room-type bedroom] [--preset default] [--graphs 128]
        [--graphs-dir results/graphs/ingested]

Reads the final graphs and the trained model of a pipeline run (make pipeline first). Training time to reach within 2% of the best
held-out NLL is in each room type's results/graph_model/<type>/planit/training.json (written by the pipeline).
"""
from __future__ import annotations

import platform
import statistics
import time
from pathlib import Path

import numpy as np
import torch

from pipeline import config as config_mod
from pipeline.graphs import checks as graph_checks, data as graph_data
from pipeline.graphs.checks import GraphRules
from pipeline.graphs.files import room_graphs
from pipeline.methods.planit.graph_model import sampler, train
from pipeline.methods.planit.graph_model.teacher import make_batch, nll

from common import ROOT, arguments, report


def train_rate(model, opt, seqs, vocab, batch: int, limit_s: float) -> float:
    """Graphs per second of training steps (forward, backward, Adam) at a batch size, for up to ``limit_s``."""
    start, done = time.perf_counter(), 0
    while done < len(seqs) and time.perf_counter() - start < limit_s:
        loss = nll(model, make_batch(seqs[done:done + batch], vocab)).sum(1).mean()
        opt.zero_grad()
        loss.backward()
        opt.step()
        done += len(seqs[done:done + batch])
    return done / (time.perf_counter() - start)


def sample_times(model, vocab, archs, seen, batch: int, repeats: int) -> list[float]:
    """Seconds per graph of each sampling call (``batch`` graphs per call)."""
    out = []
    for k in range(repeats):
        part = [archs[(k * batch + i) % len(archs)] for i in range(batch)]
        t = time.perf_counter()
        sampler.sample(model, vocab, part, seed=k, temperature=1.0,
                       limits=sampler.Limits(25, 10, GraphRules(frozenset(seen))))
        out.append((time.perf_counter() - t) / batch)
    return out


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--room-type", default="bedroom")
    ap.add_argument("--preset", default="default")
    ap.add_argument("--graphs", type=int, default=128)
    ap.add_argument("--graphs-dir", type=Path, default=ROOT / "results" / "graphs" / "ingested")
    args = ap.parse_args()
    torch.set_num_threads(1)
    torch.manual_seed(0)
    preset = config_mod.validate({})["graph_model"]["presets"][args.preset]
    vocab, graphs = room_graphs(args.graphs_dir / "nodes.parquet", args.graphs_dir / "edges.parquet", args.room_type)
    rng = np.random.default_rng(0)
    seqs = [graph_data.sequence(graphs[i % len(graphs)], rng, 10) for i in range(args.graphs)]
    model = train.build_model(vocab, preset)
    opt = torch.optim.Adam(model.parameters(), lr=preset["lr"])
    one = train_rate(model, opt, seqs, vocab, 1, 60.0)
    batched = train_rate(model, opt, seqs, vocab, preset["batch_size"], 600.0)
    seen = graph_checks.seen_triples(graphs)
    trained = ROOT / "results" / "graph_model" / args.room_type / "model.pt"
    if trained.exists():  # sample from the trained model (an untrained one stops at random lengths)
        from pipeline.methods.planit.graph_model.sample import load_model

        _, vocab, model = load_model(trained)
    model.eval()
    single = sample_times(model, vocab, graphs, seen, 1, 50)
    many = sample_times(model, vocab, graphs, seen, 100, 3)
    report({"room_type": args.room_type, "preset": args.preset, "machine": f"{platform.machine()}, 1 thread",
            "sampled_from": "trained model" if trained.exists() else "untrained model",
            "graphs": len(graphs), "train_graphs_per_s": {"batch_of_one": round(one, 1),
                                                          f"batch_of_{preset['batch_size']}": round(batched, 1),
                                                          "speed_up": round(batched / one, 1)},
            "sample_ms_per_graph": {"one_at_a_time_median": round(1000 * statistics.median(single), 2),
                                    "batched_100_median": round(1000 * statistics.median(many), 2)}},
           args.workdir, f"graph_model-{args.room_type}-{args.preset}")


if __name__ == "__main__":
    main()
