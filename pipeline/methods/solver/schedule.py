"""Temperature schedules of the annealers (``solver.schedule`` in the config): Infinigen's exponential cooling (the
paper: 0.25 -> 0.001; the released code starts at 3 and holds the final temperature for the last ``finetune``
share of the steps), S-AOG's logarithmic ``T0 / ln(1 + t)`` (supplement section 8) and the stepwise cooling of its
released code (``T0 x 0.9`` every 100 steps), and a constant temperature (tests, sampling at equilibrium)."""
from __future__ import annotations

import numpy as np

from ...errors import InputError

KINDS = ("exponential", "logarithmic", "stepwise", "constant")


def temperature(cfg: dict, t: int, steps: int) -> float:
    """The temperature at step ``t`` of ``steps`` (``cfg``: kind and its constants)."""
    kind = cfg["kind"]
    if kind == "exponential":
        cool = max(int(round(steps * (1 - cfg["finetune"]))), 1)
        r = (cfg["tf"] / cfg["t0"]) ** (1 / cool)
        return float(cfg["t0"] * r ** min(t, cool))
    if kind == "logarithmic":
        return float(cfg["t0"] / np.log(2 + t))  # t counts from 0: ln(1 + (t + 1))
    if kind == "stepwise":
        return float(cfg["t0"] * cfg["factor"] ** (t // cfg["every"]))
    if kind == "constant":
        return float(cfg["t0"])
    raise InputError(f"solver schedule kind '{kind}': one of {', '.join(KINDS)}")


def move_weights(start: dict, end: dict, t: int, steps: int) -> dict:
    """Each move's weight at step ``t``: linear from ``start`` to ``end`` over the steps (Infinigen's released code:
    discrete moves fade, continuous ones stay)."""
    f = t / max(steps - 1, 1)
    return {k: (1 - f) * start[k] + f * end.get(k, start[k]) for k in start}
