"""Instantiation on one core: seconds per scene and outcomes of the default search on sampled graphs, and how
good the placement networks are on held-out rooms (location: CFCN mass near the true centre; orientation: the
network's most likely bin against the face-away-from-the-wall rule).

    .venv/bin/python bench/instantiate.py [--room-type bedroom] [--scenes 30] [--probes 60] [--no-confirm]
        [--early-backtrack | --no-early-backtrack] [--restarts N] [--pose-rules | --no-pose-rules] [--density-cache N]

``--no-confirm``: the collision check on the coarse per-attempt grid alone, without measuring the pairs it clears
again on the evaluation's grid (what the search did before); either way the placed rooms' colliding objects are
counted by the evaluation's own test. ``--[no-]early-backtrack``, ``--restarts N`` and ``--[no-]pose-rules`` set
``instantiate.early_backtrack``, ``instantiate.restarts`` and ``instantiate.pose_rules.enabled`` (default: the
config's). The placed rooms are scored by the evaluation's functional checks (learned from the training rooms). ``--density-cache N``: keep N location densities (1: only the room at hand, what a backtrack loses); the
report counts the densities computed and found again.

Reads a pipeline run's outputs (make pipeline first): the sampled graphs, the corpus tables and
results/placement/<type>/cfcn/model.pt.
"""
from __future__ import annotations

import platform
import statistics
import zlib

import numpy as np
import pandas as pd
import torch

from pipeline import config as config_mod
from pipeline.evaluation import functional as functional_checks
from pipeline.evaluation import physical
from pipeline.learning import checkpoint
from pipeline.geometry.frames import yaw_to_local
from pipeline.methods.planit.nets.data import bin_targets, orientation_frame
from pipeline.methods.planit.nets.proposer import NetProposer
from pipeline.placement.layout import render, with_objects
from pipeline.placement.plan import PlanEdge, ScenePlan
from pipeline.placement import scene_metrics
from pipeline.methods.scenes import plan_loss
from pipeline.placement.proposers import FaceAway
from pipeline.placement.search import Grid, anchors_of
from pipeline import tables
from pipeline.methods.corpus import load_corpus
from pipeline.methods.planit import layout as instantiate
from pipeline.methods.planit.nets.fit import training_rooms

from common import ROOT, arguments, corpus_paths, report, search_flags, search_overrides, search_suffix


def corpus_of(cfg: dict, room_type: str):
    """The kept rooms of a room type as every method reads them (the default run's outputs)."""
    p = corpus_paths(cfg)
    return load_corpus(room_type, p["rooms"], p["architecture"], p["objects"], p["models"],
                       p["splits"] / f"{room_type}.parquet", p["symmetry"], p["category_sizes"])


def probe_networks(cfg, room_type: str, saved: dict, probes: int, checker) -> dict:
    """On held-out rooms, remove one object at a time and ask the networks for it; and the held-out real rooms'
    collision rate (objects penetrating another deeper than the search allows, same measure)."""
    corpus = corpus_of(cfg, room_type)
    flt = [("room_type", "=", room_type)]
    nodes = tables.read(ROOT / "results/graphs/ingested/nodes.parquet", "final_nodes", filters=flt).to_pandas()
    edges = tables.read(ROOT / "results/graphs/ingested/edges.parquet", "final_edges", filters=flt).to_pandas()
    _, _, held, _ = training_rooms(corpus.inputs, nodes, edges, corpus.split)
    net, rng = NetProposer(saved, cfg["instantiate"]["density_cache"]), np.random.default_rng(0)
    near, net_hits, rule_hits, n = [], 0, 0, 0
    for t in (held[int(rng.integers(len(held)))] for _ in range(probes)):
        room = t.room
        k = int(rng.integers(len(room.object_ids)))
        v, cat = room.object_ids[k], room.categories[k]
        kept = with_objects(room, [j for j in range(len(room.object_ids)) if j != k])
        plan = ScenePlan("probe", room.room_id, room_type, room.object_ids, room.categories, ["none"] * len(room.object_ids),
                         [1] * len(room.object_ids), [None] * len(room.object_ids), ["none"] * len(room.object_ids),
                         [PlanEdge(s, tt, "spatial", d, x) for s, tt, d, x in t.edges])
        anchors = anchors_of(v, plan, kept, t.walls, t.symmetry)
        if anchors and cat in net.categories:
            grid = Grid(room.outline, 0.05)
            d = net.density(kept, t.walls, cat, anchors, grid.points) * grid.floor
            near.append(float(d[np.linalg.norm(grid.points - room.boxes[k, :2], axis=1) < 0.25].sum() / d.sum()))
        frame = orientation_frame(t.walls, room.boxes[k, :2])
        bins = bin_targets(float(yaw_to_local(frame, room.boxes[k, 6])), t.symmetry.get(v, "none"), net.preset["bins"])
        if bins.all() or cat not in net.categories:
            continue
        with torch.no_grad():
            logits = net.ori(torch.as_tensor(render(kept, t.walls, net.ori_view, frame)[None]))[0, net.categories.index(cat)]
        net_hits += bool(bins[int(logits.argmax())])
        rule = FaceAway().orientation(kept, t.walls, cat, "none", room.boxes[k, :2], rng)
        rule_hits += bool(bins[int(np.round(yaw_to_local(frame, rule) / (2 * np.pi / len(bins)))) % len(bins)])
        n += 1
    coll = [scene_metrics.colliding_objects(t.room, t.parent, checker) for t in held]
    return {"heldout_real_collision_rate": round(sum(coll) / sum(len(t.room.object_ids) for t in held), 4),
            "location_mass_within_0.25m": round(float(np.mean(near)), 3), "location_probes": len(near),
            "orientation_accuracy_network": round(net_hits / max(n, 1), 3),
            "orientation_accuracy_face_away_rule": round(rule_hits / max(n, 1), 3), "orientation_probes": n}


