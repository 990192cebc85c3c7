"""Real-vs-synthetic classification accuracy (SCA): a small CNN trained from scratch (no downloaded weights) to tell
real top-down renders from another set's. Two folds: the other set's rooms are split in halves by room (copies of
one room stay together); the classifier trains on the real training renders against one half and is tested on the
held-out real renders against the other, then the halves swap. Batches hold as many real as other renders, each
batch turned and mirrored at random (a turned room is still a room). The score is the balanced accuracy over both
folds' test predictions, folded to ``max(a, 100 - a)`` (a classifier that is reliably wrong still tells the sets
apart), with a bootstrap 95% interval over the test rooms. 50% is ideal.

Two ways to train (``evaluate.sca.mode``): ``per_set``, a fresh classifier per set and fold (the protocol of issue 27);
``shared`` (issue 41; opt-in, docs/departures.md), one classifier per fold for all sets at once: a shared encoder with one logit per set,
each batch half real renders (a positive for every head) and half renders of the other sets (a negative for its own
set's head only), so each head is a real-vs-that-set classifier on features every set helped learn. Each set keeps its
own halves, its own test renders and its own score; the work is two trainings instead of two per set."""
from __future__ import annotations

import copy
from typing import Any, cast

import numpy as np
import torch
from torch import nn

from ..learning.device import pick_device
from ..log import progress
from ..seeding import rng_for
from .intervals import replicates


def classifier(width: int, stride: int = 1, heads: int = 1) -> nn.Module:
    """Three conv-BN-ReLU-pool blocks (the first conv with ``stride``), global average pooling and ``heads`` logits."""
    layers, c = [], 3
    for k in range(3):
        layers += [nn.Conv2d(c, width * 2 ** k, 3, stride=stride if k == 0 else 1, padding=1),
                   nn.BatchNorm2d(width * 2 ** k), nn.ReLU(), nn.MaxPool2d(2)]
        c = width * 2 ** k
    return nn.Sequential(*layers, nn.AdaptiveAvgPool2d(1), nn.Flatten(), nn.Linear(c, heads))


def _batch(x: torch.Tensor, size: int, gen: torch.Generator) -> torch.Tensor:
    return x[torch.randint(len(x), (size,), generator=gen)]


def fit_and_predict(real: torch.Tensor, other: torch.Tensor, test: torch.Tensor, cfg: dict[str, Any], seed: int) -> np.ndarray:
    """``(t,)`` bool "real" predictions for ``test`` of a fresh classifier trained up to ``cfg['steps']`` Adam steps on
    balanced, randomly turned and mirrored batches of ``real`` and ``other`` (``(n, 3, s, s)`` tensors); with
    ``cfg['patience']``, a ``cfg['validation']`` share of each held out and training stopped where its loss has not
    fallen for that many checks (every ``cfg['check_every']`` steps), the best weights kept (:func:`_fit`)."""
    torch.manual_seed(seed)
    # channels-last: faster steps on a CPU (torch's stubs do not list Module.to's memory_format)
    net = classifier(cfg["width"], cfg["stride"]).to(real.device, memory_format=torch.channels_last)  # type: ignore[call-overload]
    gen = torch.Generator().manual_seed(seed)
    held = None
    if cfg["patience"] and min(len(real), len(other)) > 1:
        (real, real_held), (other, other_held) = (_held_out(x, cfg["validation"], gen) for x in (real, other))
        held = (real_held, other_held)
    _fit(net, real, other, cfg, gen, held)
    net.eval()
    with torch.no_grad():
        return torch.cat([net(b.contiguous(memory_format=torch.channels_last)).squeeze(1) > 0
                          for b in test.split(256)]).cpu().numpy()


