"""Train the graph model of one room type on the final graphs (kept edges); one job per room type."""
from __future__ import annotations

import logging
from pathlib import Path

from .. import tables
from ..config import config_hash
from ..errors import InputError
from ..log import progress
from ..stage import Files

log = logging.getLogger("planit.train_graph_model")


def room_graphs(nodes: Path, edges: Path, room_type: str):
    """The room type's final graphs and their vocabulary."""
    from ..graphs import data as graph_data

    flt = [("room_type", "=", room_type)]
    node_df = tables.read(nodes, "final_nodes", filters=flt).to_pandas()
    edge_df = tables.read(edges, "final_edges", filters=flt).to_pandas()
    if node_df.empty:
        raise InputError(f"{nodes}: no graph of room type '{room_type}' (set graph_model.room_types)")
    vocab = graph_data.vocab_of(node_df)
    return vocab, graph_data.graphs_from_tables(node_df, edge_df, vocab)


def splits(room_ids: list[str], gm: dict, seed: int) -> tuple[list[str], list[str], list[str]]:
    """Seeded (fit, validation, test) room ids: the test rooms are the held-out split every evaluation uses; the
    validation rooms come out of the rest."""
    from ..graphs import data as graph_data

    rest, test = graph_data.split_heldout(room_ids, gm["heldout_fraction"], seed)
    fit, validation = graph_data.split_heldout(rest, gm["validation_fraction"], seed, stream=4343)
    return fit, validation, test


def run(config: dict, inp: Files, out: Files, room_type: str, threads: int = 1) -> dict:
    """Train, write the best weights (with vocabulary, split, the test NLL and seen edge types), the loss curves and
    a summary. The checkpoint beside ``out.model`` resumes an interrupted run with the same settings."""
    nodes, edges = inp.nodes, inp.edges
    out_model, out_history, out_curve, out_summary = out.model, out.history, out.curve, out.summary
    import torch

    from ..graphs import checks as graph_checks
    from ..learning import checkpoint
    from ..methods.planit.graph_model import train

    gm = config["graph_model"]
    preset = gm["presets"][gm["preset"]]
    torch.set_num_threads(threads)
    vocab, graphs = room_graphs(nodes, edges, room_type)
    fit_ids, val_ids, held_ids = splits([g.room_id for g in graphs], gm, config["seed"])
    if not fit_ids or not val_ids or not held_ids:
        raise InputError(f"{nodes}: room type '{room_type}' has {len(graphs)} graph(s); training needs 3 or more "
                         "(fitted, validation and held-out)")
    by_id = {g.room_id: g for g in graphs}
    train_g, val_g, held_g = ([by_id[i] for i in ids] for ids in (fit_ids, val_ids, held_ids))
    device = train.pick_device(gm["device"])
    chash = config_hash({"preset": preset, "max_edges": gm["max_edges"], "heldout_fraction": gm["heldout_fraction"],
                         "validation_fraction": gm["validation_fraction"], "seed": config["seed"],
                         "room_type": room_type, "graphs": sorted(by_id)})
    bar = iter(progress(range(preset["max_epochs"]), desc=f"train {room_type} (max {preset['max_epochs']} epochs)"))

    def tick(epoch, row):
        next(bar, None)
        log.info("epoch %d: train NLL %.2f, validation NLL %.2f, %.1f graphs/s", epoch, row["train_nll"],
                 row["validation_nll"], row["graphs_per_s"])

    run_ = train.train(train_g, val_g, vocab, preset, gm["max_edges"], config["seed"], out_model.with_name("checkpoint.pt"),
                       chash, device, tick)
    test = heldout_scores(run_.model, held_g, vocab, preset, gm["max_edges"], config["seed"], device)
    log.info("held-out NLL of the chosen epoch (%d): %.2f per graph", run_.best_epoch, test["per_graph"])
    checkpoint.save(out_model, checkpoint.Checkpoint(train.KIND, chash, {"model": run_.model.state_dict()}, {
        "room_type": room_type, "categories": list(vocab.categories), "preset": preset, "max_edges": gm["max_edges"],
        "train_ids": fit_ids, "validation_ids": val_ids, "heldout_ids": held_ids, "heldout_nll": test,
        "seen": sorted(graph_checks.seen_triples(train_g))}))
    import pandas as pd

    history = pd.DataFrame(run_.history)
    tables.write_csv(out_history, history)
    tables.write_figure(out_curve, _curve(history, room_type))
    summary = _summary(history, run_, room_type, (len(train_g), len(val_g), len(held_g)), test, device, preset)
    tables.write_json(out_summary, summary)
    return summary


def heldout_scores(model, held, vocab, preset: dict, max_edges: int, seed: int, device: str) -> dict:
    """The chosen weights' NLL on the held-out (test) graphs, once after training: per graph and per decision."""
    from ..methods.planit.graph_model import train

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
