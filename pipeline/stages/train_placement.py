"""Train the placement networks (location CFCN + orientation) of one room type on the training rooms of the graph
model's split (the same seeded held-out rooms are never trained on); ``film=False`` trains the unconditional FCN
of the ablation."""
from __future__ import annotations

import logging
from pathlib import Path

import pandas as pd

from .. import tables
from ..config import config_hash
from ..errors import InputError
from ..log import progress
from ..room import load_rooms
from ..stage import Files

log = logging.getLogger("planit.train_placement")


def training_rooms(config: dict, room_type: str, rooms, architecture, objects, nodes: Path, edges: Path):
    """Categories, training and held-out :class:`TrainingRoom` lists, and the held-out ids (the graph model's split)."""
    from ..graphs import data as graph_data
    from ..methods.planit.nets.data import training_room

    flt = [("room_type", "=", room_type)]
    node_df = tables.read(nodes, "final_nodes", filters=flt).to_pandas()
    edge_df = tables.read(edges, "final_edges", filters=flt).to_pandas()
    if node_df.empty:
        raise InputError(f"{nodes}: no graph of room type '{room_type}'")
    ids = sorted(node_df["room_id"].unique())
    train_ids, held_ids = graph_data.split_heldout(ids, config["graph_model"]["heldout_fraction"], config["seed"])
    _, _, objs, inputs = load_rooms(rooms, architecture, objects, set(ids))
    cats = tuple(sorted(objs["category"].astype(str).unique()))
    by_room_n, by_room_e = dict(tuple(node_df.groupby("room_id"))), dict(tuple(edge_df.groupby("room_id")))
    make = lambda i: training_room(inputs[i], by_room_n[i], by_room_e.get(i, edge_df.iloc[:0]))
    return cats, [make(i) for i in train_ids if i in inputs], [make(i) for i in held_ids if i in inputs], held_ids


def run(config: dict, inp: Files, out: Files, room_type: str, net: str, threads: int = 1) -> dict:
    rooms, architecture, objects, nodes, edges = inp.rooms, inp.architecture, inp.objects, inp.nodes, inp.edges
    out_model, out_history, out_curve, out_summary = out.model, out.history, out.curve, out.summary
    if net not in ("cfcn", "fcn"):
        raise InputError(f"--net: '{net}' is not one of cfcn, fcn")
    import torch

    from ..methods.planit.nets import train as placement_train
    from ..learning import checkpoint
    from ..learning.device import pick_device

    pc = config["placement"]
    preset = pc["presets"][pc["preset"]]
    torch.set_num_threads(threads)
    cats, train_rooms, held_rooms, held_ids = training_rooms(config, room_type, rooms, architecture, objects, nodes, edges)
    if not train_rooms:
        raise InputError(f"{nodes}: room type '{room_type}' has no training room")
    device = pick_device(pc["device"])
    chash = config_hash({"preset": preset, "net": net, "seed": config["seed"], "room_type": room_type,
                         "rooms": sorted(t.room.room_id for t in train_rooms), "categories": cats})
    bar = iter(progress(range(preset["steps"] // preset["log_every"] + 1), desc=f"train placement {room_type} ({net})"))

    def tick(step, row):
        next(bar, None)
        log.info("step %d: location %.3f (held-out %.3f), orientation %.3f (held-out %.3f)", step, row["location_loss"],
                 row["heldout_location_loss"], row["orientation_loss"], row["heldout_orientation_loss"])

    nets, history = placement_train.train(train_rooms, held_rooms, cats, preset, net == "cfcn", config["seed"],
                                          out_model.with_name("checkpoint.pt"), chash, device, tick)
    checkpoint.save(out_model, checkpoint.Checkpoint(placement_train.KIND, chash, {"nets": [n.cpu().state_dict() for n in nets]}, {
        "room_type": room_type, "net": net, "categories": list(cats), "preset": preset, "heldout_ids": held_ids}))
    frame = pd.DataFrame(history)
    tables.write_csv(out_history, frame)
    tables.write_figure(out_curve, _curve(frame, room_type, net))
    summary = {"room_type": room_type, "net": net, "preset": pc["preset"], "device": device, "train_rooms": len(train_rooms),
               "heldout_rooms": len(held_rooms), "steps": int(frame["step"].iloc[-1]),
               "train_seconds": round(float(frame["seconds"].iloc[-1]), 1),
               "final_heldout_location_loss": round(float(frame["heldout_location_loss"].iloc[-1]), 4),
               "final_heldout_orientation_loss": round(float(frame["heldout_orientation_loss"].iloc[-1]), 4)}
    tables.write_json(out_summary, summary)
    return summary


def _curve(history, room_type: str, net: str):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(8, 3.2))
    for ax, name in zip(axes, ("location", "orientation")):
        ax.plot(history["step"], history[f"{name}_loss"], label="train")
        ax.plot(history["step"], history[f"heldout_{name}_loss"], label="held-out")
        ax.set(xlabel="step", ylabel="loss", title=f"{name}, {room_type} ({net})")
        ax.legend()
    fig.tight_layout()
    return fig