def _fit(net: nn.Module, real: torch.Tensor, other: torch.Tensor, cfg: dict[str, Any], gen: torch.Generator,
         held: tuple[torch.Tensor, torch.Tensor] | None) -> int:
    """Train ``net`` in place on balanced batches of ``real`` and ``other``; with ``held`` (real and other renders
    kept out), stop after ``cfg['patience']`` checks without a lower balanced loss on them and load the best
    weights. Returns the steps taken."""
    opt = torch.optim.Adam(net.parameters(), lr=cfg["lr"])
    half = max(cfg["batch_size"] // 2, 1)
    y = torch.cat([torch.ones(half), torch.zeros(half)]).to(real.device)
    best, kept, stale = float("inf"), None, 0
    step = 0
    while step < cfg["steps"] and (held is None or stale < cfg["patience"]):
        net.train()
        x = torch.cat([_batch(real, half, gen), _batch(other, half, gen)])
        turn = int(torch.randint(8, (1,), generator=gen))
        x = torch.rot90(x.flip(3) if turn >= 4 else x, turn % 4, (2, 3)).contiguous(memory_format=torch.channels_last)
        loss = nn.functional.binary_cross_entropy_with_logits(net(x).squeeze(1), y)
        opt.zero_grad()
        loss.backward()
        opt.step()
        step += 1
        if held is not None and step % cfg["check_every"] == 0:
            checked = _held_loss(net, *held)
            best, kept, stale = (checked, copy.deepcopy(net.state_dict()), 0) if checked < best else (best, kept,
                                                                                                       stale + 1)
    if kept is not None:
        net.load_state_dict(kept)
    return step


def _held_out(x: torch.Tensor, share: float, gen: torch.Generator) -> tuple[torch.Tensor, torch.Tensor]:
    """``x`` split at random into the renders to train on and a ``share`` held out (at least one, never all)."""
    order = torch.randperm(len(x), generator=gen)
    k = min(max(int(round(share * len(x))), 1), len(x) - 1)
    return x[order[k:]], x[order[:k]]


def _held_loss(net: nn.Module, real: torch.Tensor, other: torch.Tensor) -> float:
    """The mean of the binary cross-entropies of ``net`` on held-out ``real`` (label 1) and ``other`` (0) renders."""
    net.eval()
    with torch.no_grad():
        bce = lambda x, label: float(nn.functional.binary_cross_entropy_with_logits(
            net(x.contiguous(memory_format=torch.channels_last)).squeeze(1), torch.full((len(x),), label, device=x.device)))
        return (bce(real, 1.0) + bce(other, 0.0)) / 2


def no_score() -> dict[str, float]:
    """The score of a set the classifier cannot split into two folds (or with no real renders)."""
    return {"accuracy": float("nan"), "low": float("nan"), "high": float("nan"), "train": 0, "test": 0}


def halves(groups: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Index arrays of two halves of the items, split by group (``groups (m,)``: one id per item)."""
    ids = np.unique(groups)
    mask = np.isin(groups, rng.permutation(ids)[: len(ids) // 2])
    return np.flatnonzero(mask), np.flatnonzero(~mask)


def accuracy(real_hits: np.ndarray, other_hits: np.ndarray) -> float:
    """Mean of the shares of real and of other test renders classified right (%), not folded."""
    return cast(float, 50.0 * (real_hits.mean() + other_hits.mean()))


def folded(low: float, point: float, high: float) -> tuple[float, float, float]:
    """An accuracy and its interval folded at 50: ``max(a, 100 - a)``; an interval across 50 becomes
    ``[50, max(100 - low, high)]``."""
    if low >= 50.0:
        return low, point, high
    if high <= 50.0:
        return 100.0 - high, 100.0 - point, 100.0 - low
    return 50.0, max(point, 100.0 - point), max(100.0 - low, high)


def grouped_bootstrap(real: list[np.ndarray], other: list[np.ndarray], repeats: int, seed: int) -> np.ndarray:
    """``(repeats,)`` unfolded accuracies, resampling rooms (each a group of predictions) on both sides."""
    take = lambda groups, k: np.concatenate([groups[i] for i in k])
    return np.array(replicates([real, other], lambda p: accuracy(*p), repeats, rng_for(seed, "sca-bootstrap"), take))


def sca(real_train: np.ndarray, real_test: np.ndarray, other: np.ndarray, groups: np.ndarray, cfg: dict[str, Any],
        seed: int, real_groups: np.ndarray | None = None) -> dict[str, Any]:
    """The folded balanced accuracy (%) and its bootstrap 95% interval (rooms resampled: a room's copies and a real
    room's predictions of both folds together), the first fold's training renders and all test predictions.
    ``real_groups``: the group of each real test render where the other set is made from them (the power check):
    each fold then tests only the real rooms of its test half, never the originals of what it trained on. Images
    ``(n, s, s, 3)`` in [0, 1]."""
    if min(len(real_train), len(real_test)) < 1 or len(np.unique(groups)) < 2:
        return no_score()
    device = pick_device(cfg["device"])
    t = lambda a: torch.as_tensor(np.ascontiguousarray(np.asarray(a, np.float32).transpose(0, 3, 1, 2)), device=device)
    real_train_t, real_test_t, other_t = t(real_train), t(real_test), t(other)
    first, second = halves(groups, rng_for(seed, "sca-halves"))
    real_of = np.arange(len(real_test)) if real_groups is None else np.asarray(real_groups)
    real_hits: dict[int, list[Any]] = {}
    other_hits: dict[Any, list[Any]] = {}
    for fold, (fit, test) in enumerate(((first, second), (second, first))):
        shown = np.arange(len(real_test)) if real_groups is None else np.flatnonzero(np.isin(real_of, groups[test]))
        pred = fit_and_predict(real_train_t, other_t[fit], torch.cat([real_test_t[shown], other_t[test]]), cfg,
                               seed * 1000 + fold)
        for k, hit in zip(shown, pred[:len(shown)]):
            real_hits.setdefault(int(k), []).append(hit)
        for g, hit in zip(groups[test], ~pred[len(shown):]):
            other_hits.setdefault(g, []).append(hit)
    return scored(real_hits, other_hits, cfg, seed, len(real_train) + len(first))


def scored(real_hits: dict[int, list[Any]], other_hits: dict[Any, list[Any]], cfg: dict[str, Any], seed: int,
           trained: int) -> dict[str, Any]:
    """The folded balanced accuracy and its bootstrap interval from test predictions grouped by room (``real_hits``:
    real test render -> its hits, ``other_hits``: the other set's room -> its hits); ``trained``: the first fold's
    training renders."""
    real_list = [np.asarray(v) for v in real_hits.values()]
    other_list = [np.asarray(v) for v in other_hits.values()]
    point = accuracy(np.concatenate(real_list), np.concatenate(other_list))
    reps = grouped_bootstrap(real_list, other_list, cfg["bootstrap"], seed)
    low, acc, high = folded(min(float(np.percentile(reps, 2.5)), point), point,
                            max(float(np.percentile(reps, 97.5)), point))  # widened to hold the estimate, if need be
    return {"accuracy": round(acc, 3), "low": round(low, 3), "high": round(high, 3),
            "train": trained, "test": sum(map(len, real_list)) + sum(map(len, other_list))}


def fit_and_predict_shared(real: torch.Tensor, others: list[torch.Tensor], real_test: torch.Tensor,
                           tests: list[torch.Tensor], cfg: dict[str, Any], seed: int) -> tuple[np.ndarray, list[np.ndarray]]:
    """One classifier with a head per set of ``others`` trained ``cfg['steps']`` Adam steps on batches of
    ``cfg['shared_batch_size']``: half ``real`` renders (positives of every head), half renders of the other sets (a
    set drawn uniformly, then one of its renders: a negative of that set's head). Returns every head's ``(t, K)``
    bool "real" predictions for ``real_test`` and each set's own head's ``(t_k,)`` for ``tests[k]``."""
    torch.manual_seed(seed)
    heads = len(others)
    net = classifier(cfg["width"], cfg["stride"], heads).to(real.device, memory_format=torch.channels_last)  # type: ignore[call-overload]
    opt = torch.optim.Adam(net.parameters(), lr=cfg["lr"])
    gen = torch.Generator().manual_seed(seed)
    half = max(cfg["shared_batch_size"] // 2, 1)
    pool = torch.cat(others)
    sizes = torch.tensor([len(o) for o in others])
    starts = torch.cumsum(sizes, 0) - sizes
    bce = nn.functional.binary_cross_entropy_with_logits
    net.train()
    for _ in range(cfg["steps"]):
        owner = torch.randint(heads, (half,), generator=gen)
        pick = starts[owner] + (torch.rand(half, generator=gen) * sizes[owner]).long()
        x = torch.cat([_batch(real, half, gen), pool[pick.to(pool.device)]])
        turn = int(torch.randint(8, (1,), generator=gen))
        x = torch.rot90(x.flip(3) if turn >= 4 else x, turn % 4, (2, 3)).contiguous(memory_format=torch.channels_last)
        logits = net(x)
        own = logits[half:].gather(1, owner.to(logits.device)[:, None]).squeeze(1)
        loss = bce(logits[:half], torch.ones_like(logits[:half])) + bce(own, torch.zeros_like(own))
        opt.zero_grad()
        loss.backward()
        opt.step()
    net.eval()

    def run(t: torch.Tensor) -> torch.Tensor:
        with torch.no_grad():
            return torch.cat([net(b.contiguous(memory_format=torch.channels_last)) for b in t.split(256)]) \
                if len(t) else torch.zeros(0, heads, device=real.device)

    return (run(real_test) > 0).cpu().numpy(), [(run(t)[:, k] > 0).cpu().numpy() for k, t in enumerate(tests)]


def sca_shared(real_train: np.ndarray, real_test: np.ndarray, sets: dict[str, Any], cfg: dict[str, Any],
               seed: int) -> dict[str, Any]:
    """:func:`sca` of every set ``name -> (images, groups, real_groups)`` with one shared classifier per fold (module
    docstring): each set's halves, test renders, bootstrap and folding are :func:`sca`'s."""
    names = [n for n, (_, groups, _) in sets.items() if len(np.unique(groups)) >= 2]
    if min(len(real_train), len(real_test)) < 1:
        names = []
    out = {n: no_score() for n in sets if n not in names}
    if not names:
        return out
    device = pick_device(cfg["device"])
    t = lambda a: torch.as_tensor(np.ascontiguousarray(np.asarray(a, np.float32).transpose(0, 3, 1, 2)), device=device)
    real_t, real_test_t = t(real_train), t(real_test)
    images = {n: t(sets[n][0]) for n in names}
    split = {n: halves(sets[n][1], rng_for(seed, "sca-halves")) for n in names}
    real_hits: dict[str, dict[int, list[Any]]] = {n: {} for n in names}
    other_hits: dict[str, dict[Any, list[Any]]] = {n: {} for n in names}
    for fold in range(2):
        fit = {n: split[n][fold] for n in names}
        test = {n: split[n][1 - fold] for n in names}
        real_pred, preds = fit_and_predict_shared(real_t, [images[n][fit[n]] for n in names], real_test_t,
                                                  [images[n][test[n]] for n in names], cfg, seed * 1000 + fold)
        for k, n in enumerate(names):
            groups, real_groups = sets[n][1], sets[n][2]
            shown = np.arange(len(real_test)) if real_groups is None else \
                np.flatnonzero(np.isin(np.asarray(real_groups), groups[test[n]]))
            for r in shown:
                real_hits[n].setdefault(int(r), []).append(real_pred[r, k])
            for g, hit in zip(groups[test[n]], ~preds[k]):
                other_hits[n].setdefault(g, []).append(hit)
    return out | {n: scored(real_hits[n], other_hits[n], cfg, seed, len(real_train) + len(split[n][0]))
                  for n in names}


def sca_scores(real_maps: tuple[np.ndarray, np.ndarray], sets: dict[str, Any], cfg: dict[str, Any], threads: int,
               seed: int) -> dict[str, Any]:
    """:func:`sca` of each set ``name -> (images, groups, real_groups)`` against the real training and held-out
    renders (groups None: one per image; real_groups None: the set is not made from the held-out rooms)."""
    torch.set_num_threads(max(threads, 1))
    return {name: sca(real_maps[0], real_maps[1], images, np.arange(len(images)) if groups is None else groups, cfg,
                      seed, real_groups)
            for name, (images, groups, real_groups) in progress(sets.items(), len(sets), "SCA classifiers (per set)")}


def sca_all(real_maps: tuple[np.ndarray, np.ndarray], sets: dict[str, Any], control: tuple[np.ndarray, np.ndarray, str],
            cfg: dict[str, Any], threads: int, seed: int) -> dict[str, Any]:
    """Every set's score and the real-vs-real control's, by ``cfg['mode']`` (``control``: the real training renders
    kept in the real class, those held back and scored as the other set, and the control's name). Shared: every set
    and the control against the kept renders, in one classifier per fold; per set: the sets against every training
    render, the control against the kept ones."""
    kept, back, name = control
    if cfg["mode"] == "shared":
        torch.set_num_threads(max(threads, 1))
        return sca_shared(kept, real_maps[1], {**sets, name: (back, np.arange(len(back)), None)}, cfg, seed)
    return sca_scores(real_maps, sets, cfg, threads, seed) | sca_scores((kept, real_maps[1]),
                                                                      {name: (back, None, None)}, cfg, threads, seed)
