"""Learn the string method's instantiation for one room type (rule ``train_placement``, net ``tagger``): the
relative-pose clusters of the fit rooms' edges (:mod:`.poses`) and the edge tagger (:mod:`.tagger`) on the fit rooms'
strings, validation rooms choosing the epoch; the held-out rooms' tagging accuracy is measured once, after."""
from __future__ import annotations

import logging
from pathlib import Path

import pandas as pd
import torch

from ...config import config_hash
from ...errors import InputError
from ...graphs.data import Graph, Vocab, graphs_from_tables, vocab_of
from ...graphs.files import split_graphs
from ...learning import epochs
from ...learning.checkpoint import Checkpoint
from ...learning.device import pick_device
from ...learning.fitted import Fitted, epoch_figure
from ...log import progress
from ...placement.layout import walls_of
from ...seeding import rng_for
from ..interface import RoomTypeRows
from . import tagger
from .poses import Clusters, EdgePose, edge_poses, fit_clusters
from .serialize import arch_prefix, room_string, string_graph
from .vocab import learn_vocab

log = logging.getLogger("planit.strings")


def tagger_room(g: Graph, vocab: Vocab, poses: list[EdgePose], clusters: Clusters) -> tagger.Room:
    """A room for the tagger: its string graph, each posed edge's triple and nearest cluster."""
    keyed = {(p.source, p.target, p.edge_class): p for p in poses}
    labels = {e: clusters.label(p.triple, p.pose) for e, p in keyed.items()}
    return tagger.Room(string_graph(g, vocab), g.n_arch, {e: p.triple for e, p in keyed.items()},
                       {e: y for e, y in labels.items() if y is not None})


def token_vocab(fit: list[tagger.Room], every: list[tagger.Room], seed: int, per_room: int):
    """The tokens of several strings of every fit room and of every room's architecture prefix."""
    rng = rng_for(seed, "tagger-vocab")
    texts = [room_string(r.graph, r.n_arch, rng)[0] for r in fit for _ in range(per_room)]
    return learn_vocab(texts + [arch_prefix(r.graph, r.n_arch)[0] for r in every] +
                       [f"@{k}" for k in range(max((r.n_arch for r in every), default=1))])


def fit_tagger(config: dict, room_type: str, net: str, data: RoomTypeRows, progress_file: Path,
               threads: int = 1) -> Fitted:
    """Cluster the fit rooms' relative poses, train the tagger, score it on the held-out rooms."""
    node_df, edge_df, inputs, split = data.nodes, data.edges, data.rooms, data.split
    tc = config["strings"]["tagger"]
    preset = tc["presets"][tc["preset"]]
    torch.set_num_threads(threads)
    vocab = vocab_of(node_df)
    graphs = [g for g in graphs_from_tables(node_df, edge_df, vocab) if g.room_id in inputs]
    parts = split_graphs(graphs, split, room_type)
    if not parts["fit"]:
        raise InputError(f"room type '{room_type}' has no fit room with geometry for the edge tagger")
    poses = {g.room_id: edge_poses(g, vocab, inputs[g.room_id], walls_of(inputs[g.room_id])) for g in graphs}
    clusters = fit_clusters([p for g in parts["fit"] for p in poses[g.room_id]], tc["bandwidth"])
    rooms = {s: [tagger_room(g, vocab, poses[g.room_id], clusters) for g in gs] for s, gs in parts.items()}
    tokens = token_vocab(rooms["fit"], [r for rs in rooms.values() for r in rs], config["seed"], preset["strings_per_room"])
    ids = {s: [g.room_id for g in gs] for s, gs in parts.items()}
    chash = config_hash({"preset": preset, "bandwidth": tc["bandwidth"], "seed": config["seed"], "room_type": room_type,
                         "split": ids, "tokens": tokens.tokens})
    bar = iter(progress(range(preset["max_epochs"]), desc=f"edge tagger {room_type} (max {preset['max_epochs']} epochs)"))

    def tick(epoch, row):
        next(bar, None)
        log.info("epoch %d: loss %.3f, validation accuracy %.3f (%.3f where a triple has several clusters)", epoch,
                 row["train_loss"], row["validation_accuracy"], row["validation_accuracy_with_choice"])

    session = epochs.Session(config["seed"], progress_file, chash, pick_device(tc["device"]), tick)
    model, history, best = tagger.train(rooms["fit"], rooms["validation"], clusters, tokens, preset, session)
    held = {k: round(v, 4) for k, v in tagger.accuracy(model, rooms["heldout"], clusters, tokens, preset["votes"],
                                                       config["seed"]).items()}
    log.info("%s: held-out tagging accuracy %.3f over %d edges (%.3f over the %d with a choice; majority cluster %.3f)",
             room_type, held["accuracy"], held["edges"], held["accuracy_with_choice"], held["edges_with_choice"],
             held["majority_with_choice"])
    record = {"room_type": room_type, "categories": list(vocab.categories), "tokens": list(tokens.tokens),
              "preset": preset, "clusters": clusters.to_record(), "heldout_accuracy": held, **{f"{s}_ids": v for s, v in ids.items()}}
    frame = pd.DataFrame(history)
    summary = {"room_type": room_type, "net": net, "triples": len(clusters.centres), "clusters": clusters.size,
               "triples_with_choice": int(sum(len(c) > 1 for c in clusters.centres.values())),
               "fit_edges": int(sum(len(r.labels) for r in rooms["fit"])), "epochs": int(len(frame)),
               "best_epoch": int(best), "heldout": held, "preset": preset,
               "train_seconds": round(float(frame["seconds"].sum()) if len(frame) else 0.0, 1)}
    return Fitted(Checkpoint(tagger.KIND, chash, {"model": model.state_dict()}, record), frame, summary,
                  _curve(frame, room_type))


def _curve(history: pd.DataFrame, room_type: str):
    return epoch_figure(history, [("train_loss", "train cross-entropy per edge", "-"),
                                  ("validation_accuracy", "validation accuracy (voted)", "-"),
                                  ("validation_accuracy_with_choice", "validation accuracy, triples with a choice", ":")],
                        f"edge tagger, {room_type}")
