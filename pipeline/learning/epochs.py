"""Epoch-based training with early stopping that resumes: the state a learner carries from epoch to epoch (the
epoch, the history, the best score and its weights, epochs without gain), loaded from and saved to its progress
file. Shared by the learners that train in epochs (PlanIT's graph model, the string VAE)."""
from __future__ import annotations

import copy
import logging
from pathlib import Path

import numpy as np

from . import checkpoint as ckpt

log = logging.getLogger("planit.learning")


def resume(model, opt, path: Path, kind: str, config_hash: str, device: str) -> dict:
    """The state to go on from: the progress file's (weights and optimiser loaded into ``model`` and ``opt``) when it
    is of these settings and ``kind``, else a fresh one."""
    saved = ckpt.resume(path, kind, config_hash, device)
    if saved is None:
        if Path(path).exists():
            log.info("checkpoint %s is for other settings: starting afresh", path)
        return {"epoch": 0, "history": [], "best": np.inf, "best_epoch": 0, "best_state": None, "stale": 0}
    model.load_state_dict(saved.state["model"])
    opt.load_state_dict(saved.state["optimizer"])
    log.info("resumed from %s after epoch %d", path, saved.record["epoch"])
    return {**saved.record, "best_state": saved.state["best_state"]}


def record(state: dict, model, opt, row: dict, score: float, gain: bool, path: Path, kind: str,
           config_hash: str) -> None:
    """Close an epoch: append ``row``, keep the weights when ``score`` is the best yet, count epochs without
    ``gain`` (a gain resets the count; None: the epoch does not count), save the progress file atomically."""
    state["history"].append(row)
    if gain is not None:
        state["stale"] = 0 if gain else state["stale"] + 1
    if gain is not None and score < state["best"]:
        state.update(best=score, best_epoch=row["epoch"], best_state=copy.deepcopy(model.state_dict()))
    state["epoch"] = row["epoch"]
    ckpt.save(path, ckpt.Checkpoint(kind, config_hash, {
        "model": model.state_dict(), "optimizer": opt.state_dict(), "best_state": state["best_state"]},
        {k: v for k, v in state.items() if k != "best_state"}))
