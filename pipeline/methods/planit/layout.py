"""PlanIT's layout generator (paper section 6): graphs placed by the backtracking search with the trained location
and orientation networks. One variant of ``instantiate.variants`` per method (planit and its two sampled-graph
baselines) or per Table 3 ablation (held-out rooms' own graphs)."""
from __future__ import annotations

import logging
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Iterator

import numpy as np
import torch

from ... import tables
from ...errors import InputError
from ...learning import checkpoint
from ...log import progress
from ...placement import order, proposers
from ...placement.facing import learn_anchor_facing, learn_facing_partners, learn_partner_distances
from ...placement.layout import walls_of, with_objects
from ...placement.plan import ScenePlan, plans_from_tables
from ...placement.prior import KIND as PRIOR_KIND, PosePrior
from ...placement.search import Kit, instantiate
from ...placement.support import Window, learn_centring
from ...placement.turns import learn_support_turns
from ...placement.walls import learn_wall_backs
from ...seeding import seed_of
from ...tables import SCORED
from ..interface import Corpus, Scene, Task
from ..placing import Context, load_context, scene_of
from .nets.proposer import NetProposer
from .nets.train import KIND

log = logging.getLogger("planit.instantiate")


@dataclass(frozen=True)
class PoseRules:
    """What the training rooms say about poses beyond the proposer's draw: centre-line and back-edge rules per
    (anchor, object, kind) (:func:`~pipeline.placement.support.learn_centring`) and per category the share of
    objects against a wall that have their back to it (:func:`~pipeline.placement.walls.learn_wall_backs`); per
    (partner, object) category the share of objects facing a partner (:func:`~pipeline.placement.facing.
    learn_facing_partners`) and of objects near an anchor facing it (:func:`~pipeline.placement.facing.
    learn_anchor_facing`); per (support, object) category the quarter turns and residual turns of objects on a
    support (:func:`~pipeline.placement.turns.learn_support_turns`); per (partner, object) category how near the
    objects facing a partner stand to it (:func:`~pipeline.placement.facing.learn_partner_distances`)."""
    centring: dict = field(default_factory=dict)
    wall_backs: dict = field(default_factory=dict)
    partners: dict = field(default_factory=dict)
    anchor_facing: dict = field(default_factory=dict)
    support_turns: dict = field(default_factory=dict)
    partner_near: dict = field(default_factory=dict)


def make_proposer(location: str, saved, cfg: dict, extract: dict, rules: PoseRules | None = None):
    """The variant's proposer (``cfg``: its instantiate settings, ``extract``: the extraction's): the pose networks
    (their densities weighted by the relation bands when ``relation_mask``), the relative-pose prior (likewise), or
    uniform or rule-band locations with the networks' orientations; when the variant snaps, by the training rooms'
    ``rules``, objects planned beside an anchor turned to face it (:class:`~pipeline.placement.proposers.FaceAnchor`)
    or against a wall with their back to it (:class:`~pipeline.placement.proposers.BackToWall`), drawn facing the
    placed objects the training rooms' objects face unplanned (:class:`~pipeline.placement.proposers.FacingPartner`),
    turned on their support as the training rooms' objects are (:class:`~pipeline.placement.proposers.TurnedOnSupport`)
    and put on the centre lines of their supports, planned floor anchors and the placed objects they face
    (:class:`~pipeline.placement.proposers.Centred`)."""
    base = location_proposer(location, saved, cfg, extract)
    if rules is None or not cfg["snap"]["enabled"]:
        return base
    facing = np.radians(cfg["snap"]["centre_facing_angle"])
    if rules.anchor_facing:
        base = proposers.FaceAnchor(base, rules.anchor_facing)
    if rules.wall_backs:
        base = proposers.BackToWall(base, rules.wall_backs)
    if rules.partners:
        base = proposers.FacingPartner(base, rules.partners, facing, cfg["snap"]["partner_tries"], rules.partner_near)
    if rules.support_turns:
        base = proposers.TurnedOnSupport(base, rules.support_turns)
    if rules.centring:
        base = proposers.Centred(base, rules.centring, facing)
    return base


def ordered_by_partners(ctx: Context, rules: PoseRules, cfg: dict) -> Context:
    """``ctx`` with the facing partners the search orders by (:func:`~pipeline.placement.order.facing_first`): the
    training rooms' (``rules.partners``) where the variant snaps and ``snap.partner_first`` (``cfg``: its instantiate
    settings), else none (PlanIT's order)."""
    on = cfg["snap"]["enabled"] and cfg["snap"]["partner_first"]
    return replace(ctx, partners=dict(rules.partners) if on else {})


def search_kit(config: dict, ctx: Context, location: str, saved, settings: dict):
    """(context, proposer): what the search places with in a location mode (``settings``: its instantiate settings):
    ``ctx`` ordered by the training rooms' facing partners (:func:`ordered_by_partners`) and the location proposer
    wrapped by the training rooms' pose rules (:func:`pose_rules`, :func:`make_proposer`)."""
    rules = pose_rules(config, ctx.corpus)
    return ordered_by_partners(ctx, rules, settings), make_proposer(location, saved, settings, config["extract"], rules)


