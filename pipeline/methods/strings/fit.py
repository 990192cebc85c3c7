"""Fit the sequence VAE of one room type's strings on its fit rooms (validation rooms choose the epoch; the held-out
rooms are scored once, after training)."""
from __future__ import annotations

import logging
from pathlib import Path

import pandas as pd
import torch

from ...config import config_hash
from ...graphs.data import Graph, Vocab
from ...graphs.files import split_graphs
from ...learning import epochs
from ...learning.checkpoint import Checkpoint
from ...learning.device import pick_device
from ...learning.fitted import Fitted, epoch_figure
from ...log import progress
from ...seeding import rng_for
from . import train
from .serialize import arch_prefix, string_graph
from .vocab import learn_vocab

log = logging.getLogger("planit.strings")


def rooms_of(graphs: list[Graph], vocab: Vocab) -> list[train.Room]:
    return [(string_graph(g, vocab), g.n_arch) for g in graphs]


def token_vocab(fit: list[train.Room], every: list[train.Room], seed: int, preset: dict):
    """The tokens of the fit rooms' strings (several orders each), of every room's architecture prefix (the
    architectures a string is conditioned on: held-out rooms' included, their objects not) and a reference to each
    architecture atom."""
    rng = rng_for(seed, "strings-vocab")
    most = max(n for _, n in every)
    texts = train.room_strings(fit, rng, 4 * preset["strings_per_room"]) + train.room_strings(fit, None)
    return learn_vocab([t for t, _ in texts] + [arch_prefix(g, n)[0] for g, n in every] + [f"@{k}" for k in range(most)])


def fit_room_type(config: dict, vocab: Vocab, graphs: list[Graph], split: dict[str, str], room_type: str,
                  progress_file: Path, threads: int = 1) -> Fitted:
    """Train on the ``fit`` rooms' strings until the ``validation`` ELBO stops improving; ``progress_file`` resumes
    an interrupted run with the same settings."""
    sc = config["strings"]
    preset = sc["presets"][sc["preset"]]
    torch.set_num_threads(threads)
    parts = split_graphs(graphs, split, room_type)
    ids = {s: [g.room_id for g in gs] for s, gs in parts.items()}
    fit, val, held = (rooms_of(parts[s], vocab) for s in ("fit", "validation", "heldout"))
    tokens = token_vocab(fit, rooms_of(graphs, vocab), config["seed"], preset)
    device = pick_device(sc["device"])
    chash = config_hash({"preset": preset, "seed": config["seed"], "room_type": room_type, "split": ids,
                         "tokens": tokens.tokens})
    bar = iter(progress(range(preset["max_epochs"]), desc=f"strings VAE {room_type} (max {preset['max_epochs']} epochs)"))

    def tick(epoch, row):
        next(bar, None)
        log.info("epoch %d: beta %.2f, train NLL %.2f KL %.2f, validation ELBO %.2f, %.0f strings/s", epoch,
                 row["beta"], row["train_nll"], row["train_kl"], row["validation_elbo"], row["strings_per_s"])

    run_ = train.train(fit, val, tokens, preset, epochs.Session(config["seed"], progress_file, chash, device, tick))
    test = {k: round(v, 4) for k, v in train.score(run_.model, train.room_strings(held, None), tokens, preset,
                                                   device).items()}
    log.info("held-out ELBO of the chosen epoch (%d): %.2f per string", run_.best_epoch, test["elbo"])
    ckpt = Checkpoint(train.KIND, chash, {"model": run_.model.state_dict()}, {
        "room_type": room_type, "categories": list(vocab.categories), "tokens": list(tokens.tokens), "preset": preset,
        "train_ids": ids["fit"], "validation_ids": ids["validation"], "heldout_ids": ids["heldout"],
        "heldout_nll": {"per_graph": test["elbo"], **test}})
    history = pd.DataFrame(run_.history)
    summary = {"room_type": room_type, "train_graphs": len(fit), "validation_graphs": len(val),
               "heldout_graphs": len(held), "device": device, "preset": preset, "tokens": len(tokens),
               "epochs": int(len(history)), "best_epoch": int(run_.best_epoch), "heldout": test,
               "train_seconds": round(float(history["seconds"].sum()), 1),
               "strings_per_s": round(float(history["strings_per_s"].median()), 1), "resumed_from_epoch": run_.resumed_from}
    return Fitted(ckpt, history, summary, _curve(history, room_type))


def _curve(history: pd.DataFrame, room_type: str):
    return epoch_figure(history, [(history["train_nll"] + history["train_kl"], "train NLL + KL", "-"),
                                  ("validation_elbo", "validation ELBO (KL weight 1)", "-"),
                                  ("validation_kl", "validation KL", ":")], f"strings VAE, {room_type}", "nats per string")
