"""What a room type's rooms hold, learned from training rooms' category lists: each category's largest count in one
room, and the categories (nearly) every room holds. One implementation for the evaluation's plausibility check
and every generator that keeps its rooms plausible. A share counts as "nearly every" when the Wilson 95% lower bound
of the rooms' share is at least ``min_share``."""
from __future__ import annotations

from collections import Counter
from typing import Any, Iterable

import numpy as np


def wilson_lower(passed: int, total: int, z: float = 1.96) -> float:
    """The Wilson score interval's lower bound of a share ``passed / total`` (0 for no trials)."""
    if total == 0:
        return 0.0
    p = passed / total
    centre = p + z * z / (2 * total)
    return float((centre - z * np.sqrt(p * (1 - p) / total + z * z / (4 * total * total))) / (1 + z * z / total))


def learn_contents(rooms: Iterable[Iterable[str]], min_share: float) -> dict[str, Any]:
    """From each training room's object categories: ``max_count`` (category -> its largest count in one room) and
    ``required`` (the sorted categories whose share of rooms is confidently >= ``min_share``)."""
    counts = [Counter(r) for r in rooms]
    cats = sorted({c for k in counts for c in k})
    required = [c for c in cats if wilson_lower(sum(c in k for k in counts), len(counts)) >= min_share]
    return {"max_count": {c: max(k[c] for k in counts) for c in cats}, "required": required}


def implausible(categories: Iterable[str], contents: dict[str, Any]) -> tuple[list[str], list[str]]:
    """The categories a room holds more often than any training room (or never seen), and the required ones it
    lacks."""
    counts = Counter(categories)
    excess = sorted(c for c, n in counts.items() if n > contents["max_count"].get(c, 0))
    return excess, [c for c in contents["required"] if c not in counts]
