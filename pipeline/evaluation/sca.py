"""Real-vs-synthetic classification accuracy (SCA): a small CNN trained from scratch (no downloaded weights) to tell
real top-down renders from another set's. Two folds: the other set's rooms are split in halves by room (copies of
one room stay together); the classifier trains on the real training renders against one half and is tested on the
held-out real renders against the other, then the halves swap. Batches hold as many real as other renders, each
batch turned and mirrored at random (a turned room is still a room). The score is the balanced accuracy over both
folds' test predictions, folded to ``max(a, 100 - a)`` (a classifier that is reliably wrong still tells the sets
apart), with a bootstrap 95% interval over the test rooms. 50% is ideal."""
from __future__ import annotations

import numpy as np
import torch
from torch import nn

from ..learning.device import pick_device


def classifier(width: int, stride: int = 1) -> nn.Module:
    """Three conv-BN-ReLU-pool blocks (the first conv with ``stride``), global average pooling and one logit."""
    layers, c = [], 3
    for k in range(3):
        layers += [nn.Conv2d(c, width * 2 ** k, 3, stride=stride if k == 0 else 1, padding=1),
                   nn.BatchNorm2d(width * 2 ** k), nn.ReLU(), nn.MaxPool2d(2)]
        c = width * 2 ** k
    return nn.Sequential(*layers, nn.AdaptiveAvgPool2d(1), nn.Flatten(), nn.Linear(c, 1))


def _batch(x: torch.Tensor, size: int, gen: torch.Generator) -> torch.Tensor:
    return x[torch.randint(len(x), (size,), generator=gen)]


def fit_and_predict(real: torch.Tensor, other: torch.Tensor, test: torch.Tensor, cfg: dict, seed: int) -> np.ndarray:
    """``(t,)`` bool "real" predictions for ``test`` of a fresh classifier trained ``cfg['steps']`` Adam steps on
    balanced, randomly turned and mirrored batches of ``real`` and ``other`` (``(n, 3, s, s)`` tensors)."""
    torch.manual_seed(seed)
    net = classifier(cfg["width"], cfg["stride"]).to(real.device, memory_format=torch.channels_last)  # faster steps on a CPU
    opt = torch.optim.Adam(net.parameters(), lr=cfg["lr"])
    gen = torch.Generator().manual_seed(seed)
    half = max(cfg["batch_size"] // 2, 1)
    y = torch.cat([torch.ones(half), torch.zeros(half)]).to(real.device)
    net.train()
    for _ in range(cfg["steps"]):
        x = torch.cat([_batch(real, half, gen), _batch(other, half, gen)])
        turn = int(torch.randint(8, (1,), generator=gen))
        x = torch.rot90(x.flip(3) if turn >= 4 else x, turn % 4, (2, 3)).contiguous(memory_format=torch.channels_last)
        loss = nn.functional.binary_cross_entropy_with_logits(net(x).squeeze(1), y)
        opt.zero_grad()
        loss.backward()
        opt.step()
    net.eval()
    with torch.no_grad():
        return torch.cat([net(b.contiguous(memory_format=torch.channels_last)).squeeze(1) > 0
                          for b in test.split(256)]).cpu().numpy()


def halves(groups: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Index arrays of two halves of the items, split by group (``groups (m,)``: one id per item)."""
    ids = np.unique(groups)
    mask = np.isin(groups, rng.permutation(ids)[: len(ids) // 2])
    return np.flatnonzero(mask), np.flatnonzero(~mask)


def accuracy(real_hits: np.ndarray, other_hits: np.ndarray) -> float:
    """Mean of the shares of real and of other test renders classified right (%), not folded."""
    return 50.0 * (real_hits.mean() + other_hits.mean())


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
    rng = np.random.default_rng([seed, 5151])
    pick = lambda groups: np.concatenate([groups[k] for k in rng.integers(len(groups), size=len(groups))])
    return np.array([accuracy(pick(real), pick(other)) for _ in range(repeats)])


def sca(real_train: np.ndarray, real_test: np.ndarray, other: np.ndarray, groups: np.ndarray, cfg: dict,
        seed: int, real_groups: np.ndarray | None = None) -> dict:
    """The folded balanced accuracy (%) and its bootstrap 95% interval (rooms resampled: a room's copies and a real
    room's predictions of both folds together), the first fold's training renders and all test predictions.
    ``real_groups``: the group of each real test render where the other set is made from them (the power check):
    each fold then tests only the real rooms of its test half, never the originals of what it trained on. Images
    ``(n, s, s, 3)`` in [0, 1]."""
    if min(len(real_train), len(real_test)) < 1 or len(np.unique(groups)) < 2:
        return {"accuracy": float("nan"), "low": float("nan"), "high": float("nan"), "train": 0, "test": 0}
    device = pick_device(cfg["device"])
    t = lambda a: torch.as_tensor(np.ascontiguousarray(np.asarray(a, np.float32).transpose(0, 3, 1, 2)), device=device)
    real_train, real_test, other = t(real_train), t(real_test), t(other)
    first, second = halves(groups, np.random.default_rng([seed, 5150]))
    real_of = np.arange(len(real_test)) if real_groups is None else np.asarray(real_groups)
    real_hits: dict = {}
    other_hits: dict = {}
    for fold, (fit, test) in enumerate(((first, second), (second, first))):
        shown = np.arange(len(real_test)) if real_groups is None else np.flatnonzero(np.isin(real_of, groups[test]))
        pred = fit_and_predict(real_train, other[fit], torch.cat([real_test[shown], other[test]]), cfg,
                               seed * 1000 + fold)
        for k, hit in zip(shown, pred[:len(shown)]):
            real_hits.setdefault(int(k), []).append(hit)
        for g, hit in zip(groups[test], ~pred[len(shown):]):
            other_hits.setdefault(g, []).append(hit)
    real_list = [np.asarray(v) for v in real_hits.values()]
    other_list = [np.asarray(v) for v in other_hits.values()]
    point = accuracy(np.concatenate(real_list), np.concatenate(other_list))
    reps = grouped_bootstrap(real_list, other_list, cfg["bootstrap"], seed)
    low, acc, high = folded(min(float(np.percentile(reps, 2.5)), point), point,
                            max(float(np.percentile(reps, 97.5)), point))  # widened to hold the estimate, if need be
    return {"accuracy": round(acc, 3), "low": round(low, 3), "high": round(high, 3),
            "train": len(real_train) + len(first), "test": sum(map(len, real_list)) + sum(map(len, other_list))}


def sca_scores(real_maps: tuple[np.ndarray, np.ndarray], sets: dict, cfg: dict, threads: int, seed: int) -> dict:
    """:func:`sca` of each set ``name -> (images, groups, real_groups)`` against the real training and held-out
    renders (groups None: one per image; real_groups None: the set is not made from the held-out rooms)."""
    torch.set_num_threads(max(threads, 1))
    return {name: sca(real_maps[0], real_maps[1], images, np.arange(len(images)) if groups is None else groups, cfg,
                      seed, real_groups) for name, (images, groups, real_groups) in sets.items()}
