"""Set figures from per-room rows, with bootstrap 95% intervals: every set's rooms (and the held-out real rooms they
are compared with) resampled with replacement together, the figures recomputed per replicate; the difference of
every set from a reference set (PlanIT, the real rooms) taken per replicate, so its interval says whether the
difference is more than the noise of the sample sizes. Pure NumPy and pandas."""
from __future__ import annotations

from collections.abc import Callable, Sequence, Sized
from typing import Any, TypeVar

import numpy as np
import pandas as pd

from ..seeding import rng_for
from .distributions import category_kl_counts, count_distance

CATEGORY = "cat:"  # prefix of the per-room category count columns
S = TypeVar("S", bound=Sized)
R = TypeVar("R")


def _mean(frame: pd.DataFrame, column: str) -> float:
    values = frame[column].to_numpy(float) if column in frame else np.zeros(0)
    values = values[np.isfinite(values)]
    return float(values.mean()) if len(values) else float("nan")


def figures(rows: pd.DataFrame, real: pd.DataFrame, eps: float, extra: list[str]) -> dict[str, float]:
    """The set figures of one set's per-room ``rows`` against the real rooms' ``real`` rows: the distribution
    distances, collision, bounds and walkability rates, and the mean of every ``extra`` column (NaN ignored)."""
    cats = [c for c in rows.columns if c.startswith(CATEGORY)]
    objects = max(float(rows["objects"].sum()), 1.0)
    scenes = len(rows)
    none = float("nan")  # a set with no room has no distribution to compare
    out = {
        "category_kl": category_kl_counts(real[cats].to_numpy(float).sum(0), rows[cats].to_numpy(float).sum(0), eps)
        if scenes else none,
        "count_distance": count_distance(real["objects"].tolist(), rows["objects"].tolist()) if scenes else none,
        "object_collision_rate": float(rows["colliding_objects"].sum()) / objects,
        "scene_collision_rate": float((rows["colliding_objects"] > 0).mean()) if scenes else float("nan"),
        "out_of_bounds_rate": float(rows["out_of_bounds"].sum()) / objects,
        "walkable_share": _mean(rows, "walkable_share"),
        "reachable_scenes": float((rows["reachable"] >= 1.0).mean()) if scenes else float("nan"),
    }
    return out | {c: _mean(rows, c) for c in extra}


def replicates(samples: Sequence[S], stat: Callable[[list[Any]], R], repeats: int, rng: np.random.Generator,
               take: Callable[[S, np.ndarray], Any]) -> list[R]:
    """``repeats`` bootstrap values of ``stat(picks)``: in each replicate every one of ``samples`` resampled with
    replacement, in order (an empty one stays as it is, drawing nothing). ``take(sample, index)``: its items at an
    index array (rows of a frame; the groups of a list, concatenated, to resample by group)."""
    return [stat([take(s, rng.integers(len(s), size=len(s))) if len(s) else s for s in samples])
            for _ in range(repeats)]


def bootstrap(sets: dict[str, pd.DataFrame], real: str, stat: Callable[[pd.DataFrame, pd.DataFrame], dict[str, Any]],
              repeats: int, seed: int) -> dict[str, pd.DataFrame]:
    """``repeats`` replicates of ``stat(rows, real_rows)`` per set (a frame per set: one row per replicate, one
    column per figure), every set and the real rooms resampled independently in each replicate."""
    names = list(sets)

    def per_set(picks: list[pd.DataFrame]) -> list[dict[str, Any]]:
        return [stat(p, picks[names.index(real)]) for p in picks]

    reps = replicates(list(sets.values()), per_set, repeats, rng_for(seed, "bootstrap"), lambda f, k: f.iloc[k])
    return {name: pd.DataFrame([r[i] for r in reps]) for i, name in enumerate(names)}


def interval(values: pd.Series) -> tuple[float, float]:
    """The 2.5th and 97.5th percentiles of the finite values (NaN, NaN if none)."""
    v = values.to_numpy(float)
    v = v[np.isfinite(v)]
    return (float(np.percentile(v, 2.5)), float(np.percentile(v, 97.5))) if len(v) else (float("nan"), float("nan"))


def intervals(reps: dict[str, pd.DataFrame]) -> dict[str, dict[str, list[float]]]:
    """``set -> figure -> [low, high]``."""
    return {name: {col: list(interval(frame[col])) for col in frame.columns} for name, frame in reps.items()}


RELATIVE = ("category_kl", "count_distance")  # distances to the real rooms: no difference taken with the real set


def _span(lo: float, hi: float, enough: bool) -> dict[str, Any]:
    """A difference's interval; it excludes zero only where both sets hold enough rooms."""
    return {"low": lo, "high": hi, "excludes_zero": bool(enough and (lo > 0 or hi < 0))}


def differences(reps: dict[str, pd.DataFrame], reference: str, sizes: dict[str, int], min_rooms: int,
                real: str) -> dict[str, dict[str, dict[str, Any]]]:
    """``set -> figure -> {low, high, excludes_zero}``: each set's replicate figures minus the reference set's;
    ``excludes_zero`` only where both sets hold at least ``min_rooms`` rooms (``sizes``: rooms per set), since a
    handful of rooms resamples to a degenerate interval. The :data:`RELATIVE` figures are left out wherever the
    ``real`` set is one side (its distance to itself is 0 by definition; they sit beside the sampling floor)."""
    out: dict[str, dict[str, dict[str, Any]]] = {}
    for name, frame in reps.items():
        if name == reference:
            continue
        diff = frame - reps[reference]
        enough = min(sizes[name], sizes[reference]) >= min_rooms
        columns = [c for c in frame.columns if real not in (name, reference) or c not in RELATIVE]
        out[name] = {col: _span(*interval(diff[col]), enough) for col in columns}
    return out
