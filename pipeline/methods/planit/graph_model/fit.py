"""Fit PlanIT's graph model on one room type's fit graphs (validation graphs choose the epoch; the held-out graphs
are scored once, after training)."""
from __future__ import annotations

import logging
from pathlib import Path

import pandas as pd
import torch

from ....config import config_hash
from ....graphs import checks as graph_checks
from ....graphs.data import Graph, Vocab
from ....graphs.files import split_graphs
from ....learning import epochs
from ....learning.checkpoint import Checkpoint
from ....learning.device import pick_device
from ....learning.fitted import Fitted
from ....log import progress
from . import train

log = logging.getLogger("planit.train_graph_model")


def fit_room_type(config: dict, vocab: Vocab, graphs: list[Graph], split: dict[str, str], room_type: str,
                  progress_file: Path, threads: int = 1) -> Fitted:
    """Train on the ``fit`` graphs until ``validation`` stops improving; ``progress_file`` resumes an interrupted
    run with the same settings."""
    gm = config["graph_model"]
    preset = gm["presets"][gm["preset"]]
    torch.set_num_threads(threads)
    parts = split_graphs(graphs, split, room_type)
    ids = {s: [g.room_id for g in gs] for s, gs in parts.items()}
    train_g, val_g, held_g = parts["fit"], parts["validation"], parts["heldout"]
    device = pick_device(gm["device"])
    chash = config_hash({"preset": preset, "max_edges": gm["max_edges"], "heldout_fraction": gm["heldout_fraction"],
                         "validation_fraction": gm["validation_fraction"], "seed": config["seed"],
                         "room_type": room_type, "graphs": sorted(g.room_id for g in graphs)})
    session = epochs.Session(config["seed"], progress_file, chash, device, _ticker(room_type, preset))
    run_ = train.train(train_g, val_g, vocab, preset, gm["max_edges"], session)
    test = heldout_scores(run_.model, held_g, vocab, preset, gm["max_edges"], config["seed"], device)
    log.info("held-out NLL of the chosen epoch (%d): %.2f per graph", run_.best_epoch, test["per_graph"])
    ckpt = Checkpoint(train.KIND, chash, {"model": run_.model.state_dict()}, {
        "room_type": room_type, "categories": list(vocab.categories), "preset": preset, "max_edges": gm["max_edges"],
        "train_ids": ids["fit"], "validation_ids": ids["validation"], "heldout_ids": ids["heldout"],
        "heldout_nll": test, "seen": sorted(graph_checks.seen_triples(train_g))})
    history = pd.DataFrame(run_.history)
    sizes = (len(train_g), len(val_g), len(held_g))
    return Fitted(ckpt, history, _summary(history, run_, room_type, sizes, test, device, preset),
                  _curve(history, room_type))


def _ticker(room_type: str, preset: dict):
    bar = iter(progress(range(preset["max_epochs"]), desc=f"train {room_type} (max {preset['max_epochs']} epochs)"))

    def tick(epoch, row):
        next(bar, None)
        log.info("epoch %d: train NLL %.2f, validation NLL %.2f, %.1f graphs/s", epoch, row["train_nll"],
                 row["validation_nll"], row["graphs_per_s"])
    return tick


def heldout_scores(model, held, vocab, preset: dict, max_edges: int, seed: int, device: str) -> dict:
    """The chosen weights' NLL on the held-out (test) graphs, once after training: per graph and per decision."""
    model.eval()
    nll = train.heldout_nll(model, held, vocab, seed, max_edges, preset["batch_size"], device)
    return {k: round(v, 4) for k, v in train.mean_nll(nll).items()}


def _summary(history, run_, room_type, sizes, test, device, preset) -> dict:
    elapsed = history["seconds"].cumsum()
    best = float(history["validation_nll"].min())
    within = history.index[history["validation_nll"] <= best * 1.02]
    return {"room_type": room_type, "train_graphs": sizes[0], "validation_graphs": sizes[1], "heldout_graphs": sizes[2],
            "device": device, "preset": preset, "epochs": int(len(history)), "best_epoch": int(run_.best_epoch),
            "best_validation_nll": round(best, 4), "heldout_nll": test["per_graph"],
            "train_seconds": round(float(elapsed.iloc[-1]), 1),
            "seconds_to_within_2pct_of_best": round(float(elapsed.iloc[within[0]]), 1),
            "graphs_per_s": round(float(history["graphs_per_s"].median()), 1),
            "edges_dropped_per_epoch": int(history["edges_dropped"].iloc[-1]), "resumed_from_epoch": run_.resumed_from}


def _curve(history, room_type: str):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(history["epoch"], history["train_nll"], label="train")
    ax.plot(history["epoch"], history["validation_nll"], label="validation")
    ax.set(xlabel="epoch", ylabel="NLL per graph (nats)", title=f"graph model, {room_type}")
    ax.legend()
    fig.tight_layout()
    return fig
