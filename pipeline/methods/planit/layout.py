"""PlanIT's layout generator (paper section 6): graphs placed by the backtracking search with the trained location
and orientation networks. One variant of ``instantiate.variants`` per method (planit and its two sampled-graph
baselines) or per Table 3 ablation (held-out rooms' own graphs)."""
from __future__ import annotations

import json
import logging
import zlib
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Iterator

import numpy as np
import torch

from ... import tables
from ...errors import InputError
from ...geometry.raycast import intersector_class
from ...learning import checkpoint
from ...log import progress
from ...placement import order, proposers, scene_metrics
from ...placement.checks import Checker, checks_config
from ...placement.layout import walls_of, with_objects
from ...placement.plan import ScenePlan, plans_from_tables
from ...placement.poses import PoseRules, describe, learn_pose_rules
from ...placement.support import learn_support_floor
from ...placement.retrieval import ModelPool
from ...placement.search import instantiate
from ..interface import Corpus, Scene, Task
from .nets.proposer import NetProposer
from .nets.train import KIND

log = logging.getLogger("planit.instantiate")


@dataclass
class Context:
    """Everything the scenes of one room type share."""
    corpus: Corpus
    pool: ModelPool
    checker: Checker
    mean_area: dict
    poses: PoseRules | None = None


def load_context(config: dict, corpus: Corpus) -> Context:
    sym_rows = tables.read(corpus.symmetry, "symmetry", columns=["model_id", "symmetry"]).to_pylist()
    sym = {r["model_id"]: r["symmetry"] for r in sym_rows}
    sizes = tables.read(corpus.category_sizes, "category_sizes").to_pandas()
    sizes = sizes[sizes["room_type"].astype(str) == corpus.room_type]
    ext = {**config["extract"], "floor_contact": config["floor_contact"]}
    training = corpus.training()
    checks = checks_config(config)
    floor = learn_support_floor(training, checks, config["floor_contact"])
    checker = Checker(corpus.meshes, corpus.box_models, sym, ext, intersector_class(ext["backend"]), checks, floor)
    if floor:
        log.info("%s: support shares learned from the training rooms: %s", corpus.room_type, floor)
    objs = corpus.objects
    pool = ModelPool(objs[~objs["room_id"].isin(set(corpus.ids("heldout")))], sym, config["floor_contact"])
    rules = config["instantiate"]["pose_rules"]
    poses = learn_pose_rules(training, rules) if rules["enabled"] else None
    if poses is not None:
        log.info("%s: %d pose rules learned from %d training rooms:\n  %s", corpus.room_type,
                 len(poses.turns), len(training), "\n  ".join(describe(poses)))
    return Context(corpus, pool, checker, dict(zip(sizes["category"].astype(str), sizes["mean_area"])), poses)


def make_proposer(location: str, saved, cfg: dict):
    """The variant's proposer: network densities (weighted by the relation bands when ``relation_mask``), uniform or
    rule-band locations; orientations from the network. ``cfg``: the instantiate section."""
    nets = NetProposer(saved, cfg["density_cache"], film=location == "cfcn")
    if location in ("cfcn", "fcn"):
        bands = proposers.RelationPrior(soft=cfg["band_softness"])
        return proposers.Masked(nets, bands) if cfg["relation_mask"] else nets
    return proposers.Combined(proposers.UniformLocation() if location == "random" else proposers.RelationPrior(), nets)


def place_scene(plan: ScenePlan, ctx: Context, proposer, cfg: dict, variant: dict, seed: int, keep: int = 0):
    """Search one scene. ``keep``: the first objects of the constraint order stay where the source room has them
    (completion of a real room)."""
    source = ctx.corpus.inputs.get(plan.room_id)
    if source is None:
        raise InputError(f"scene {plan.scene_id}: its room {plan.room_id} is not among the kept rooms of "
                         f"{ctx.corpus.room_type}")
    rng = np.random.default_rng(seed)
    seq = order.placement_order(plan, ctx.mean_area, variant["ordering"] == "constraint", rng)
    fixed = [plan.ids[k] for k in seq[:keep]]
    start = with_objects(source, [source.object_ids.index(o) for o in fixed if o in source.object_ids])
    walls = walls_of(start)
    return instantiate(plan, start, walls, seq[keep:], proposer, ctx.pool, ctx.checker, cfg, seed, ctx.poses), walls


def scene_of(plan: ScenePlan, ctx: Context, outcome, walls) -> Scene:
    """The searched scene with its search counts and graph consistency (the project's extraction judges it)."""
    room = outcome.room
    parents = dict(zip(plan.ids, plan.parent))
    record = {"seconds": outcome.seconds, "planned_objects": len(plan.ids), "placed_objects": len(room.object_ids),
              "insertions": outcome.insertions, "rejections": outcome.rejections, "backtracks": outcome.backtracks,
              "attempts": outcome.attempts, "failures": json.dumps(outcome.failures),
              "drops": json.dumps(outcome.drops),
              **scene_metrics.consistency(plan, room, walls.ids, ctx.checker, outcome.dropped, outcome.accepted),
              "colliding_objects": scene_metrics.colliding_objects(room, parents, ctx.checker)}
    return Scene(plan.scene_id, plan.room_id, room, walls, outcome.status, outcome.reason, record, plan.edges, parents)


