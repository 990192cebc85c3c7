"""Training GRAINS's recursive VAE on room hierarchies: Adam over mini-batches of trees (each batch encoded and
decoded in one pass, :mod:`.model`), the KL term weighted by ``kl_weight`` (0.1 in the released code), gradients
clipped to norm ``clip`` (optional in the preset, default :data:`CLIP`; 0: none; without it training on a few
hundred rooms diverged after some dozens of epochs at lr 1e-3). Every epoch shuffles the fit trees with a
generator drawn from ``(seed, epoch)`` and draws the codes' noise from ``(seed, epoch)`` too, so a resumed run
continues exactly as an uninterrupted one. The validation loss (the same total,
decoded from the codes' means) decides early stopping after ``patience`` epochs without gain; the weights of its
best epoch are kept. The progress file (:mod:`pipeline.learning.epochs`, written atomically after every epoch)
carries the config hash: the same hash resumes, another starts over.

What picks the kept epoch is the preset's ``select``: ``loss`` (the validation loss above, checked every epoch) or
``samples``: every ``select_every`` epochs, ``select_samples`` trees decoded from the prior (a fixed noise) and the
category KL of their leaves against the validation trees' (:func:`pipeline.evaluation.distributions.category_kl`,
the evaluation's measure), lowest kept. On the default sizes the validation loss rises after about 60-120 epochs
(the codes fit the training trees) while the prior's samples keep getting closer to the validation rooms (kitchens:
category KL 1.2 at the loss's best epoch, 0.12 after 150), so the loss is the wrong judge of what is sampled.
``patience`` counts epochs since the last gain in either case."""
from __future__ import annotations

import logging
import time

import torch

from ...evaluation.distributions import category_kl
from ...learning import epochs
from ...seeding import rng_for
from .hierarchy import Node, leaves
from .model import GrainsVAE, Sizes

log = logging.getLogger("planit.grains")
KIND, PROGRESS = "grains_vae", "grains_vae.progress"
CLIP = 1.0  # gradient norm clip when the preset names none


Run = epochs.Run


def build_model(labels: list[str], preset: dict) -> GrainsVAE:
    """A fresh VAE of the preset's sizes (``scale``, m, optional: 2)."""
    sizes = Sizes(preset["feature"], preset["hidden"], preset["root_feature"], preset["root_hidden"])
    return GrainsVAE(labels, sizes, preset.get("scale", 2.0))


def _epoch(model: GrainsVAE, opt, trees: list[Node], preset: dict, seed: int, epoch: int) -> tuple[float, float]:
    """One pass over ``trees`` in shuffled mini-batches; the mean total loss and KL per tree."""
    order = rng_for(seed, epoch).permutation(len(trees))
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


def sample_kl(model: GrainsVAE, trees: list[Node], preset: dict, seed: int) -> float:
    """Category KL of the leaves of ``select_samples`` trees decoded from the prior (noise from ``seed``) against
    the leaves of ``trees`` (:mod:`pipeline.evaluation.distributions`)."""
    was = model.training
    model.eval()
    gen = torch.Generator().manual_seed(int(seed))
    with torch.no_grad():
        drawn = model.decode(torch.randn(preset["select_samples"], model.sizes.root_feature, generator=gen))
    model.train(was)
    return category_kl([leaf.label for t in trees for leaf in leaves(t)], [leaf.label for t in drawn for leaf in leaves(t)])


def judge(model: GrainsVAE, held_out: list[Node], preset: dict, seed: int, epoch: int, row: dict) -> tuple[float, bool | None]:
    """The epoch's selection score and whether it is checked (``select``: module docstring); adds ``sample_kl``
    to ``row`` on a checked epoch of ``samples``."""
    if preset.get("select", "loss") == "loss":
        return row["validation_loss"], True
    if epoch % preset["select_every"]:
        return float("inf"), False
    row["sample_kl"] = sample_kl(model, held_out, preset, seed)
    return row["sample_kl"], True


def train(fit: list[Node], val: list[Node], labels: list[str], preset: dict, session: epochs.Session) -> Run:
    """Fit the VAE on the ``fit`` trees, stopping early on the ``val`` trees' loss (the fit trees' when there are
    none; :func:`~pipeline.learning.epochs.fit`). See the module docstring."""
    torch.manual_seed(session.seed)
    model = build_model(labels, preset).to(session.device)
    opt = torch.optim.Adam(model.parameters(), lr=preset["lr"])
    held_out = val or fit

    def epoch(n: int, best: float) -> tuple[dict, float, bool]:
        start = time.perf_counter()
        loss, kl = _epoch(model, opt, fit, preset, session.seed, n)
        seconds = time.perf_counter() - start
        validation = score(model, held_out, preset)["total"]
        row = {"epoch": n, "train_loss": loss, "train_kl": kl, "validation_loss": validation,
               "seconds": seconds, "trees_per_s": len(fit) / max(seconds, 1e-9)}
        judged, checked = judge(model, held_out, preset, session.seed, n, row)
        log.info("epoch %d: loss %.4f (kl %.4f), validation %.4f, %.1f trees/s", n, loss, kl, validation,
                 row["trees_per_s"])
        return row, judged, checked and judged < best

    return epochs.fit(model, opt, session, PROGRESS, preset, epoch)
