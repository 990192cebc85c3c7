"""The placement networks (PlanIT section 6, Fig. 9).

:class:`LocationNet` is the conditional FCN: a residual encoder (ResNet-34's layout in the paper preset), then
upsampling blocks of conv - BatchNorm - FiLM - LeakyReLU with CoordConv (two coordinate channels concatenated) and
skips from the encoder, predicting per pixel a distribution over every category plus background at once. FiLM
scales and shifts every decoder block from an embedding of the planned edge (:data:`~.data.EDGE_KINDS`: direction
and distance, support, or none), whether the anchor is a wall and whether the edge runs from the target to the
anchor. Without FiLM (``film=False``) it is the unconditional FCN of the ablation.

:class:`OrientationNet` reads a crop centred on a location, turned like the anchor's frame, and gives per category
logits over ``bins`` yaws relative to that frame plus one logit of standing square to the nearest wall (the paper's
snap classifier); FiLM scales and shifts its encoder from the same edge embedding and the location's position in the
anchor's frame (a documented simpler choice than the paper's CVAE: binned yaws).
"""
from __future__ import annotations

import torch
from torch import nn
from torch.nn import functional as F

from .data import EDGE_KINDS


def coords(x: torch.Tensor) -> torch.Tensor:
    """``x`` with two channels of pixel coordinates in [-1, 1] appended (CoordConv)."""
    n, _, h, w = x.shape
    ys = torch.linspace(-1, 1, h, device=x.device).view(1, 1, h, 1).expand(n, 1, h, w)
    xs = torch.linspace(-1, 1, w, device=x.device).view(1, 1, 1, w).expand(n, 1, h, w)
    return torch.cat([x, xs, ys], 1)


class Residual(nn.Module):
    """ResNet's basic block."""

    def __init__(self, cin: int, cout: int, stride: int):
        super().__init__()
        self.a = nn.Sequential(nn.Conv2d(cin, cout, 3, stride, 1, bias=False), nn.BatchNorm2d(cout), nn.ReLU(inplace=True),
                               nn.Conv2d(cout, cout, 3, 1, 1, bias=False), nn.BatchNorm2d(cout))
        self.skip = (nn.Sequential(nn.Conv2d(cin, cout, 1, stride, bias=False), nn.BatchNorm2d(cout))
                     if stride != 1 or cin != cout else nn.Identity())

    def forward(self, x):
        return F.relu(self.a(x) + self.skip(x))


def encoder(cin: int, widths: list[int], blocks: list[int]) -> nn.ModuleList:
    """Stages of residual blocks, each halving the resolution (the paper preset: widths 64-512, blocks 3,4,6,3)."""
    stages, c = [], cin
    for w, n in zip(widths, blocks):
        stages.append(nn.Sequential(Residual(c, w, 2), *(Residual(w, w, 1) for _ in range(n - 1))))
        c = w
    return nn.ModuleList(stages)


class LocationNet(nn.Module):
    def __init__(self, channels: int, categories: int, widths: list[int], blocks: list[int], film: bool = True,
                 embed: int = 16):
        super().__init__()
        self.film = film
        self.stem = nn.Sequential(nn.Conv2d(channels + 2, widths[0], 3, 1, 1), nn.ReLU(inplace=True))
        self.down = encoder(widths[0], widths, blocks)
        ups, c = [], widths[-1]
        skips = widths[-2::-1] + [widths[0]]
        for s in skips:
            ups.append(nn.Conv2d(c + s + 2, s, 3, 1, 1))
            c = s
        self.up = nn.ModuleList(ups)
        self.norm = nn.ModuleList(nn.BatchNorm2d(s) for s in skips)
        self.head = nn.Conv2d(c, categories + 1, 1)
        self.embed = Condition(embed)
        self.gamma_beta = nn.Linear(self.embed.size, 2 * sum(skips))
        self.sizes = skips

    def forward(self, image: torch.Tensor, cond: torch.Tensor) -> torch.Tensor:
        """``(n, C, s, s)`` images and ``(n, 3)`` conditions -> ``(n, categories + 1, s, s)`` logits."""
        x = self.stem(coords(image))
        feats = [x]
        for stage in self.down:
            x = stage(x)
            feats.append(x)
        gb = self.gamma_beta(self.embed(cond))
        offset = 0
        for k, (conv, norm, size) in enumerate(zip(self.up, self.norm, self.sizes)):
            skip = feats[-2 - k]
            x = F.interpolate(x, size=skip.shape[-2:], mode="nearest")
            x = norm(conv(coords(torch.cat([x, skip], 1))))
            if self.film:
                g, b = gb[:, offset:offset + size], gb[:, offset + size:offset + 2 * size]
                x = x * (1 + g[:, :, None, None]) + b[:, :, None, None]
            offset += 2 * size
            x = F.leaky_relu(x, 0.1)
        return self.head(x)