def select_plans(config: dict, variant: dict, corpus: Corpus, nodes: Path, edges: Path, count: int) -> list[ScenePlan]:
    flt = [("room_type", "=", corpus.room_type)]
    if variant["graphs"] == "sampled":
        node_df = tables.read(nodes, "generated_nodes", filters=flt).to_pandas()
        edge_df = tables.read(edges, "generated_edges", filters=flt).to_pandas()
    else:
        held = [("room_id", "in", corpus.ids("heldout"))]
        node_df = tables.read(nodes, "final_nodes", filters=flt + held).to_pandas()
        edge_df = tables.read(edges, "final_edges", filters=flt + held).to_pandas()
    return plans_from_tables(node_df, edge_df, variant["pruning"], config["seed"], limit=count)


def scene_count(ic: dict, variant: dict) -> int:
    """Scenes a variant places: ``scenes`` for sampled graphs, ``table3_scenes`` for held-out ones, capped by the
    variant's own ``scenes`` (``ic``: the ``instantiate`` config section)."""
    n = ic["scenes"] if variant["graphs"] == "sampled" else ic["table3_scenes"]
    return min(n, variant.get("scenes", n))


class PlanitLayout:
    """The search of one ``instantiate.variants`` entry (``name``); ``task.graphs``: sampled graphs, or the corpus's
    final graphs (held-out rooms' own graphs, Table 3)."""

    def __init__(self, config: dict, name: str):
        ic = config["instantiate"]
        if name not in ic["variants"]:
            raise InputError(f"'{name}' is not in instantiate.variants ({', '.join(ic['variants'])})")
        self.config, self.name, self.variant = config, name, ic["variants"][name]
        self.info = dict(self.variant)

    def generate(self, task: Task) -> Iterator[Scene]:
        torch.set_num_threads(task.threads)
        saved = checkpoint.load(task.model, KIND)
        ctx = load_context(self.config, task.corpus)
        plans = select_plans(self.config, self.variant, task.corpus, *task.graphs,
                             task.count or scene_count(self.config["instantiate"], self.variant))
        if not plans:
            log.warning("%s: no graph of room type '%s' to place: writing empty tables", task.graphs[0],
                        task.corpus.room_type)
        proposer = make_proposer(self.variant["location"], saved, self.config["instantiate"])
        for plan in progress(plans, total=len(plans), desc=f"instantiate {task.corpus.room_type} ({self.name})"):
            seed = zlib.crc32(f"{self.config['seed']}/{self.name}/{plan.scene_id}".encode())
            outcome, walls = place_scene(plan, ctx, proposer, self.config["instantiate"], self.variant, seed)
            yield scene_of(plan, ctx, outcome, walls)


class CompleteRoom:
    """Completion of a real room: its first ``keep`` objects (of the constraint order) stay where they are, the search
    places the rest of its final graph (the held-out graphs' variant)."""

    def __init__(self, config: dict, room: str, keep: int):
        self.config, self.room, self.keep = config, room, keep
        self.variant = config["instantiate"]["variants"]["heldout"]
        self.info = {"room": room, "keep": keep, **self.variant}

    def generate(self, task: Task) -> Iterator[Scene]:
        torch.set_num_threads(task.threads)
        flt = [("room_id", "=", self.room)]
        nodes = tables.read(task.graphs[0], "final_nodes", filters=flt).to_pandas()
        if nodes.empty or self.room not in task.corpus.inputs:
            raise InputError(f"{task.graphs[0]}: no room '{self.room}' among the kept {task.corpus.room_type} rooms")
        edges = tables.read(task.graphs[1], "final_edges", filters=flt).to_pandas()
        plan = replace(plans_from_tables(nodes, edges)[0], scene_id=f"{self.room}_keep{self.keep}")
        if not 0 <= self.keep <= len(plan.ids):
            raise InputError(f"keep: {self.keep}, but room {self.room} has {len(plan.ids)} objects")
        saved = checkpoint.load(task.model, KIND)
        ctx = load_context(self.config, task.corpus)
        proposer = make_proposer("cfcn", saved, self.config["instantiate"])
        seed = zlib.crc32(f"{self.config['seed']}/complete/{plan.scene_id}".encode())
        outcome, walls = place_scene(plan, ctx, proposer, self.config["instantiate"], self.variant, seed, self.keep)
        yield scene_of(plan, ctx, outcome, walls)
