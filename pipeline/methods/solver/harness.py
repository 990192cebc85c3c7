"""What the annealing methods share around the solver: the hard limits and step sizes from the config, the rooms a
method generates into (the held-out architectures, in turn) and the loop that solves one scene per room."""
from __future__ import annotations

import time
from typing import Callable, Iterator

import numpy as np

from ...log import progress
from ...placement.layout import walls_of
from ...placement.retrieval import ModelPool
from ...seeding import seed_of
from ..interface import Scene, Task
from .anneal import Chain
from .moves import Steps
from .scene import solved_scene
from .state import State, empty_state
from .terms import Hard, Limits


def limits_of(config: dict, support_floor: dict[str, float] | None = None) -> Limits:
    """The hard constraints' thresholds: PlanIT's placement checks' (``instantiate.checks``), with the support
    shares its checker learned from the training rooms (``support_floor``: category -> share; televisions wider
    than their stands)."""
    c = config["instantiate"]["checks"]
    return Limits(c["collision"], c["outside"], c["door_clearance"], c["min_support"], dict(support_floor or {}))


def steps_of(cfg: dict) -> Steps:
    s = cfg["step"]
    return Steps(s["scale"], s["least"], s["most"], np.deg2rad(s["quantum"]))


def majority_symmetry(pool: ModelPool, category: str) -> str:
    """The symmetry most of the category's training instances have (the one retrieval prefers)."""
    syms = pool.sym.get(category, ["none"])
    return max(sorted(set(syms)), key=syms.count)


def solve_rooms(config: dict, task: Task, name: str, count: int,
                solve_one: Callable[[State, Hard, np.random.Generator], Chain],
                support_floor: dict[str, float] | None = None) -> Iterator[Scene]:
    """One scene per held-out room in turn, ``count`` in all: ``solve_one(empty state, hard, rng)`` anneals it
    (``support_floor``: the checker's learned support shares, :func:`limits_of`)."""
    rooms = task.corpus.heldout()
    limits = limits_of(config, support_floor)
    for i in progress(range(count if rooms else 0), total=count, desc=f"{name} {task.corpus.room_type}"):
        room = rooms[i % len(rooms)]
        scene_id = f"gen_{task.corpus.room_type}_{i:05d}"
        rng = np.random.default_rng(seed_of(config["seed"], name, scene_id))
        state = empty_state(room, walls_of(room))
        hard = Hard(state, limits)
        start = time.perf_counter()
        chain = solve_one(state, hard, rng)
        yield solved_scene(chain, hard, scene_id, room.room_id, time.perf_counter() - start)
