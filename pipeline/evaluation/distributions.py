"""Set-level distances between two collections of rooms: category KL divergence (ATISS's definition), object-count
distance, and their sampling floors (the same distance between two disjoint sets of real rooms)."""
from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Sequence
from typing import Any, TypeVar, cast

import numpy as np

from ..seeding import rng_for

L = TypeVar("L", str, int)  # a category label: a name, or a class index
P = TypeVar("P")


def category_kl(real: Sequence[L], generated: Sequence[L], eps: float = 1e-6) -> float:
    """KL(p || q) of the category frequencies over all objects: p from ``real``, q from ``generated`` (one category
    label per object), ``sum p (log(p + eps) - log(q + eps))`` over the categories of both."""
    cats = sorted(set(real) | set(generated))
    count: Callable[[Sequence[L]], np.ndarray] = lambda labels: np.array([Counter(labels)[c] for c in cats], dtype=float)
    return category_kl_counts(count(real), count(generated), eps)


def category_kl_counts(real: np.ndarray, generated: np.ndarray, eps: float = 1e-6) -> float:
    """:func:`category_kl` from two category count vectors ``(c,)`` over the same categories (only those of either
    set count)."""
    keep = (real > 0) | (generated > 0)
    if not keep.any():
        return 0.0
    p, q = real[keep] / max(real.sum(), 1), generated[keep] / max(generated.sum(), 1)
    return float(np.sum(p * (np.log(p + eps) - np.log(q + eps))))


def count_distance(real: Sequence[int], generated: Sequence[int]) -> float:
    """Total variation distance (0: same, 1: disjoint) between the rooms' object-count distributions."""
    if not len(real) or not len(generated):
        return 1.0
    support = sorted(set(real) | set(generated))
    return float(0.5 * np.abs(_frequencies(real, support) - _frequencies(generated, support)).sum())


def _frequencies(values: Sequence[int], support: list[int]) -> np.ndarray:
    counts = Counter(values)
    total = max(sum(counts.values()), 1)
    return np.array([counts[v] / total for v in support], dtype=float)


def sampling_floor(pool: Sequence[P], sizes: tuple[int, int], distance: Callable[[list[P], list[P]], float], repeats: int,
                   seed: int) -> dict[str, Any]:
    """The distance between two disjoint random sets of ``pool`` rooms of ``sizes`` (shrunk in proportion when the
    pool is smaller than their sum), mean and sd over ``repeats`` draws. ``distance`` takes the two lists."""
    a, b = _split_sizes(len(pool), sizes)
    if a == 0 or b == 0:
        return {"mean": float("nan"), "sd": float("nan"), "sizes": [a, b], "repeats": 0}
    rng = rng_for(seed, "sampling-floor")
    values = []
    for _ in range(repeats):
        perm = rng.permutation(len(pool))
        values.append(distance([pool[i] for i in perm[:a]], [pool[i] for i in perm[a:a + b]]))
    return {"mean": float(np.mean(values)), "sd": float(np.std(values)), "sizes": [a, b], "repeats": repeats}


def _split_sizes(n: int, sizes: tuple[int, int]) -> tuple[int, int]:
    a, b = sizes
    if a + b <= n:
        return a, b
    a2 = int(n * a / max(a + b, 1))
    return a2, n - a2


def flatten(rooms: Sequence[Sequence[str]]) -> list[str]:
    """One category label per object over rooms given as category lists."""
    return [c for room in rooms for c in room]


def cooccurrence(rooms: Sequence[Sequence[str]], categories: list[str]) -> np.ndarray:
    """``(c, c)`` GRAINS's conditional co-occurrence ``P(c1 | c2) = N(c1, c2) / N(c2)`` over ``rooms`` (each a list
    of categories): the share of the rooms holding ``c2`` that also hold ``c1`` (row c1, column c2; 0 where no room
    holds c2)."""
    index = {c: k for k, c in enumerate(categories)}
    has = np.zeros((len(rooms), len(categories)))
    for i, r in enumerate(rooms):
        has[i, [index[c] for c in set(r) if c in index]] = 1.0
    both, single = has.T @ has, has.sum(0)
    return cast(np.ndarray, np.divide(both, single[None, :], out=np.zeros_like(both), where=single[None, :] > 0))


def cooccurrence_similarity(train: Sequence[Sequence[str]], rooms: Sequence[Sequence[str]], min_share: float) -> float:
    """GRAINS's co-occurrence similarity (supplement section 2): the mean over pairs of distinct categories held by at
    least ``min_share`` of the training rooms of ``1 - |P_train(c1 | c2) - P_set(c1 | c2)|`` (NaN for no room or no
    such pair)."""
    counts = {c: sum(c in set(r) for r in train) for c in {c for r in train for c in r}}
    cats = sorted(c for c, n in counts.items() if n >= min_share * max(len(train), 1))
    if not rooms or len(cats) < 2:
        return float("nan")
    diff = np.abs(cooccurrence(train, cats) - cooccurrence(rooms, cats))
    off = ~np.eye(len(cats), dtype=bool)
    return float(1.0 - diff[off].mean())
