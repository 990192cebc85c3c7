"""Fit GRAINS's recursive VAE for one room type (rule ``train_placement``, net ``grains``): each kept room's
hierarchy (``hierarchy.build_tree``, from its objects and its final graph's support parents and hub roles), the fit
rooms' trees trained on, the validation rooms' choosing the epoch; the held-out rooms' loss scored once, after."""
from __future__ import annotations

import logging
from pathlib import Path

import pandas as pd
import torch

from ...config import config_hash
from ...learning import epochs
from ...learning.checkpoint import Checkpoint
from ...learning.device import pick_device
from ...learning.fitted import Fitted, epoch_figure
from ...log import progress
from ...room import RoomInput
from ..interface import RoomTypeRows
from . import train
from .hierarchy import Node, build_tree, leaves, to_dict, tree_depth

log = logging.getLogger("planit.grains")


def room_trees(node_df: pd.DataFrame, inputs: dict[str, RoomInput], ids: list[str], wall_gap: float) -> list[Node]:
    """The hierarchies of the rooms ``ids``, support parents and roles from the final graph rows."""
    objs = node_df[node_df["kind"].astype(str) == "object"]
    by_room = dict(tuple(objs.groupby("room_id", sort=False)))
    out = []
    for r in ids:
        g = by_room.get(r, objs.iloc[:0])
        parents = {n: p if isinstance(p, str) else None for n, p in zip(g["node_id"], g["parent_id"])}
        roles = {n: (str(role), grp if isinstance(grp, str) else None)
                 for n, role, grp in zip(g["node_id"], g["role"], g["group_id"])}
        out.append(build_tree(inputs[r], parents, roles, wall_gap))
    return out


def fit_grains(config: dict, room_type: str, net: str, data: RoomTypeRows, progress_file: Path,
               threads: int = 1) -> Fitted:
    """Train on the fit rooms' trees until the validation loss stops improving; resumes from ``progress_file``."""
    node_df, inputs, split = data.nodes, data.rooms, data.split
    gc = config["grains"]
    preset = gc["presets"][gc["preset"]]
    torch.set_num_threads(threads)
    ids = {s: sorted(r for r, p in split.items() if p == s and r in inputs) for s in ("fit", "validation", "heldout")}
    trees = {s: room_trees(node_df, inputs, ids[s], gc["wall_gap"]) for s in ids}
    labels = sorted({leaf.label for s in ("fit", "validation") for t in trees[s] for leaf in leaves(t)})
    device = pick_device(gc["device"])
    chash = config_hash({"preset": preset, "seed": config["seed"], "room_type": room_type, "split": ids,
                         "labels": labels, "wall_gap": gc["wall_gap"]})
    bar = iter(progress(range(preset["max_epochs"]), desc=f"GRAINS VAE {room_type} (max {preset['max_epochs']} epochs)"))
    run = train.train(trees["fit"], trees["validation"], labels, preset,
                      epochs.Session(config["seed"], progress_file, chash, device, lambda epoch, row: next(bar, None)))
    held = [t for t in trees["heldout"] if all(leaf.label in labels for leaf in leaves(t))]
    test = {k: round(v, 4) for k, v in train.score(run.model, held, preset).items()} if held else {}
    history = pd.DataFrame(run.history)
    ckpt = Checkpoint(train.KIND, chash, {"model": run.model.state_dict()}, {
        "room_type": room_type, "labels": labels, "preset": preset, "heldout": test,
        "example_tree": to_dict(trees["fit"][0]) if trees["fit"] else None})
    summary = {"room_type": room_type, "trees": {s: len(t) for s, t in trees.items()}, "labels": len(labels),
               "depth_max": max((tree_depth(t) for t in trees["fit"]), default=0), "device": device, "preset": preset,
               "epochs": int(len(history)), "best_epoch": int(run.best_epoch), "heldout": test,
               "train_seconds": round(float(history["seconds"].sum()), 1) if len(history) else 0.0,
               "resumed_from_epoch": run.resumed_from}
    log.info("GRAINS %s: %d fit trees, %d labels, best epoch %d, held-out loss %s", room_type, len(trees["fit"]),
             len(labels), run.best_epoch, test.get("total"))
    return Fitted(ckpt, history, summary, _curve(history, room_type))


def _curve(history: pd.DataFrame, room_type: str):
    return epoch_figure(history, [("train_loss", "train loss", "-"), ("validation_loss", "validation loss", "-"),
                                  ("train_kl", "train KL", ":")], f"GRAINS VAE, {room_type}", "loss per tree")
