"""Epoch-based training with early stopping that resumes: the loop every learner that trains in epochs shares
(PlanIT's graph model, the string VAE and its tagger, GRAINS), the state it carries from epoch to epoch (the epoch,
the history, the best score and its weights, epochs without gain), loaded from and saved to its progress file."""
from __future__ import annotations

import copy
import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from . import checkpoint as ckpt

log = logging.getLogger("planit.learning")


@dataclass(frozen=True)
class Session:
    """Where and how a learner trains: its ``seed``, its progress file (resumed when it holds the settings of
    ``config_hash``), the ``device`` and ``tick(epoch, row)``, called after every epoch (or logged step)."""
    seed: int
    progress_file: Path
    config_hash: str
    device: str = "cpu"
    tick: Callable[[int, dict], Any] | None = None


@dataclass
class Run:
    """What training returns: the model with its best epoch's weights, the history (one row per epoch), the best
    epoch and the epoch it resumed after (0: a fresh start)."""
    model: Any
    history: list[dict]
    best_epoch: int
    resumed_from: int


Epoch = Callable[[int, float], tuple[dict, float, bool | None]]  # (epoch, best score) -> (row, score, gain)


def fit(model, opt, session: Session, kind: str, preset: dict, epoch: Epoch) -> Run:
    """Run ``epoch`` until ``preset['max_epochs']`` or ``preset['patience']`` epochs without gain, going on from the
    session's progress file (of checkpoint ``kind``); keep the weights of the lowest score. ``epoch(n, best)``
    trains epoch ``n`` and returns its history row, its score (lower is better) and whether it gains on ``best``
    (None: it does not count)."""
    state = resume(model, opt, session, kind)
    resumed = state["epoch"]
    while state["epoch"] < preset["max_epochs"] and state["stale"] < preset["patience"]:
        n = state["epoch"] + 1
        row, score, gain = epoch(n, state["best"])
        record(state, (model, opt), row, score, gain, session, kind)
        if session.tick:
            session.tick(n, row)
    if state["best_state"] is not None:
        model.load_state_dict(state["best_state"])
    return Run(model, state["history"], state["best_epoch"] or state["epoch"], resumed)


def resume(model, opt, session: Session, kind: str) -> dict:
    """The state to go on from: the progress file's (weights and optimiser loaded into ``model`` and ``opt``) when it
    is of the session's settings and ``kind``, else a fresh one."""
    saved = ckpt.resume(session.progress_file, kind, session.config_hash, session.device)
    if saved is None:
        if Path(session.progress_file).exists():
            log.info("checkpoint %s is for other settings: starting afresh", session.progress_file)
        return {"epoch": 0, "history": [], "best": np.inf, "best_epoch": 0, "best_state": None, "stale": 0}
    model.load_state_dict(saved.state["model"])
    opt.load_state_dict(saved.state["optimizer"])
    log.info("resumed from %s after epoch %d", session.progress_file, saved.record["epoch"])
    return {**saved.record, "best_state": saved.state["best_state"]}


def record(state: dict, learner: tuple, row: dict, score: float, gain: bool | None, session: Session,
           kind: str) -> None:
    """Close an epoch of ``learner`` (model, optimiser): append ``row``, keep the weights when ``score`` is the best
    yet, count epochs without ``gain`` (a gain resets the count; None: the epoch does not count), save the progress
    file atomically."""
    model, opt = learner
    state["history"].append(row)
    if gain is not None:
        state["stale"] = 0 if gain else state["stale"] + 1
    if gain is not None and score < state["best"]:
        state.update(best=score, best_epoch=row["epoch"], best_state=copy.deepcopy(model.state_dict()))
    state["epoch"] = row["epoch"]
    ckpt.save(session.progress_file, ckpt.Checkpoint(kind, session.config_hash, {
        "model": model.state_dict(), "optimizer": opt.state_dict(), "best_state": state["best_state"]},
        {k: v for k, v in state.items() if k != "best_state"}))