class OrientationNet(nn.Module):
    def __init__(self, channels: int, categories: int, bins: int, widths: list[int], film: bool = True, embed: int = 16):
        super().__init__()
        self.film = film
        self.down = encoder(channels + 2, widths, [1] * len(widths))
        self.embed = Condition(embed, extra=2)
        self.gamma_beta = nn.Linear(self.embed.size, 2 * sum(widths))
        self.head = nn.Linear(widths[-1], categories * (bins + 1))
        self.categories, self.bins, self.widths = categories, bins, widths

    def forward(self, image: torch.Tensor, cond: torch.Tensor, rel: torch.Tensor) -> torch.Tensor:
        """``(n, C, s, s)`` crops, ``(n, 3)`` conditions and ``(n, 2)`` positions in the anchor's frame ->
        ``(n, categories, bins + 1)`` logits (yaw bins, then standing square to the nearest wall)."""
        x = coords(image)
        gb = self.gamma_beta(self.embed(cond, rel)) if self.film else None
        offset = 0
        for stage, width in zip(self.down, self.widths):
            x = stage(x)
            if gb is not None:
                g, b = gb[:, offset:offset + width], gb[:, offset + width:offset + 2 * width]
                x = x * (1 + g[:, :, None, None]) + b[:, :, None, None]
            offset += 2 * width
        return self.head(x.mean((2, 3))).view(-1, self.categories, self.bins + 1)


class Condition(nn.Module):
    """The embedding of a planned edge: its kind, wall anchor and reverse flags (``cond (n, 3)``), concatenated
    with ``extra`` continuous features."""

    def __init__(self, embed: int, extra: int = 0):
        super().__init__()
        self.parts = nn.ModuleList([nn.Embedding(len(EDGE_KINDS), embed), nn.Embedding(2, embed), nn.Embedding(2, embed)])
        self.size = 3 * embed + extra

    def forward(self, cond: torch.Tensor, extra: torch.Tensor | None = None) -> torch.Tensor:
        parts = [e(cond[:, k]) for k, e in enumerate(self.parts)]
        return torch.cat(parts + ([] if extra is None else [extra]), 1)


def location_loss(logits: torch.Tensor, cat: torch.Tensor, row: torch.Tensor, col: torch.Tensor,
                  weight: float) -> torch.Tensor:
    """Per-pixel cross-entropy: the target's pixel holds its category, every other pixel background (index 0);
    category classes weigh ``weight`` (the paper's 10)."""
    n, c, h, w = logits.shape
    target = torch.zeros(n, h, w, dtype=torch.long, device=logits.device)
    target[torch.arange(n), row, col] = cat + 1
    weights = torch.full((c,), float(weight), device=logits.device)
    weights[0] = 1.0
    return F.cross_entropy(logits, target, weight=weights)


def orientation_loss(logits: torch.Tensor, cat: torch.Tensor, bins: torch.Tensor, snap: torch.Tensor) -> torch.Tensor:
    """``-log`` of the probability of the equivalent bins of the target's yaw, plus the snap bit's cross-entropy."""
    own = logits[torch.arange(len(cat)), cat]
    return -bin_loglik(own[:, :-1], bins).mean() + F.binary_cross_entropy_with_logits(own[:, -1], snap.float())


def bin_loglik(logits: torch.Tensor, bins: torch.Tensor) -> torch.Tensor:
    """``(n,)`` log probability of the equivalent bins ``bins (n, b)`` under ``logits (n, b)``."""
    logp = F.log_softmax(logits, 1)
    return torch.logsumexp(logp.masked_fill(~bins, float("-inf")), 1)


def location_loglik(logits: torch.Tensor, cat: torch.Tensor, row: torch.Tensor, col: torch.Tensor) -> torch.Tensor:
    """``(n,)`` log probability of the target's pixel under its category's map normalised over the view (the density
    the search draws from)."""
    p = torch.softmax(logits, 1)[torch.arange(len(cat)), cat + 1]  # (n, h, w)
    return torch.log(p[torch.arange(len(cat)), row, col] / p.sum((1, 2)).clamp_min(1e-12) + 1e-12)
