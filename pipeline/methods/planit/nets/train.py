"""Training the location and orientation networks together, one batch of fresh examples per step.

Batches come from ``(seed, step)`` alone, so a run resumed from its checkpoint (written atomically every
``checkpoint_every`` steps, carrying the config hash) continues exactly as an uninterrupted one. Every
``log_every`` steps the losses and the log-likelihood of the true pose (location pixel and yaw bins, nats per
example) on a fixed set of held-out examples (``heldout_examples``) are logged.
"""
from __future__ import annotations

import logging
import time

import numpy as np
import torch

from ....learning import checkpoint as ckpt
from ....learning.epochs import Session
from ....placement.layout import View
from .data import TrainingRoom, batch
from .model import LocationNet, OrientationNet, bin_loglik, location_loglik, location_loss, orientation_loss

KIND, PROGRESS = "placement_nets", "placement_nets.progress"  # checkpoint kinds
log = logging.getLogger("planit.placement")


def views(preset: dict, categories: tuple[str, ...]) -> tuple[View, View]:
    return (View(preset["size"], preset["mpp"], categories), View(preset["crop_size"], preset["crop_mpp"], categories))


def build(preset: dict, categories: tuple[str, ...], film: bool) -> tuple[LocationNet, OrientationNet]:
    loc_view, ori_view = views(preset, categories)
    return (LocationNet(loc_view.channels, len(categories), preset["widths"], preset["blocks"], film),
            OrientationNet(ori_view.channels, len(categories), preset["bins"], preset["crop_widths"], film))


def _tensors(b: dict, device: str) -> dict:
    return {k: torch.as_tensor(v, device=device) for k, v in b.items()}


def _losses(nets, b: dict, weight: float) -> tuple[torch.Tensor, torch.Tensor]:
    loc, ori = nets
    return (location_loss(loc(b["loc"], b["cond"]), b["cat"], b["row"], b["col"], weight),
            orientation_loss(ori(b["ori"], b["cond"], b["rel"]), b["cat"], b["bins"], b["snap"]))


def pose_loglik(nets, b: dict) -> dict:
    """Mean log-likelihood (nats per example) of the true location pixel and of the true yaw's bins under the
    networks, on batch ``b``."""
    loc, ori = nets
    with torch.no_grad():
        where = location_loglik(loc(b["loc"], b["cond"]), b["cat"], b["row"], b["col"])
        own = ori(b["ori"], b["cond"], b["rel"])[torch.arange(len(b["cat"])), b["cat"]]
        turn = bin_loglik(own[:, :-1], b["bins"])
    return {"heldout_location_loglik": float(where.mean()), "heldout_orientation_loglik": float(turn.mean()),
            "heldout_pose_loglik": float((where + turn).mean())}


def train(rooms: list[TrainingRoom], held: list[TrainingRoom], categories: tuple[str, ...], preset: dict, film: bool,
          session: Session, data: dict | None = None):
    """Train for ``preset['steps']`` steps; returns the two networks (eval mode) and the history rows (the session's
    ``tick(step, row)`` after each). ``data``: ``snap_angle`` (deg) and ``none_share`` of the examples
    (:func:`~.data.batch`)."""
    torch.manual_seed(session.seed)
    nets = [n.to(session.device) for n in build(preset, categories, film)]
    opt = torch.optim.Adam([p for n in nets for p in n.parameters()], lr=preset["lr"])
    loc_view, ori_view = views(preset, categories)
    cfg = {"bins": preset["bins"], **(data or {"snap_angle": 5.0, "none_share": 0.1})}
    draw = lambda pool, s, step, n: _tensors(batch(pool, s, step, n, loc_view, ori_view, cfg), session.device)
    fixed = draw(held or rooms, session.seed + 1, 0, preset["heldout_examples"])
    state = _resume(nets, opt, session)
    start, window = time.perf_counter(), []
    while state["step"] < preset["steps"]:
        state["step"] += 1
        for n in nets:
            n.train()
        loc_l, ori_l = _losses(nets, draw(rooms, session.seed, state["step"], preset["batch_size"]), preset["loss_weight"])
        opt.zero_grad()
        (loc_l + ori_l).backward()
        opt.step()
        window.append((loc_l.item(), ori_l.item()))
        if state["step"] % preset["log_every"] == 0 or state["step"] == preset["steps"]:
            state["history"].append(_row(nets, fixed, preset, state["step"], window, time.perf_counter() - start))
            window = []
            if session.tick:
                session.tick(state["step"], state["history"][-1])
        if state["step"] % preset["checkpoint_every"] == 0 or state["step"] == preset["steps"]:
            ckpt.save(session.progress_file, ckpt.Checkpoint(PROGRESS, session.config_hash, {
                "nets": [n.state_dict() for n in nets], "optimizer": opt.state_dict()}, state))
    for n in nets:
        n.eval()
    return nets, state["history"]


def _resume(nets, opt, session: Session) -> dict:
    """The step and history to go on from: the progress file's (weights and optimiser loaded) when it holds the
    session's settings, else a fresh start."""
    saved = ckpt.resume(session.progress_file, PROGRESS, session.config_hash, session.device)
    if saved is None:
        return {"step": 0, "history": []}
    for n, sd in zip(nets, saved.state["nets"]):
        n.load_state_dict(sd)
    opt.load_state_dict(saved.state["optimizer"])
    log.info("resumed from %s after step %d", session.progress_file, saved.record["step"])
    return saved.record


def _row(nets, fixed: dict, preset: dict, step: int, window: list[tuple[float, float]], seconds: float) -> dict:
    """A history row: the mean training losses since the last row and the held-out losses and log-likelihoods."""
    for n in nets:
        n.eval()
    with torch.no_grad():
        h_loc, h_ori = _losses(nets, fixed, preset["loss_weight"])
    return {"step": step, "location_loss": float(np.mean([w[0] for w in window])),
            "orientation_loss": float(np.mean([w[1] for w in window])), "heldout_location_loss": float(h_loc),
            "heldout_orientation_loss": float(h_ori), **pose_loglik(nets, fixed), "seconds": seconds}