def evaluation_collisions(room, parent: dict, checker, ev: dict):
    """``(n,)`` bool: the placed room's objects the evaluation's own test finds colliding."""
    return physical.colliding(room, [parent.get(i) for i in room.object_ids], checker.meshes_of(room), ev)


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--room-type", default="bedroom")
    ap.add_argument("--scenes", type=int, default=30)
    ap.add_argument("--probes", type=int, default=60)
    ap.add_argument("--no-confirm", action="store_true")
    search_flags(ap)
    ap.add_argument("--density-cache", type=int)
    args = ap.parse_args()
    torch.set_num_threads(1)
    cfg = config_mod.load(ROOT / "config" / "config.yaml")
    cfg["instantiate"] = config_mod.deep_merge(cfg["instantiate"], search_overrides(args))
    if args.density_cache:
        cfg["instantiate"]["density_cache"] = args.density_cache
    saved = checkpoint.load(ROOT / "results/placement" / args.room_type / "cfcn" / "model.pt", "placement_nets")
    ctx = instantiate.load_context(cfg, corpus_of(cfg, args.room_type))
    if args.no_confirm:
        ctx.checker.cfg["confirm"] = None
    variant = cfg["instantiate"]["variants"]["planit"]
    graphs = ROOT / "results/graph_model" / args.room_type / "sampled"
    plans = instantiate.select_plans(cfg, variant, ctx.corpus, graphs / "nodes.parquet", graphs / "edges.parquet", args.scenes)
    proposer = instantiate.make_proposer("cfcn", saved, cfg["instantiate"])
    nets = getattr(proposer, "base", proposer)  # the NetProposer, under the relation bands when they are on
    rows, colliding, ev = [], 0, {**cfg["evaluate"]["collision"], "intersector": ctx.checker.intersector}
    fn_cfg = cfg["evaluate"]["functional"]
    learned, functional = functional_checks.learn_checks(ctx.corpus.training(), fn_cfg), []
    for plan in plans:
        seed = zlib.crc32(f"{cfg['seed']}/bench/{plan.scene_id}".encode())
        out, walls = instantiate.place_scene(plan, ctx, proposer, cfg["instantiate"], variant, seed)
        metrics = scene_metrics.consistency(plan, out.room, walls.ids, ctx.checker, out.dropped, out.accepted)
        rows.append((out.ok, out.seconds, metrics["consistency"], out.rejections, out.failures.get("nowhere", 0),
                     out.attempts, metrics["plan_loss"]))
        if out.ok:
            functional.append(functional_checks.score_room(out.room, learned, fn_cfg))
            colliding += int(evaluation_collisions(out.room, dict(zip(plan.ids, plan.parent)), ctx.checker, ev).sum())
    placed = [r for r in rows if r[0]]
    result = {"room_type": args.room_type, "scenes": len(rows), "placed": len(placed),
              "confirm_on_evaluation_grid": not args.no_confirm, "search_seconds": round(sum(r[1] for r in rows), 1),
              "colliding_objects_by_evaluation": colliding, "early_backtrack": cfg["instantiate"]["early_backtrack"],
              "restarts": cfg["instantiate"]["restarts"], "restarted_scenes": sum(r[5] > 1 for r in rows),
              "attempts": sum(r[5] for r in rows),
              "rejections_per_scene": round(float(np.mean([r[3] for r in rows])), 1),
              "early_backtracks": sum(r[4] for r in rows), "density_cache": cfg["instantiate"]["density_cache"],
              "densities_computed": nets.densities.computed, "densities_reused": nets.densities.reused,
              "median_seconds_per_scene": round(statistics.median(r[1] for r in rows), 3),
              "median_seconds_placed": round(statistics.median(r[1] for r in placed), 3) if placed else None,
              "mean_consistency_placed": round(float(np.mean([r[2] for r in placed])), 4) if placed else None,
              "plan_loss_placed": plan_loss(pd.Series([r[6] for r in placed])),
              "functional_placed": {k: round(float(v), 3) for k, v in
                                    pd.DataFrame(functional).mean().items()} if functional else None,
              **probe_networks(cfg, args.room_type, saved, args.probes, ctx.checker),
              "machine": platform.processor() or platform.machine(), "threads": 1}
    report(result, args.workdir, f"instantiate_{args.room_type}" + ("_no_confirm" if args.no_confirm else "")
           + search_suffix(args)
           + (f"_cache{args.density_cache}" if args.density_cache else ""))


if __name__ == "__main__":
    main()