def pose_rules(config: dict, corpus: Corpus) -> PoseRules:
    """The training rooms' pose rules (``instantiate.snap``'s settings): centre lines and back edges of objects on
    supports, beside floor anchors and facing each other; backs to walls; facing partners and anchors; turns on
    supports."""
    snap, floor = config["instantiate"]["snap"], config["floor_contact"]
    training, facing = corpus.training(), np.radians(snap["centre_facing_angle"])
    tolerance = config["instantiate"]["checks"]["learned_support"]["tolerance"]
    window = Window(snap["centre_within"], snap["centre_min_pairs"], snap["centre_concentration"], snap["centre_fraction"])
    rules = PoseRules(
        learn_centring(training, window, tolerance, floor, facing, snap["flush_within"]),
        learn_wall_backs(training, snap["wall_back_gap"], np.radians(snap["wall_back_angle"]), snap["centre_min_pairs"],
                         floor) if snap["wall_back_gap"] > 0 else {},
        learn_facing_partners(training, facing, snap["centre_min_pairs"], snap["facing_min_share"], floor)
        if snap["partner_tries"] else {},
        learn_anchor_facing(training, snap["face_anchor_gap"], facing, snap["centre_min_pairs"], snap["facing_min_share"],
                            floor) if snap["face_anchor_gap"] > 0 else {},
        learn_support_turns(training, tolerance, floor, snap["centre_min_pairs"], snap["support_turn_min_share"])
        if snap["support_turns"] else {},
        learn_partner_distances(training, facing, snap["partner_near_quantile"], floor) if snap["partner_tries"] else {})
    named = lambda rule: {"/".join(key): (tuple(v[:2]) if isinstance(v, tuple) else v) for key, v in rule.items()}
    log.info("%s: pose rules from the training rooms: centre lines and back edges %s; back to the wall %s; facing "
             "partners %s; facing anchors %s; quarter turns on supports %s", corpus.room_type, named(rules.centring),
             rules.wall_backs, named(rules.partners), {"/".join(k): v.share for k, v in rules.anchor_facing.items()},
             {"/".join(k): v.quarters for k, v in rules.support_turns.items()})
    return rules


def location_proposer(location: str, saved, cfg: dict, extract: dict):
    bands = proposers.RelationPrior(extract, soft=cfg["band_softness"], slack=cfg["band_slack"])
    if location == "prior":
        return PosePrior.from_record(saved.record, bands if cfg["relation_mask"] else None)
    nets = NetProposer(saved, cfg["density_cache"], film=location == "cfcn")
    if location in ("cfcn", "fcn"):
        return proposers.Masked(nets, bands) if cfg["relation_mask"] else nets
    return proposers.Combined(proposers.UniformLocation() if location == "random" else bands, nets)


def search_settings(ic: dict, variant: dict) -> dict:
    """The instantiate settings a variant searches with: its own ``search`` values over the section's."""
    own = variant.get("search", {})
    out = {**ic, **{k: v for k, v in own.items() if k != "snap"}}
    if "snap" in own:
        out["snap"] = {**ic["snap"], "enabled": own["snap"]}
    return out


def checkpoint_kind(location: str) -> str:
    return PRIOR_KIND if location == "prior" else KIND


def place_scene(plan: ScenePlan, ctx: Context, proposer, cfg: dict, variant: dict, seed: int, keep: int = 0):
    """Search one scene. ``keep``: the first objects of the constraint order stay where the source room has them
    (completion of a real room)."""
    source = ctx.corpus.inputs.get(plan.room_id)
    if source is None:
        raise InputError(f"scene {plan.scene_id}: its room {plan.room_id} is not among the kept rooms of "
                         f"{ctx.corpus.room_type}")
    rng, walls = np.random.default_rng(seed), walls_of(source)  # the architecture's; the kept objects add none
    first = order.facing_first(plan, ctx.partners, walls)
    seq = order.placement_order(plan, ctx.mean_area, variant["ordering"] == "constraint", rng, first)
    fixed = [plan.ids[k] for k in seq[:keep]]
    start = with_objects(source, [source.object_ids.index(o) for o in fixed if o in source.object_ids])
    return instantiate(plan, start, seq[keep:], proposer, Kit(ctx.pool, ctx.checker), cfg, seed), walls


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
        self.settings = search_settings(ic, self.variant)
        self.info = dict(self.variant)

    def generate(self, task: Task) -> Iterator[Scene]:
        torch.set_num_threads(task.threads)
        saved = checkpoint.load(task.model, checkpoint_kind(self.variant["location"]))
        ctx = load_context(self.config, task.corpus, self.settings["wall_bound_share"], walkable=True)
        count = task.count or scene_count(self.config["instantiate"], self.variant)
        draws = self.settings["graph_draws"] if self.variant["graphs"] == "sampled" else 1
        plans = select_plans(self.config, self.variant, task.corpus, *task.graphs, count * draws)
        if not plans:
            log.warning("%s: no graph of room type '%s' to place: writing empty tables", task.graphs[0],
                        task.corpus.room_type)
        ctx, proposer = search_kit(self.config, ctx, self.variant["location"], saved, self.settings)
        scored, bar = 0, iter(progress(range(count), desc=f"instantiate {task.corpus.room_type} ({self.name})"))
        for plan in plans:
            if scored >= count:
                break
            seed = seed_of(self.config["seed"], self.name, plan.scene_id)
            outcome, walls = place_scene(plan, ctx, proposer, self.settings, self.variant, seed)
            scored += outcome.status in SCORED
            next(bar, None) if outcome.status in SCORED else None
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
        ctx = load_context(self.config, task.corpus, self.config["instantiate"]["wall_bound_share"], walkable=True)
        ctx, proposer = search_kit(self.config, ctx, "cfcn", saved, self.config["instantiate"])
        seed = seed_of(self.config["seed"], "complete", plan.scene_id)
        outcome, walls = place_scene(plan, ctx, proposer, self.config["instantiate"], self.variant, seed, self.keep)
        yield scene_of(plan, ctx, outcome, walls)
