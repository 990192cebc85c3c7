"""Training the sequence VAE on room strings: each epoch draws new random depth-first strings of every fit room from
``(seed, epoch)`` alone (several per room, as the paper trains on several strings per shape), so a resumed run
continues exactly as an uninterrupted one. Batched, Adam, word dropout (Bowman et al.), free bits per latent
dimension (``free_bits``), the KL weight annealed linearly from 0 to 1 over ``kl_anneal`` epochs; once annealed,
training stops when the validation ELBO (fixed strings, full KL weight) has not improved for ``patience`` epochs;
the epoch of the best validation ELBO is kept. The progress file (written atomically after every epoch) carries the
config hash."""
from __future__ import annotations

import logging
import time

import numpy as np
import torch

from ...learning import epochs
from ...seeding import rng_for
from .model import SeqVAE, kl_objective, losses
from .serialize import StringGraph, arch_prefix, serialize_room, tokens
from .vocab import UNK, TokenVocab

log = logging.getLogger("planit.strings")
KIND, PROGRESS = "strings_vae", "strings_vae.progress"
Room = tuple[StringGraph, int]  # a room's graph as strings see it, and its architecture node count
Text = tuple[str, int]  # a room string and its forced tokens (the architecture's prefix and ".")


Run = epochs.Run


def build_model(vocab: TokenVocab, preset: dict) -> SeqVAE:
    return SeqVAE(len(vocab), preset["embed"], preset["hidden"], preset["latent"], preset["layers"])


def room_strings(rooms: list[Room], rng: np.random.Generator | None, per_room: int = 1) -> list[Text]:
    """``per_room`` strings of every room (random object orders with ``rng``; the one canonical string without),
    each with its forced tokens: the architecture's prefix and the ``.`` after it."""
    out = []
    for g, n in rooms:
        forced = len(tokens(arch_prefix(g, n)[0])) + 1
        out += [(serialize_room(g, n, rng), forced) for _ in range(per_room if rng is not None else 1)]
    return out


def _tensors(batch: list[Text], vocab: TokenVocab, preset: dict, device: str):
    """Token rows ``(B, T)``, their lengths ``(B,)`` and forced token counts ``(B,)``."""
    x = torch.from_numpy(vocab.encode([t for t, _ in batch], preset["max_length"])).to(device)
    return x, (x != 0).sum(1), torch.tensor([f for _, f in batch], device=device)


def _word_dropout(x: torch.Tensor, vocab: TokenVocab, rate: float, gen: torch.Generator) -> torch.Tensor:
    """The decoder's inputs ``x[:, :-1]`` with each token after ``<bos>`` replaced by ``<unk>`` at ``rate``."""
    inputs = x[:, :-1].clone()
    drop = (torch.rand(inputs.shape, generator=gen) < rate).to(x.device) & (inputs != 0)
    drop[:, 0] = False
    return inputs.masked_fill(drop, vocab.index[UNK])


def _epoch(learner: tuple, strings: list[Text], vocab: TokenVocab, preset: dict, beta: float, session: epochs.Session,
           epoch: int) -> tuple[float, float]:
    """One pass of ``learner`` (model, optimiser) over ``strings`` in random batches; the mean reconstruction NLL and
    KL per string."""
    model, opt = learner
    gen = torch.Generator().manual_seed(int(session.seed) * 100_003 + epoch)
    order = torch.randperm(len(strings), generator=gen).tolist()
    nll_sum = kl_sum = 0.0
    for k in range(0, len(order), preset["batch_size"]):
        x, lengths, forced = _tensors([strings[i] for i in order[k:k + preset["batch_size"]]], vocab, preset, session.device)
        noise = torch.randn(len(x), preset["latent"], generator=gen)
        logits, mu, logvar = model(x, lengths, _word_dropout(x, vocab, preset["word_dropout"], gen), noise)
        nll, kl = losses(logits, x, mu, logvar, forced)
        opt.zero_grad()
        (nll.mean() + beta * kl_objective(mu, logvar, preset["free_bits"])).backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), preset["clip"])
        opt.step()
        nll_sum, kl_sum = nll_sum + float(nll.detach().sum()), kl_sum + float(kl.detach().sum())
    return nll_sum / max(len(strings), 1), kl_sum / max(len(strings), 1)


def score(model: SeqVAE, strings: list[Text], vocab: TokenVocab, preset: dict, device: str) -> dict:
    """Mean reconstruction NLL (of the tokens after the forced prefix), KL and ELBO (their sum) per string, decoded
    from the code's mean."""
    model.eval()
    nll_sum = kl_sum = 0.0
    with torch.no_grad():
        for k in range(0, len(strings), preset["batch_size"]):
            x, lengths, forced = _tensors(strings[k:k + preset["batch_size"]], vocab, preset, device)
            logits, mu, logvar = model(x, lengths)
            nll, kl = losses(logits, x, mu, logvar, forced)
            nll_sum, kl_sum = nll_sum + float(nll.sum()), kl_sum + float(kl.sum())
    n = max(len(strings), 1)
    return {"nll": nll_sum / n, "kl": kl_sum / n, "elbo": (nll_sum + kl_sum) / n}


def train(fit: list[Room], validation: list[Room], vocab: TokenVocab, preset: dict, session: epochs.Session) -> Run:
    """Fit the VAE on ``fit`` rooms' strings; keep the epoch of the best validation ELBO (see the module;
    :func:`~pipeline.learning.epochs.fit`)."""
    torch.manual_seed(session.seed)
    model = build_model(vocab, preset).to(session.device)
    opt = torch.optim.Adam(model.parameters(), lr=preset["lr"])
    val_strings = room_strings(validation, None)

    def epoch(n: int, best: float) -> tuple[dict, float, bool | None]:
        beta = min(1.0, n / max(preset["kl_anneal"], 1))
        start = time.perf_counter()
        model.train()
        strings = room_strings(fit, rng_for(session.seed, n), preset["strings_per_room"])
        nll, kl = _epoch((model, opt), strings, vocab, preset, beta, session, n)
        seconds = time.perf_counter() - start
        val = score(model, val_strings, vocab, preset, session.device)
        row = {"epoch": n, "beta": beta, "train_nll": nll, "train_kl": kl, "validation_nll": val["nll"],
               "validation_kl": val["kl"], "validation_elbo": val["elbo"], "seconds": seconds,
               "strings_per_s": len(strings) / max(seconds, 1e-9)}
        return row, val["elbo"], (val["elbo"] < best if beta >= 1.0 else None)  # scores compare once the KL weight is 1

    return epochs.fit(model, opt, session, PROGRESS, preset, epoch)
