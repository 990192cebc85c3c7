"""A solved chain as a generated scene: objects still in a hard violation are left out (recorded, as PlanIT's search
records what it drops), and the scene's record carries the solver's figures and its energy trace."""
from __future__ import annotations

import json

from ..interface import Scene
from .anneal import Chain
from .moves import drop_items
from .state import State
from .terms import Hard


def violators(state: State, hard: Hard) -> list[int]:
    """Items in a hard violation: the later item of the first colliding pair, else the first item outside the floor,
    in a door zone or overhanging (the caller drops the first and asks again)."""
    found = hard.offenders(state)
    if found["collision"]:
        return found["collision"][:1]
    rest = sorted({k for kind in ("outside", "door", "overhang") for k in found[kind]})
    return rest[:1]


def repaired(state: State, hard: Hard) -> tuple[State, list[dict]]:
    """The state without the objects in hard violations, and what was dropped (id, category, cause)."""
    drops: list[dict] = []
    while True:
        bad = violators(state, hard)
        if not bad:
            return state, drops
        it = state.items[bad[0]]
        drops.append({"id": it.object_id, "category": it.category, "cause": "violation", "check": None})
        state = state.with_items(drop_items(state.items, bad[0]))


def solved_scene(chain: Chain, hard: Hard, scene_id: str, room_id: str, seconds: float, trace_every: int = 1) -> Scene:
    """The chain's best state as a scene (``placed``, or ``partial`` when objects were left out)."""
    state, drops = repaired(chain.best, hard)
    parents = {it.object_id: state.items[it.parent].object_id if it.parent >= 0 else None for it in state.items}
    record = {"seconds": seconds, "planned_objects": len(chain.best.items), "insertions": chain.accepted,
              "rejections": chain.proposed - chain.accepted, "backtracks": 0, "attempts": 1,
              "drops": json.dumps(drops), "violations": chain.best_score[0], "energy": chain.best_score[1],
              "energy_trace": json.dumps(chain.trace[::trace_every])}
    status = "partial" if drops else "placed"
    reason = f"left out {len(drops)} objects in a hard violation" if drops else None
    return Scene(scene_id, room_id, state.as_room(), state.walls, status, reason, record, [], parents)
