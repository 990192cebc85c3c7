"""Real-vs-synthetic classification accuracy (SCA): a small CNN trained from scratch (no downloaded weights) to tell
real top-down renders from generated ones. Train on real training renders vs half the generated ones, test on
held-out real renders vs the other half, both balanced; re-initialised for each of ``runs`` runs. 50% is ideal;
accuracies below 50% are folded to 100 - x (a classifier that is reliably wrong still tells the sets apart)."""
from __future__ import annotations

import numpy as np
import torch
from torch import nn

from ..log import progress
from ..learning.device import pick_device


def classifier(width: int) -> nn.Module:
    """Three conv-BN-ReLU-pool blocks, global average pooling and one logit."""
    layers, c = [], 3
    for k in range(3):
        layers += [nn.Conv2d(c, width * 2 ** k, 3, padding=1), nn.BatchNorm2d(width * 2 ** k), nn.ReLU(), nn.MaxPool2d(2)]
        c = width * 2 ** k
    return nn.Sequential(*layers, nn.AdaptiveAvgPool2d(1), nn.Flatten(), nn.Linear(c, 1))


def balanced(real: np.ndarray, fake: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Images ``(2m, 3, s, s)`` and labels ``(2m,)`` (1: real) with ``m`` of each, ``m`` the smaller count."""
    m = min(len(real), len(fake))
    x = np.concatenate([real[rng.permutation(len(real))[:m]], fake[rng.permutation(len(fake))[:m]]])
    return x, np.concatenate([np.ones(m), np.zeros(m)]).astype(np.float32)


def fit_and_score(train: tuple[np.ndarray, np.ndarray], test: tuple[np.ndarray, np.ndarray], cfg: dict, seed: int,
                  device: str) -> float:
    """Accuracy on ``test`` of a freshly initialised classifier trained ``cfg['steps']`` Adam steps on ``train``."""
    torch.manual_seed(seed)
    net = classifier(cfg["width"]).to(device, memory_format=torch.channels_last)  # faster steps on a CPU
    opt = torch.optim.Adam(net.parameters(), lr=cfg["lr"])
    x = torch.as_tensor(train[0], device=device).to(memory_format=torch.channels_last)
    y = torch.as_tensor(train[1], device=device)
    gen = torch.Generator().manual_seed(seed)
    net.train()
    for _ in range(cfg["steps"]):  # steps, not epochs: a few dozen images still get a trained classifier
        idx = torch.randint(len(x), (min(cfg["batch_size"], len(x)),), generator=gen)
        loss = nn.functional.binary_cross_entropy_with_logits(net(x[idx]).squeeze(1), y[idx])
        opt.zero_grad()
        loss.backward()
        opt.step()
    net.eval()
    with torch.no_grad():
        xt = torch.as_tensor(test[0], device=device).to(memory_format=torch.channels_last)
        pred = torch.cat([net(b).squeeze(1) > 0 for b in xt.split(256)]).cpu().numpy()
    return float((pred == (test[1] > 0.5)).mean())


def sca(real_train: np.ndarray, real_test: np.ndarray, generated: np.ndarray, cfg: dict, seed: int) -> dict:
    """Mean and sd of the folded accuracy (%) over ``cfg['runs']`` runs. Images ``(n, s, s, 3)`` in [0, 1]; the
    generated ones are split in two halves (train, test) anew per run."""
    device = pick_device(cfg["device"])
    to_chw = lambda a: np.ascontiguousarray(np.asarray(a, np.float32).transpose(0, 3, 1, 2))
    real_train, real_test, generated = to_chw(real_train), to_chw(real_test), to_chw(generated)
    if min(len(real_train), len(real_test)) < 1 or len(generated) < 2:
        return {"mean": float("nan"), "sd": float("nan"), "runs": [], "train": 0, "test": 0}
    accs = []
    for run in progress(range(cfg["runs"]), desc="SCA runs"):
        rng = np.random.default_rng([seed, 5150, run])
        perm = rng.permutation(len(generated))
        half = len(generated) // 2
        train = balanced(real_train, generated[perm[:half]], rng)
        test = balanced(real_test, generated[perm[half:]], rng)
        acc = fit_and_score(train, test, cfg, seed * 1000 + run, device)
        accs.append(100.0 * max(acc, 1.0 - acc))
    return {"mean": float(np.mean(accs)), "sd": float(np.std(accs)), "runs": accs, "train": len(train[1]),
            "test": len(test[1])}


def sca_scores(real_maps: tuple[np.ndarray, np.ndarray], generated: np.ndarray, cfg: dict, threads: int, seed: int) -> dict:
    """:func:`sca` of one set's renders against the real training and held-out renders, rounded for the report."""
    torch.set_num_threads(max(threads, 1))
    out = sca(real_maps[0], real_maps[1], generated, cfg, seed)
    return {k: (round(v, 3) if isinstance(v, float) else v) for k, v in out.items() if k != "runs"} | {
        "runs": [round(a, 3) for a in out["runs"]]}
