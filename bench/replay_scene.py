"""Replay one generated scene of a finished run with its own seed, logging every draw of the pose wrappers
(``FaceAnchor``, ``BackToWall``, ``FacingPartner``, ``Centred``) for the chosen categories: how the causes of
docs/benchmarks.md's issue-40 figures were found (a chair drawn 0.36 m off its desk's line that ``Centred`` kept).

    cd RUN && PYTHONPATH=/path/to/checkout .venv/bin/python /path/to/checkout/bench/replay_scene.py \\
        --room-type office --method planit --scene 00010 --watch office_chair,monitor

RUN: a run directory (``snakemake --directory RUN``) with the room type's trained layout model and sampled graphs.
The replayed scene is the generated one when the code and the config are those of its run; with ``--bench``, the
one ``bench/instantiate.py`` placed (whose JSON lists each placed scene's failing functional checks).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import torch

from pipeline import config as config_mod
from pipeline.learning import checkpoint
from pipeline.methods.placing import load_context
from pipeline.methods.planit import layout as inst
from pipeline.placement import proposers
from pipeline.seeding import seed_of

sys.path.insert(0, str(Path(__file__).parent))
from instantiate import bench_seed, corpus_of  # noqa: E402  (bench/instantiate.py: the run's corpus of one room type)

WRAPPERS = (proposers.FaceAnchor, proposers.BackToWall, proposers.FacingPartner, proposers.Centred)


def logged(cls, watch: set[str]) -> None:
    """Wrap ``cls.pose`` to print each draw for a category in ``watch``: anchors and the pose it returns."""
    pose = cls.pose

    def logging_pose(self, req, rng):
        out = pose(self, req, rng)
        if req.category in watch:
            anchors = [(a.node, a.edge, a.reverse) for a in req.anchors]
            drawn = None if out is None else (np.round(out[0], 2).tolist(), round(float(np.degrees(out[1]))) % 360)
            print(f"  {cls.__name__:14s} {req.category:14s} anchors={anchors} -> {drawn}")
        return out

    cls.pose = logging_pose


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--room-type", required=True)
    ap.add_argument("--method", choices=["planit", "planit_prior"], default="planit")
    ap.add_argument("--scene", required=True, help="the generated scene id's numeric end, e.g. 00010")
    ap.add_argument("--watch", required=True, help="comma-separated categories whose draws are logged")
    ap.add_argument("--bench", action="store_true", help="the seed bench/instantiate.py gives the scene, not the run's")
    ap.add_argument("--config", type=Path, default=Path(__file__).parents[1] / "config/config.yaml")
    args = ap.parse_args()
    torch.set_num_threads(1)
    cfg = config_mod.load(args.config)
    location = {"planit": "cfcn", "planit_prior": "prior"}[args.method]
    saved = checkpoint.load(Path("results/placement") / args.room_type / location / "model.pt",
                            inst.checkpoint_kind(location))
    ctx = load_context(cfg, corpus_of(cfg, args.room_type), cfg["instantiate"]["wall_bound_share"])  # as PlanIT's search
    variant = {**cfg["instantiate"]["variants"]["planit"], "location": location}
    graphs = Path("results/graph_model") / args.room_type / "planit" / "sampled"
    plans = inst.select_plans(cfg, variant, ctx.corpus, graphs / "nodes.parquet", graphs / "edges.parquet", 200)
    plan = next(p for p in plans if p.scene_id.endswith(args.scene))
    for cls in WRAPPERS:
        logged(cls, set(args.watch.split(",")))
    ctx, proposer = inst.search_kit(cfg, ctx, location, saved, cfg["instantiate"])
    seed = bench_seed(cfg, plan.scene_id) if args.bench else seed_of(cfg["seed"], args.method, plan.scene_id)
    out, _ = inst.place_scene(plan, ctx, proposer, cfg["instantiate"], variant, seed)
    boxes = out.room.boxes.reshape(-1, 7)
    for k, category in enumerate(out.room.categories):
        if category in args.watch.split(","):
            print("placed", category, np.round(boxes[k, :2], 2).tolist(), round(float(np.degrees(boxes[k, 6]))) % 360)
    print(out.status, out.reason, "relaxed", out.relaxed)


if __name__ == "__main__":
    main()
