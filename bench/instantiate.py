"""Instantiation on one core: seconds per scene and outcomes of PlanIT's search on sampled graphs with one layout mode
(``--location cfcn``: the pose networks; ``prior``: the relative-pose prior; ``fcn``: the unconditional networks),
and how good the networks are on held-out rooms (location: the density's mass near the true centre; orientation:
the networks' most likely world yaw against the true one, symmetric turns counted as one, beside the
face-away-from-the-wall rule).

    .venv/bin/python bench/instantiate.py [--room-type bedroom] [--scenes 30] [--probes 60] [--location cfcn]
        [--no-confirm] [--early-backtrack | --no-early-backtrack] [--restarts N] [--density-cache N]

Run it in a pipeline run's folder (its results/): the sampled graphs, the corpus tables and
results/placement/<type>/<cfcn|fcn|prior>/model.pt. ``--no-confirm``: the collision check on the coarse per-attempt
grid alone, without measuring the pairs it clears again on the evaluation's grid; either way the placed rooms'
colliding objects are counted by the evaluation's own test. ``--[no-]early-backtrack`` and ``--restarts N`` set
``instantiate.early_backtrack`` and ``instantiate.restarts`` (default: the config's). The placed rooms are scored by
the evaluation's functional checks (learned from the training rooms, symmetric fronts counted) and its off-axis
shares. ``--density-cache N``: keep N location densities (1: only the room at hand, what a backtrack loses).
"""
from __future__ import annotations

import json
import platform
import statistics
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import torch

from pipeline import config as config_mod, tables
from pipeline.evaluation import functional as functional_checks, physical
from pipeline.evaluation.distributions import category_kl
from pipeline.evaluation.evaluate import failed_checks, off_axis_gap, off_axis_shares
from pipeline.geometry.collision import CollisionTest
from pipeline.geometry.frames import turn_error
from pipeline.learning import checkpoint
from pipeline.methods.corpus import load_corpus
from pipeline.methods.interface import RoomTypeRows
from pipeline.methods.placing import load_context
from pipeline.methods.planit import layout as instantiate
from pipeline.methods.planit.nets.fit import training_rooms
from pipeline.methods.planit.nets.proposer import TURNS, NetProposer
from pipeline.methods.scenes import plan_loss
from pipeline.placement import scene_metrics
from pipeline.placement.anchors import anchors_of
from pipeline.placement.layout import wall_frame, with_objects
from pipeline.placement.plan import PlanEdge, ScenePlan
from pipeline.placement.proposers import Grid, Request, nearest_wall
from pipeline.room.walkability import Walk, walkable_share
from pipeline.seeding import seed_of

from common import ROOT, arguments, corpus_paths, report, search_flags, search_overrides, search_suffix


def corpus_of(cfg: dict, room_type: str):
    """The kept rooms of a room type as every method reads them (the default run's outputs)."""
    p = corpus_paths(cfg)
    return load_corpus(room_type, {**p, "split": p["splits"] / f"{room_type}.parquet"})


def bench_seed(cfg: dict, scene_id: str) -> int:
    """The seed this bench places scene ``scene_id`` with (``bench/replay_scene.py --bench`` replays it)."""
    return seed_of(cfg["seed"], "bench", scene_id)


