"""The Infinigen-style method: one constraint program per room type (derived from the training split by rule
``learn_program``, or a user's own: ``planit generate --method infinigen --program FILE``) solved by the staged
annealer in each held-out room's architecture."""
from __future__ import annotations

import logging
from dataclasses import replace
from typing import Iterator

import numpy as np

from ...errors import InputError
from ...room.walkability import Walk
from ..interface import Scene, Task
from ..placing import load_context
from ..solver.anneal import solve
from ..solver.harness import majority_symmetry, solve_rooms, steps_of
from ..solver.moves import Proposer
from ..solver.terms import Energy
from .energy import specs_of, terms_of
from .program import load_program

log = logging.getLogger("planit.infinigen")


class InfinigenLayout:
    """Solves ``infinigen.scenes`` scenes per room type with the program ``task.program``."""

    def __init__(self, config: dict, name: str):
        self.config, self.name, self.cfg = config, name, config["infinigen"]
        self.info = {"preset": self.cfg["preset"], "steps": self.cfg["presets"][self.cfg["preset"]],
                     "schedule": self.cfg["schedule"]}

    def generate(self, task: Task) -> Iterator[Scene]:
        if task.program is None:
            raise InputError(f"method {self.name}: no constraint program given (--program FILE)")
        program = load_program(task.program)
        if program.room_type != task.corpus.room_type:
            raise InputError(f"{task.program}: room_type is '{program.room_type}', the task's is "
                             f"'{task.corpus.room_type}'")
        ctx = load_context(self.config, task.corpus)
        specs = specs_of(program, ctx.pool, {c: majority_symmetry(ctx.pool, c) for c in program.objects})
        missing = sorted(set(program.objects) - set(specs))
        if missing:
            log.warning("%s: no training instance of %s: left out of the program", task.program, ", ".join(missing))
        walk = replace(Walk.of(self.config["evaluate"]["walk"]), cell=self.cfg["free_floor_cell"])
        solver_cfg = {"schedule": self.cfg["schedule"], "moves": self.cfg["moves"],
                      "steps": self.cfg["presets"][self.cfg["preset"]]}

        def solve_one(state, hard, rng: np.random.Generator):
            counts = program.counts(rng)  # a recipe's contents as a whole, or each rule's range
            scene = {c: replace(s, count=counts[c]) for c, s in specs.items()}
            energy = Energy(hard, terms_of(program, self.cfg["reach"], walk))
            proposer = Proposer(scene, ctx.pool, steps_of(self.cfg), violations=hard.total, attempts=self.cfg["attempts"])
            return solve(state, scene, energy, proposer, solver_cfg, rng)

        yield from solve_rooms(self.config, task, self.name, task.count or self.cfg["scenes"], solve_one,
                               ctx.checker.support_floor)
