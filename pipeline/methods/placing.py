"""What every layout generator that places objects with the project's placement checks shares (PlanIT's search, the
string method's assembly): the context of one room type's scenes (model pool, checker, learned support shares) and
a searched scene as a :class:`~pipeline.methods.interface.Scene` with its search counts and
graph consistency. No torch."""
from __future__ import annotations

import json
import logging
from dataclasses import dataclass, field

import numpy as np

from .. import tables
from ..geometry.raycast import intersector_class
from ..placement import scene_metrics
from ..placement.checks import Checker, checks_config
from ..placement.plan import ScenePlan
from ..placement.retrieval import ModelPool
from ..placement.support import learn_support_floor
from ..placement.walkable import FloorKept
from ..placement.walls import learn_wall_bound
from .interface import Corpus, Scene

log = logging.getLogger("planit.instantiate")


@dataclass
class Context:
    """Everything the scenes of one room type share."""
    corpus: Corpus
    pool: ModelPool
    checker: Checker
    mean_area: dict
    partners: dict = field(default_factory=dict)  # facing partners the search orders by (facing_first); {}: PlanIT's order


def load_context(config: dict, corpus: Corpus, wall_bound_share: float = 0.0, walkable: bool = False) -> Context:
    """The room type's model pool, checker (with the support shares learned from the training rooms and, for PlanIT's
    search, the categories it keeps at their planned walls: ``wall_bound_share``, its ``instantiate.wall_bound_share``;
    0: none, for the methods with placements of their own; and with ``walkable`` the least walkable share a floor
    object may leave, :mod:`pipeline.placement.walkable`) and mean areas."""
    sym_rows = tables.read(corpus.symmetry, "symmetry", columns=["model_id", "symmetry"]).to_pylist()
    sym = {r["model_id"]: r["symmetry"] for r in sym_rows}
    sizes = tables.read(corpus.category_sizes, "category_sizes").to_pandas()
    sizes = sizes[sizes["room_type"].astype(str) == corpus.room_type]
    ext = {**config["extract"], "floor_contact": config["floor_contact"]}
    training = corpus.training()
    checks = checks_config(config)
    floor = learn_support_floor(training, checks, config["floor_contact"])
    bound: frozenset[str] = frozenset()
    if wall_bound_share > 0:
        snap = config["instantiate"]["snap"]
        bound = learn_wall_bound(training, snap["wall_back_gap"], np.radians(snap["wall_back_angle"]),
                                 wall_bound_share, snap["centre_min_pairs"], config["floor_contact"])
    # the evaluation's walkability measure (evaluate.walk: a key of PlanIT's search only, builtin.search_keys)
    kept = FloorKept.learn(training, config["evaluate"]["walk"], checks["walkable"]) if walkable else None
    checker = Checker(corpus.meshes, corpus.box_models, sym, ext, intersector_class(ext["backend"]), checks, floor,
                      bound, floor_kept=kept)
    if floor:
        log.info("%s: support shares learned from the training rooms: %s", corpus.room_type, floor)
    if bound:
        log.info("%s: categories kept at their planned walls: %s", corpus.room_type, sorted(bound))
    if kept:
        log.info("%s: a floor object may not leave less than %.3f of the free floor connected to a door",
                 corpus.room_type, kept.least)
    objs = corpus.objects
    pool = ModelPool(objs[~objs["room_id"].isin(set(corpus.ids("heldout")))], sym, config["floor_contact"])
    return Context(corpus, pool, checker, dict(zip(sizes["category"].astype(str), sizes["mean_area"])))


def scene_of(plan: ScenePlan, ctx: Context, outcome, walls) -> Scene:
    """The searched scene with its search counts and graph consistency (the project's extraction judges it)."""
    room = outcome.room
    parents = dict(zip(plan.ids, plan.parent))
    record = {"seconds": outcome.seconds, "planned_objects": len(plan.ids), "placed_objects": len(room.object_ids),
              "insertions": outcome.insertions, "rejections": outcome.rejections, "backtracks": outcome.backtracks,
              "attempts": outcome.attempts, "failures": json.dumps(outcome.failures),
              "drops": json.dumps(outcome.drops), "relaxed_objects": len(outcome.relaxed),
              "relaxed": json.dumps(outcome.relaxed),
              **scene_metrics.consistency(plan, room, walls.ids, ctx.checker, outcome.dropped, outcome.accepted),
              "colliding_objects": scene_metrics.colliding_objects(room, parents, ctx.checker)}
    return Scene(plan.scene_id, plan.room_id, room, walls, outcome.status, outcome.reason, record, plan.edges, parents)