def probe_networks(cfg, room_type: str, saved, probes: int, checker) -> dict:
    """On held-out rooms, remove one object at a time and ask the networks for it (given every planned edge to the
    rest); and the held-out real rooms' collision rate (objects penetrating another deeper than the search allows)."""
    corpus = corpus_of(cfg, room_type)
    flt = [("room_type", "=", room_type)]
    nodes = tables.read(Path("results/graphs/ingested/nodes.parquet"), "final_nodes", filters=flt).to_pandas()
    edges = tables.read(Path("results/graphs/ingested/edges.parquet"), "final_edges", filters=flt).to_pandas()
    held = training_rooms(RoomTypeRows(nodes, edges, corpus.inputs, corpus.split)).held
    net, rng = NetProposer(saved, cfg["instantiate"]["density_cache"]), np.random.default_rng(0)
    near, net_hits, rule_hits, n = [], 0, 0, 0
    for t in (held[int(rng.integers(len(held)))] for _ in range(probes)):
        room = t.room
        k = int(rng.integers(len(room.object_ids)))
        v, cat, sym = room.object_ids[k], room.categories[k], t.symmetry.get(room.object_ids[k], "none")
        if cat not in net.categories or sym == "radial":
            continue
        kept = with_objects(room, [j for j in range(len(room.object_ids)) if j != k])
        plan = ScenePlan("probe", room.room_id, room_type, room.object_ids, room.categories, ["none"] * len(room.object_ids),
                         [1] * len(room.object_ids), [t.parent.get(o) for o in room.object_ids],
                         ["none"] * len(room.object_ids),
                         [PlanEdge(s, tt, "support" if kind == "support" else "spatial",
                                   *(kind.split("/") if kind != "support" else (None, None))) for s, tt, kind in t.edges])
        anchors = anchors_of(v, plan, kept, t.walls, t.symmetry, tuple(room.boxes[k, 3:5]))
        grid = Grid(room.outline, 0.05)
        if anchors:
            d = net.density(kept, t.walls, cat, anchors, grid.points) * grid.floor
            near.append(float(d[np.linalg.norm(grid.points - room.boxes[k, :2], axis=1) < 0.25].sum() / d.sum()))
        p, _ = net.turns(Request(kept, t.walls, cat, sym, anchors, grid, grid.floor), room.boxes[k, :2])
        best = float(np.argmax(p)) * 2 * np.pi / TURNS
        net_hits += bool(turn_error(best - room.boxes[k, 6], sym) <= np.radians(15))
        rule = wall_frame(t.walls, nearest_wall(t.walls, room.boxes[k, :2])).yaw
        rule_hits += bool(turn_error(rule - room.boxes[k, 6], sym) <= np.radians(15))
        n += 1
    coll = [scene_metrics.colliding_objects(t.room, t.parent, checker) for t in held]
    return {"heldout_real_collision_rate": round(sum(coll) / sum(len(t.room.object_ids) for t in held), 4),
            "location_mass_within_0.25m": round(float(np.mean(near)), 3), "location_probes": len(near),
            "orientation_within_15deg_network": round(net_hits / max(n, 1), 3),
            "orientation_within_15deg_face_away_rule": round(rule_hits / max(n, 1), 3), "orientation_probes": n}


def evaluation_collisions(room, parent: dict, checker, ev: CollisionTest):
    """``(n,)`` bool: the placed room's objects the evaluation's own test finds colliding."""
    return physical.colliding(room, [parent.get(i) for i in room.object_ids], checker.meshes_of(room), ev)


