"""Training GRAINS's recursive VAE on room hierarchies: Adam over mini-batches of trees (each batch encoded and
decoded in one pass, :mod:`.model`), the KL term weighted by ``kl_weight`` (0.1 in the released code), gradients
clipped to norm ``clip`` (optional in the preset, default :data:`CLIP`; 0: none; without it training on a few
hundred rooms diverged after some dozens of epochs at lr 1e-3). Every epoch shuffles the fit trees with a
generator drawn from ``(seed, epoch)`` and draws the codes' noise from ``(seed, epoch)`` too, so a resumed run
continues exactly as an uninterrupted one. The validation loss (the same total,
decoded from the codes' means) decides early stopping after ``patience`` epochs without gain; the weights of its
best epoch are kept. The progress file (:mod:`pipeline.learning.epochs`, written atomically after every epoch)
carries the config hash: the same hash resumes, another starts over."""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from ...learning import epochs
from .hierarchy import Node
from .model import GrainsVAE, Sizes

log = logging.getLogger("planit.grains")
KIND, PROGRESS = "grains_vae", "grains_vae.progress"
CLIP = 1.0  # gradient norm clip when the preset names none


@dataclass
class Run:
    model: GrainsVAE
    history: list[dict]
    best_epoch: int
    resumed_from: int


def build_model(labels: list[str], preset: dict) -> GrainsVAE:
    """A fresh VAE of the preset's sizes (``scale``, m, optional: 2)."""
    sizes = Sizes(preset["feature"], preset["hidden"], preset["root_feature"], preset["root_hidden"])
    return GrainsVAE(labels, sizes, preset.get("scale", 2.0))


def _epoch(model: GrainsVAE, opt, trees: list[Node], preset: dict, seed: int, epoch: int) -> tuple[float, float]:
    """One pass over ``trees`` in shuffled mini-batches; the mean total loss and KL per tree."""
    order = np.random.default_rng([seed, epoch]).permutation(len(trees))
    gen = torch.Generator().manual_seed(int(seed) * 100_003 + epoch)
    total = kl = 0.0
    model.train()
    for k in range(0, len(order), preset["batch_size"]):
        batch = [trees[i] for i in order[k:k + preset["batch_size"]]]
        parts = model.loss(batch, preset["kl_weight"], gen)
        opt.zero_grad()
        parts["total"].backward()
        if preset.get("clip", CLIP):
            torch.nn.utils.clip_grad_norm_(model.parameters(), preset.get("clip", CLIP))
        opt.step()
        total, kl = total + float(parts["total"].detach()) * len(batch), kl + float(parts["kl"].detach()) * len(batch)
    return total / max(len(trees), 1), kl / max(len(trees), 1)


def score(model: GrainsVAE, trees: list[Node], preset: dict) -> dict[str, float]:
    """Mean per-tree losses (``total``, ``recon``, ``kind``, ``label``, ``kl``) of ``trees``, each decoded from its
    code's mean."""
    model.eval()
    sums: dict[str, float] = {}
    with torch.no_grad():
        for k in range(0, len(trees), preset["batch_size"]):
            batch = trees[k:k + preset["batch_size"]]
            for name, value in model.loss(batch, preset["kl_weight"], sample=False).items():
                sums[name] = sums.get(name, 0.0) + float(value) * len(batch)
    return {name: value / max(len(trees), 1) for name, value in sums.items()}


def train(fit: list[Node], val: list[Node], labels: list[str], preset: dict, seed: int, progress_file: Path,
          chash: str, device: str = "cpu", tick=None) -> Run:
    """Fit the VAE on the ``fit`` trees, stopping early on the ``val`` trees' loss (the fit trees' when there are
    none); ``tick(epoch, row)`` is called after every epoch. See the module docstring."""
    torch.manual_seed(seed)
    model = build_model(labels, preset).to(device)
    opt = torch.optim.Adam(model.parameters(), lr=preset["lr"])
    state = epochs.resume(model, opt, progress_file, PROGRESS, chash, device)
    resumed, held_out = state["epoch"], val or fit
    while state["epoch"] < preset["max_epochs"] and state["stale"] < preset["patience"]:
        epoch = state["epoch"] + 1
        start = time.perf_counter()
        loss, kl = _epoch(model, opt, fit, preset, seed, epoch)
        seconds = time.perf_counter() - start
        validation = score(model, held_out, preset)["total"]
        row = {"epoch": epoch, "train_loss": loss, "train_kl": kl, "validation_loss": validation,
               "seconds": seconds, "trees_per_s": len(fit) / max(seconds, 1e-9)}
        epochs.record(state, model, opt, row, validation, validation < state["best"], progress_file, PROGRESS, chash)
        log.info("epoch %d: loss %.4f (kl %.4f), validation %.4f, %.1f trees/s", epoch, loss, kl, validation,
                 row["trees_per_s"])
        if tick:
            tick(epoch, row)
    if state["best_state"] is not None:
        model.load_state_dict(state["best_state"])
    return Run(model, state["history"], state["best_epoch"] or state["epoch"], resumed)
