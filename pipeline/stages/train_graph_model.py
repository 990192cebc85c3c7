"""Train the graph model of one room type on the final graphs (kept edges); one job per room type."""
from __future__ import annotations

import logging
from pathlib import Path

from .. import tables
from ..config import config_hash
from ..errors import InputError
from ..log import progress

log = logging.getLogger("planit.train_graph_model")


def room_graphs(nodes: Path, edges: Path, room_type: str):
    """The room type's final graphs, their vocabulary, and the seeded (train, held-out) split of room ids."""
    from ..learn import graph_data

    flt = [("room_type", "=", room_type)]
    node_df = tables.read(nodes, "final_nodes", filters=flt).to_pandas()
    edge_df = tables.read(edges, "final_edges", filters=flt).to_pandas()
    if node_df.empty:
        raise InputError(f"{nodes}: no graph of room type '{room_type}' (set graph_model.room_types)")
    vocab = graph_data.vocab_of(node_df)
    return vocab, graph_data.graphs_from_tables(node_df, edge_df, vocab)


def run(config: dict, room_type: str, nodes: Path, edges: Path, out_model: Path, out_history: Path, out_curve: Path,
        out_summary: Path, threads: int = 1) -> dict:
    """Train, write the best weights (with vocabulary, split and seen edge types), the loss curves and a summary.
    The checkpoint beside ``out_model`` resumes an interrupted run with the same settings."""
    import torch

    from ..learn import graph_checks, graph_data, train

    gm = config["graph_model"]
    preset = gm["presets"][gm["preset"]]
    torch.set_num_threads(threads)
    vocab, graphs = room_graphs(nodes, edges, room_type)
    train_ids, held_ids = graph_data.split_heldout([g.room_id for g in graphs], gm["heldout_fraction"], config["seed"])
    if not train_ids or not held_ids:
        raise InputError(f"{nodes}: room type '{room_type}' has {len(graphs)} graph(s); training needs 2 or more")
    by_id = {g.room_id: g for g in graphs}
    train_g, held_g = [by_id[i] for i in train_ids], [by_id[i] for i in held_ids]
    device = train.pick_device(gm["device"])
    chash = config_hash({"preset": preset, "max_edges": gm["max_edges"], "heldout_fraction": gm["heldout_fraction"],
                         "seed": config["seed"], "room_type": room_type, "graphs": sorted(by_id)})
    bar = iter(progress(range(preset["max_epochs"]), desc=f"train {room_type} (max {preset['max_epochs']} epochs)"))

    def tick(epoch, row):
        next(bar, None)
        log.info("epoch %d: train NLL %.2f, held-out NLL %.2f, %.1f graphs/s", epoch, row["train_nll"],
                 row["heldout_nll"], row["graphs_per_s"])

    run_ = train.train(train_g, held_g, vocab, preset, gm["max_edges"], config["seed"], out_model.with_name("checkpoint.pt"),
                       chash, device, tick)
    tables.write_atomic(out_model, lambda tmp: torch.save({
        "config_hash": chash, "room_type": room_type, "categories": list(vocab.categories), "preset": preset,
        "max_edges": gm["max_edges"], "state_dict": run_.model.state_dict(), "train_ids": train_ids,
        "heldout_ids": held_ids, "seen": sorted(graph_checks.seen_triples(train_g))}, tmp))
    import pandas as pd

    history = pd.DataFrame(run_.history)
    tables.write_csv(out_history, history)
    tables.write_figure(out_curve, _curve(history, room_type))
    summary = _summary(history, run_, room_type, len(train_g), len(held_g), device, preset)
    tables.write_json(out_summary, summary)
    return summary


def _summary(history, run_, room_type, n_train, n_held, device, preset) -> dict:
    elapsed = history["seconds"].cumsum()
    best = float(history["heldout_nll"].min())
    within = history.index[history["heldout_nll"] <= best * 1.02]
    return {"room_type": room_type, "train_graphs": n_train, "heldout_graphs": n_held, "device": device,
            "preset": preset, "epochs": int(len(history)), "best_epoch": int(run_.best_epoch),
            "best_heldout_nll": round(best, 4), "train_seconds": round(float(elapsed.iloc[-1]), 1),
            "seconds_to_within_2pct_of_best": round(float(elapsed.iloc[within[0]]), 1),
            "graphs_per_s": round(float(history["graphs_per_s"].median()), 1),
            "edges_dropped_per_epoch": int(history["edges_dropped"].iloc[-1]), "resumed_from_epoch": run_.resumed_from}


def _curve(history, room_type: str):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(history["epoch"], history["train_nll"], label="train")
    ax.plot(history["epoch"], history["heldout_nll"], label="held-out")
    ax.set(xlabel="epoch", ylabel="NLL per graph (nats)", title=f"graph model, {room_type}")
    ax.legend()
    fig.tight_layout()
    return fig
