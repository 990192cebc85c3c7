"""The S-AOG method: rooms sampled from the grammar learned by rule ``learn_program`` (or a user's own: ``planit
generate --method saog --program FILE``) into each held-out room's architecture."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Iterator

import numpy as np
import yaml

from ... import schemas
from ...errors import InputError
from ..interface import Scene, Task
from ..placing import load_context
from ..solver.harness import solve_rooms
from .potentials import POTENTIALS
from .sample import sample_room

_NUMBERS = {"type": "array", "items": {"type": "number", "format": "finite"}}
_LOGNORMAL = {"type": "object", "required": ["mu", "sigma"],
              "properties": {"mu": {"type": "number"}, "sigma": {"type": "number", "exclusiveMinimum": 0},
                             "floor": {"type": "number", "exclusiveMinimum": 0}}}
SCHEMA: dict[str, Any] = {  # what ``learn_program`` writes (``learn.py``) and a user's own grammar must hold
    "type": "object", "required": ["room_type", "categories", "groups", "affordance", "weights"],
    "additionalProperties": False,
    "properties": {
        "room_type": {"type": "string"},
        "categories": {"type": "object", "additionalProperties": {
            "type": "object", "required": ["count"], "additionalProperties": False,
            "properties": {
                "count": {"type": "object", "required": ["values", "probs"], "additionalProperties": False,
                          "properties": {"values": {"type": "array", "minItems": 1,
                                                    "items": {"type": "integer", "minimum": 0}},
                                         "probs": {**_NUMBERS, "minItems": 1}}},
                "size_bandwidth": {**_NUMBERS, "minItems": 3, "maxItems": 3},
                "on": {"type": "string"},
                "wall_distance": _LOGNORMAL,
                "wall_angle": {"type": "object", "required": ["weights", "mu", "kappa"],
                               "properties": {"weights": _NUMBERS, "mu": _NUMBERS, "kappa": _NUMBERS}}}}},
        "groups": {"type": "array", "items": {**_LOGNORMAL, "required": ["hub", "spoke", "mu", "sigma"],
                                              "properties": {**_LOGNORMAL["properties"], "hub": {"type": "string"},
                                                             "spoke": {"type": "string"}}}},
        "affordance": {"type": "object", "properties": {"humans": {"type": "array", "items": {"type": "string"}},
                                                        "extent": {"type": "number", "exclusiveMinimum": 0},
                                                        "maps": {"type": "object"}}},
        "weights": {"type": "object", "required": list(POTENTIALS), "additionalProperties": False,
                    "properties": {p: {"type": "number", "format": "finite"} for p in POTENTIALS}},
    },
}
_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml: 10x


def load_grammar(path: Path, room_type: str) -> dict:
    """A grammar file, valid by :data:`SCHEMA` and of ``room_type``; errors ``<file>:<line>: <field>: <what>``."""
    try:
        text = Path(path).read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not a readable grammar ({exc})") from None
    grammar = schemas.load(text, str(path), _LOADER)
    tree = lambda: schemas.compose(text, str(path), _LOADER)  # noqa: E731  (line numbers, on an error only)
    if isinstance(grammar, dict) and grammar.get("room_type", room_type) != room_type:  # the task's first
        line = schemas.line_of(tree(), ["room_type"])
        raise schemas.fail(str(path), line, "room_type", f"'{grammar['room_type']}', the task's is '{room_type}'")
    schemas.validate(grammar, SCHEMA, str(path), tree, "grammar")
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
            return sample_room(grammar, grammar["weights"], (state, hard), ctx.pool, self.cfg, steps, rng)

        yield from solve_rooms(self.config, task, self.name, task.count or self.cfg["scenes"], solve_one,
                               ctx.checker.support_floor)
