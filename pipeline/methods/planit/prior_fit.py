"""Learn the relative-pose prior (``placement/prior.py``) of one room type from the fit split's rooms and their final
graphs (the rule ``train_placement`` with ``net=prior``): seconds, no training loop. The checkpoint's record holds
the densities; its figure shows the relative positions of the most frequent triples."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd

from ...config import config_hash
from ...errors import InputError
from ...learning.checkpoint import Checkpoint
from ...learning.fitted import Fitted
from ...placement.prior import KIND, learn_prior
from ..interface import RoomTypeRows
from .nets.data import training_room


def fit_prior(config: dict, room_type: str, net: str, data: RoomTypeRows, progress_file: Path,
              threads: int = 1) -> Fitted:
    """The prior of ``room_type`` from its fit rooms (room id -> RoomInput ``inputs``) and final graph rows."""
    node_df, edge_df, inputs, split = data.nodes, data.edges, data.rooms, data.split
    cfg = config["placement"]["prior"]
    ids = sorted(i for i in node_df["room_id"].unique() if split.get(i) == "fit" and i in inputs)
    if not ids:
        raise InputError(f"room type '{room_type}' has no fit room to learn the pose prior from")
    start = time.perf_counter()
    by_n, by_e = dict(tuple(node_df.groupby("room_id"))), dict(tuple(edge_df.groupby("room_id")))
    rooms = [training_room(inputs[i], by_n[i], by_e.get(i, edge_df.iloc[:0])) for i in ids]
    record = learn_prior([(t.room, t.edges) for t in rooms], cfg)
    seconds = time.perf_counter() - start
    samples = sum(len(t["poses"]) for t in record["triples"])
    chash = config_hash({"prior": cfg, "room_type": room_type, "rooms": ids})
    summary = {"room_type": room_type, "net": net, "fit_rooms": len(ids), "triples": len(record["triples"]),
               "samples": samples, "train_seconds": round(seconds, 2)}
    history = pd.DataFrame([{"step": 1, "triples": summary["triples"], "samples": samples, "seconds": seconds}])
    return Fitted(Checkpoint(KIND, chash, {}, {"room_type": room_type, **record}), history, summary,
                  _figure(record, room_type))


def _figure(record: dict, room_type: str, count: int = 6):
    """Relative positions of the ``count`` triples with the most samples."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    top = sorted(record["triples"], key=lambda t: -len(t["poses"]))[:count]
    fig, axes = plt.subplots(1, max(len(top), 1), figsize=(2.6 * max(len(top), 1), 2.8), squeeze=False)
    for ax, t in zip(axes[0], top):
        p = np.array(t["poses"])
        ax.scatter(p[:, 0], p[:, 1], s=4, c=np.cos(p[:, 2]), cmap="coolwarm", vmin=-1, vmax=1)
        ax.scatter([0], [0], marker="+", c="k")
        ax.set_title(f"{t['anchor']} -{t['edge']}{' (rev)' if t['reverse'] else ''}-> {t['target']}", fontsize=7)
        ax.set_aspect("equal")
    fig.suptitle(f"relative-pose prior, {room_type}: target centres in the anchor's frame (colour: cos turn)", fontsize=8)
    fig.tight_layout()
    return fig