def selection(corpus, plans: list, rooms: list) -> dict:
    """Category KL to the held-out real rooms of the placed rooms and of every graph drawn for them: the difference
    is what the search's failures select (graph_draws replaces a failed graph by the next)."""
    real = [c for r in corpus.heldout() for c in r.categories]
    drawn = [c for p in plans for c in p.categories]
    placed = [c for r in rooms for c in r.categories]
    return {"category_kl_placed": round(category_kl(real, placed), 4),
            "category_kl_drawn": round(category_kl(real, drawn), 4)}


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--room-type", default="bedroom")
    ap.add_argument("--scenes", type=int, default=30)
    ap.add_argument("--probes", type=int, default=60)
    ap.add_argument("--location", default="cfcn", choices=["cfcn", "fcn", "prior"])
    ap.add_argument("--graphs", default="sampled", choices=["sampled", "heldout"], help="the graph model's sampled graphs "
                    "or the held-out rooms' own graphs (Table 3's)")
    ap.add_argument("--config", type=Path, default=ROOT / "config" / "config.yaml")
    ap.add_argument("--no-confirm", action="store_true")
    ap.add_argument("--override", default="{}", help="JSON merged into the config (e.g. '{\"instantiate\": {\"relax\": {\"max\": 0.5}}}')")
    ap.add_argument("--name", default="", help="suffix of the report's name")
    search_flags(ap)
    ap.add_argument("--density-cache", type=int)
    args = ap.parse_args()
    torch.set_num_threads(1)
    cfg = config_mod.deep_merge(config_mod.load(args.config), json.loads(args.override))
    cfg["instantiate"] = config_mod.deep_merge(cfg["instantiate"], search_overrides(args))
    if args.density_cache:
        cfg["instantiate"]["density_cache"] = args.density_cache
    saved = checkpoint.load(Path("results/placement") / args.room_type / args.location / "model.pt",
                            instantiate.checkpoint_kind(args.location))
    ctx = load_context(cfg, corpus_of(cfg, args.room_type), cfg["instantiate"]["wall_bound_share"],
                       walkable=True)  # as PlanIT's search
    if args.no_confirm:
        ctx.checker = replace(ctx.checker, cfg={**ctx.checker.cfg, "confirm": None})  # a fresh collision_test
    variant = {**cfg["instantiate"]["variants"]["planit"], "location": args.location, "graphs": args.graphs}
    graphs = Path("results/graph_model") / args.room_type / "planit" / "sampled"
    if args.graphs == "heldout":
        graphs = Path("results/graphs/ingested")
    draws = cfg["instantiate"]["graph_draws"] if args.graphs == "sampled" else 1
    plans = instantiate.select_plans(cfg, variant, ctx.corpus, graphs / "nodes.parquet", graphs / "edges.parquet",
                                     args.scenes * draws)
    ctx, proposer = instantiate.search_kit(cfg, ctx, args.location, saved, cfg["instantiate"])
    rows, rooms, failing, colliding, ev = [], [], {}, 0, CollisionTest.of(cfg["evaluate"]["collision"]["penetration"],
                                                     cfg["evaluate"]["collision"]["max_penetration"], ctx.checker.intersector)
    fn_cfg, sym = cfg["evaluate"]["functional"], ctx.checker.symmetry
    learned, functional = functional_checks.learn_checks(ctx.corpus.training(), fn_cfg, sym), []
    for plan in plans:
        if len(rooms) >= args.scenes:
            break
        seed = bench_seed(cfg, plan.scene_id)
        out, walls = instantiate.place_scene(plan, ctx, proposer, cfg["instantiate"], variant, seed)
        metrics = scene_metrics.consistency(plan, out.room, walls.ids, ctx.checker, out.dropped, out.accepted)
        rows.append((out.ok, out.seconds, metrics["consistency"], out.rejections, len(out.relaxed),
                     out.attempts, metrics["plan_loss"], len(out.room.object_ids), f"{plan.scene_id}: {out.reason}"))
        if out.status in tables.SCORED:
            rooms.append(out.room)
            functional.append(functional_checks.score_room(out.room, learned, fn_cfg, sym))
            failing[plan.scene_id] = failed_checks(functional[-1])
            colliding += int(evaluation_collisions(out.room, dict(zip(plan.ids, plan.parent)), ctx.checker, ev).sum())
    placed = [r for r in rows if r[0]]
    walk = Walk.of(cfg["evaluate"]["walk"])
    shares = np.array([walkable_share(r, walk) for r in rooms])  # each placed room's, once
    axis = off_axis_shares(rooms, sym, cfg["evaluate"]["off_axis_angle"])
    train_axis = off_axis_shares(ctx.corpus.training(), sym, cfg["evaluate"]["off_axis_angle"])
    result = {"room_type": args.room_type, "location": args.location, "graphs": args.graphs, "scenes": len(rows),
              "placed": len(placed),
              "confirm_on_evaluation_grid": not args.no_confirm, "search_seconds": round(sum(r[1] for r in rows), 1),
              "colliding_objects_by_evaluation": colliding, "restarted_scenes": sum(r[5] > 1 for r in rows),
              "rejections_per_scene": round(float(np.mean([r[3] for r in rows])), 1),
              "relaxed_share": round(sum(r[4] for r in placed) / max(sum(r[7] for r in placed), 1), 4),
              "median_seconds_per_scene": round(statistics.median(r[1] for r in rows), 3),
              "mean_consistency_placed": round(float(np.mean([r[2] for r in placed])), 4) if placed else None,
              "plan_loss_placed": plan_loss(pd.Series([r[6] for r in placed])),
              "failed_reasons": [r[8] for r in rows if not r[0]],
              "failing_checks": {scene: checks for scene, checks in failing.items() if checks},
              "functional_placed": {k: round(float(v), 3) for k, v in
                                    pd.DataFrame(functional).mean().items()} if functional else None,
              **selection(ctx.corpus, plans[:len(rows)], rooms),
              "walkable_share": round(float(np.mean(shares)), 4) if rooms else None,
              "walkable_under_0.8": int((shares < 0.8).sum()),
              "off_axis_share": axis["all"], "off_axis_share_training": train_axis["all"],
              "off_axis_gap": off_axis_gap(axis, train_axis, cfg["evaluate"]["off_axis_min_objects"]),
              **(probe_networks(cfg, args.room_type, saved, args.probes, ctx.checker) if args.location != "prior" else {}),
              "machine": platform.processor() or platform.machine(), "threads": 1}
    report(result, args.workdir, f"instantiate_{args.room_type}_{args.location}_{args.graphs}" + ("_no_confirm" if args.no_confirm else "")
           + search_suffix(args) + (f"_cache{args.density_cache}" if args.density_cache else "") + args.name)


if __name__ == "__main__":
    main()
