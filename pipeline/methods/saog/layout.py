"""The S-AOG method: rooms sampled from the grammar learned by rule ``learn_program`` (or a user's own: ``planit
generate --method saog --program FILE``) into each held-out room's architecture."""
from __future__ import annotations

from pathlib import Path
from typing import Iterator

import numpy as np
import yaml

from ...errors import InputError
from ..interface import Scene, Task
from ..placing import load_context
from ..solver.harness import solve_rooms
from .potentials import POTENTIALS
from .sample import sample_room


def load_grammar(path: Path, room_type: str) -> dict:
    """A grammar file; errors name the file and the missing or wrong field."""
    try:
        grammar = yaml.load(Path(path).read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))  # libyaml: 10x
    except (OSError, yaml.YAMLError) as exc:
        raise InputError(f"{path}: not a readable grammar ({exc})") from None
    if not isinstance(grammar, dict):
        raise InputError(f"{path}: a grammar is a mapping")
    for key in ("room_type", "categories", "groups", "affordance", "weights"):
        if key not in grammar:
            raise InputError(f"{path}: {key}: missing")
    if grammar["room_type"] != room_type:
        raise InputError(f"{path}: room_type: '{grammar['room_type']}', the task's is '{room_type}'")
    missing = [p for p in POTENTIALS if p not in grammar["weights"]]
    if missing:
        raise InputError(f"{path}: weights: no weight for {', '.join(missing)}")
    for c, node in grammar["categories"].items():
        if not isinstance(node, dict) or "count" not in node:
            raise InputError(f"{path}: categories.{c}.count: missing")
    return grammar


class SaogLayout:
    """Samples ``saog.scenes`` rooms per room type from the grammar ``task.program``."""

    def __init__(self, config: dict, name: str):
        self.config, self.name, self.cfg = config, name, config["saog"]
        self.info = {"preset": self.cfg["preset"], "steps": self.cfg["presets"][self.cfg["preset"]]["steps"],
                     "schedule": self.cfg["schedule"]}

    def generate(self, task: Task) -> Iterator[Scene]:
        if task.program is None:
            raise InputError(f"method {self.name}: no grammar given (--program FILE)")
        grammar = load_grammar(task.program, task.corpus.room_type)
        ctx = load_context(self.config, task.corpus)
        grammar["categories"] = {c: n for c, n in grammar["categories"].items() if ctx.pool.has(c)}
        steps = self.cfg["presets"][self.cfg["preset"]]["steps"]

        def solve_one(state, hard, rng: np.random.Generator):
            return sample_room(grammar, grammar["weights"], state, hard, ctx.pool, self.cfg, steps, rng)

        yield from solve_rooms(self.config, task, self.name, task.count or self.cfg["scenes"], solve_one)
