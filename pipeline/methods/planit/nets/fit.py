"""Fit PlanIT's pose networks (location CFCN + orientation) of one room type on its training rooms (fit and
validation splits; the held-out rooms are never trained on); ``net="fcn"`` trains the unconditional pair of the
ablation (no FiLM in either)."""
from __future__ import annotations

import logging
from pathlib import Path
from typing import NamedTuple

import pandas as pd
import torch

from ....config import config_hash
from ....errors import InputError
from ....learning.checkpoint import Checkpoint
from ....learning.device import pick_device
from ....learning.epochs import Session
from ....learning.fitted import Fitted
from ....log import progress
from ...interface import RoomTypeRows
from . import train as nets_train
from .data import TrainingRoom, training_room

log = logging.getLogger("planit.train_placement")
NETS = ("cfcn", "fcn")
LOGLIK = ("heldout_location_loglik", "heldout_orientation_loglik", "heldout_pose_loglik")


class TrainingSet(NamedTuple):
    """One room type's categories, training (fit and validation) and held-out :class:`TrainingRoom` lists, and the
    held-out room ids."""
    categories: tuple[str, ...]
    train: list[TrainingRoom]
    held: list[TrainingRoom]
    held_ids: list[str]


def training_rooms(data: RoomTypeRows) -> TrainingSet:
    """The :class:`TrainingSet` of one room type's rooms and final graphs."""
    inputs, node_df, edge_df, split = data.rooms, data.nodes, data.edges, data.split
    ids = sorted(node_df["room_id"].unique())
    train_ids = [i for i in ids if split.get(i) in ("fit", "validation")]
    held_ids = [i for i in ids if split.get(i) == "heldout"]
    cats = tuple(sorted({c for i in ids if i in inputs for c in inputs[i].categories}))
    by_room_n, by_room_e = dict(tuple(node_df.groupby("room_id"))), dict(tuple(edge_df.groupby("room_id")))
    make = lambda i: training_room(inputs[i], by_room_n[i], by_room_e.get(i, edge_df.iloc[:0]))
    return TrainingSet(cats, [make(i) for i in train_ids if i in inputs], [make(i) for i in held_ids if i in inputs],
                       held_ids)


def fit_room_type(config: dict, room_type: str, net: str, rooms: TrainingSet, progress_file: Path,
                  threads: int = 1) -> Fitted:
    """Train for the preset's steps; ``progress_file`` resumes an interrupted run with the same settings."""
    cats, train_rooms, held_rooms, held_ids = rooms
    if net not in NETS:
        raise InputError(f"--net: '{net}' is not one of {', '.join(NETS)}")
    if not train_rooms:
        raise InputError(f"room type '{room_type}' has no training room")
    pc = config["placement"]
    preset = pc["presets"][pc["preset"]]
    torch.set_num_threads(threads)
    device = pick_device(pc["device"])
    data = {"snap_angle": pc["snap_angle"], "none_share": pc["none_share"]}
    chash = config_hash({"preset": preset, "net": net, "seed": config["seed"], "room_type": room_type, **data,
                         "rooms": sorted(t.room.room_id for t in train_rooms), "categories": cats})
    session = Session(config["seed"], progress_file, chash, device, _ticker(room_type, net, preset))
    nets, history = nets_train.train(train_rooms, held_rooms, cats, preset, net == "cfcn", session, data)
    ckpt = Checkpoint(nets_train.KIND, chash, {"nets": [n.cpu().state_dict() for n in nets]}, {
        "room_type": room_type, "net": net, "categories": list(cats), "preset": preset, "heldout_ids": held_ids, **data})
    frame = pd.DataFrame(history)
    summary = {"room_type": room_type, "net": net, "preset": pc["preset"], "device": device,
               "train_rooms": len(train_rooms), "heldout_rooms": len(held_rooms), "steps": int(frame["step"].iloc[-1]),
               "train_seconds": round(float(frame["seconds"].iloc[-1]), 1),
               "final_heldout_location_loss": round(float(frame["heldout_location_loss"].iloc[-1]), 4),
               "final_heldout_orientation_loss": round(float(frame["heldout_orientation_loss"].iloc[-1]), 4),
               **{k: round(float(frame[k].iloc[-1]), 4) for k in LOGLIK}}
    return Fitted(ckpt, frame, summary, _curve(frame, room_type, net))


def fit_from_tables(config: dict, room_type: str, net: str, data: RoomTypeRows, progress_file: Path,
                    threads: int = 1) -> Fitted:
    """:func:`fit_room_type` on one room type's final graph rows and rooms (the placement learners' signature)."""
    return fit_room_type(config, room_type, net, training_rooms(data), progress_file, threads)


def _ticker(room_type: str, net: str, preset: dict):
    bar = iter(progress(range(preset["steps"] // preset["log_every"] + 1), desc=f"train placement {room_type} ({net})"))

    def tick(step, row):
        next(bar, None)
        log.info("step %d: location %.3f (held-out %.3f), orientation %.3f (held-out %.3f)", step, row["location_loss"],
                 row["heldout_location_loss"], row["orientation_loss"], row["heldout_orientation_loss"])
    return tick


def _curve(history, room_type: str, net: str):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(12, 3.2))
    for ax, name in zip(axes, ("location", "orientation")):
        ax.plot(history["step"], history[f"{name}_loss"], label="train")
        ax.plot(history["step"], history[f"heldout_{name}_loss"], label="held-out")
        ax.set(xlabel="step", ylabel="loss", title=f"{name}, {room_type} ({net})")
        ax.legend()
    for k in LOGLIK:
        axes[2].plot(history["step"], history[k], label=k.replace("heldout_", "").replace("_loglik", ""))
    axes[2].set(xlabel="step", ylabel="nats per example", title="held-out log-likelihood of the true pose")
    axes[2].legend()
    fig.tight_layout()
    return fig
