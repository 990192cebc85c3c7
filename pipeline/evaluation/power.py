"""The classifier's power check: before the real-vs-synthetic classifier scores any method, the same protocol scores
known-bad sets made from the held-out real rooms (``perturb.py``) and a real-vs-real control (training rooms held
back from the classifier's real class and scored as the other set). The check passes when every required
perturbation is detected with at least ``min_accuracy`` and the control stays within ``null_tolerance`` of 50%;
a method's SCA is only read against its goal when it passes (otherwise: inconclusive)."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..room import RoomInput
from ..seeding import rng_for
from .perturb import perturbed

CONTROL = "real_vs_real"


def perturbation_name(spec: dict[str, Any]) -> str:
    """``jitter_0.1``, ``turns``, ...: a power set's name."""
    return f"{spec['kind']}_{spec['strength']:g}" if spec["kind"] == "jitter" else spec["kind"]


def power_sets(real: list[RoomInput], cfg: dict[str, Any], seed: int) -> dict[str, tuple[list[RoomInput], np.ndarray]]:
    """``name -> (rooms, groups)``: ``cfg['copies']`` perturbed copies of every held-out real room per perturbation
    of ``cfg['perturbations']`` (a room's copies share a group, so they land in the same fold)."""
    groups = np.repeat(np.arange(len(real)), cfg["copies"])
    return {perturbation_name(p): (perturbed(real, p["kind"], p.get("strength", 0.0), cfg["copies"], seed), groups)
            for p in cfg["perturbations"]}


def control_split(rooms: int, size: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the training rooms kept in the classifier's real class and of ``size`` held back (at most half)."""
    perm = rng_for(seed, "power-control").permutation(rooms)
    back = min(size, rooms // 2)
    return np.sort(perm[back:]), np.sort(perm[:back])


def verdict(scores: dict[str, dict[str, Any]], cfg: dict[str, Any]) -> dict[str, Any]:
    """Whether the power check passes: each required perturbation's accuracy and the control's distance from 50%."""
    required = {perturbation_name(p) for p in cfg["perturbations"] if p.get("required")}
    misses = [n for n in sorted(required) if not scores[n]["accuracy"] >= cfg["min_accuracy"]]
    control = scores[CONTROL]["accuracy"]
    null_ok = bool(abs(control - 50.0) <= cfg["null_tolerance"])
    return {"passed": bool(not misses and null_ok), "required": sorted(required), "missed": misses,
            "control_within_tolerance": null_ok, "min_accuracy": cfg["min_accuracy"],
            "null_tolerance": cfg["null_tolerance"]}
