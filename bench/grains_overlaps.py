"""Where GRAINS's overlaps come from (issue 42): the same trees the ``grains`` job decodes, their objects' boxes at
each step of the decoding, and the share of floor objects penetrating another floor object (deeper than the
placement checks' ``collision`` margin, box against box) at that step:

* ``decoded``: the decoder's own boxes (sizes and offsets as regressed, the codes' reals);
* ``decoded_snapped``: the same with the codes' bits winning over their reals (``grains.snap``);
* ``retrieved``: each box replaced by the training instance nearest to its size, at the decoded place and turn
  (GRAINS's retrieval, for the configured ``grains.snap``); against ``decoded`` (same snap), what retrieval adds;
* ``retrieved_within``: the nearest instance whose footprint fits the decoded one (``grains.retrieval: within``).

    .venv/bin/python bench/grains_overlaps.py [--room-type bedroom] [--scenes 30]

Run it in a pipeline run's folder (``results/placement/<type>/grains/model.pt`` and the corpus tables)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from pipeline import config as config_mod
from pipeline.geometry.boxes import penetration_depths
from pipeline.learning import checkpoint
from pipeline.methods.grains.hierarchy import decoded_room, layout, room_rect
from pipeline.methods.grains.layout import supports
from pipeline.methods.grains.train import KIND, build_model
from pipeline.methods.placing import load_context
from pipeline.placement.retrieval import nearest, nearest_within
from pipeline.seeding import seed_of

from common import ROOT, arguments, report
from instantiate import corpus_of


def retrieved(boxes: np.ndarray, placed: list, on: dict[int, int], pool, pick) -> np.ndarray:
    """``(n, 7)`` the decoded ``boxes`` with each leaf's half extents those of the instance ``pick(pool, label, half)``
    retrieves for it (a floor object's bottom kept on the floor)."""
    got = boxes.copy()
    for j, (label, _, box) in enumerate(placed):
        inst = pick(pool, label, box[3:6])
        if inst is not None:
            got[j, 3:6] = inst.half
            if j not in on:
                got[j, 2] = inst.half[2]
    return got


def colliding_share(boxes: np.ndarray, on: dict[int, int], limit: float) -> tuple[int, int]:
    """(floor objects penetrating another floor object deeper than ``limit`` m, floor objects) of ``(n, 7)`` boxes;
    ``on``: supported object -> its support (left out)."""
    floor = np.array([k for k in range(len(boxes)) if k not in on], int)
    if len(floor) < 2:
        return 0, len(floor)
    depth = penetration_depths(boxes[floor])
    np.fill_diagonal(depth, 0.0)
    return int((depth > limit).any(1).sum()), len(floor)


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--room-type", default="bedroom")
    ap.add_argument("--scenes", type=int, default=30)
    ap.add_argument("--config", type=Path, default=ROOT / "config" / "config.yaml")
    args = ap.parse_args()
    torch.set_num_threads(1)
    cfg = config_mod.load(args.config)
    saved = checkpoint.load(Path("results/placement") / args.room_type / "grains" / "model.pt", KIND)
    model = build_model(saved.record["labels"], saved.record["preset"])
    model.load_state_dict(saved.state["model"])
    model.eval()
    ctx = load_context(cfg, corpus_of(cfg, args.room_type))
    rooms = ctx.corpus.heldout()
    gen = torch.Generator().manual_seed(seed_of(cfg["seed"], "grains"))
    trees = model.decode(torch.randn(args.scenes, model.sizes.root_feature, generator=gen), cfg["grains"]["max_depth"])
    limit = cfg["instantiate"]["checks"]["collision"]
    tally = {k: [0, 0] for k in ("decoded", "decoded_snapped", "retrieved", "retrieved_within")}
    for mode, faithful in (("held-out rooms", False), ("decoded rooms", True)):
        for k, tree in enumerate(trees):
            room = decoded_room(tree, f"s{k}", args.room_type) if faithful else rooms[k % len(rooms)]
            on = supports(tree)
            for snap in (False, True):
                placed = layout(tree, room_rect(room), snap)
                boxes = np.array([b for _, _, b in placed]).reshape(-1, 7)
                key = "decoded_snapped" if snap else "decoded"
                tally[key] = [a + b for a, b in zip(tally[key], colliding_share(boxes, on, limit))]
                if snap != cfg["grains"]["snap"]:
                    continue
                for key, pick in (("retrieved", nearest), ("retrieved_within", nearest_within)):
                    got = retrieved(boxes, placed, on, ctx.pool, pick)
                    tally[key] = [a + c for a, c in zip(tally[key], colliding_share(got, on, limit))]
        report({"room_type": args.room_type, "rooms": mode, "scenes": len(trees), "collision_margin_m": limit,
                "snap": cfg["grains"]["snap"],
                **{f"{k}_colliding_share": round(v[0] / max(v[1], 1), 4) for k, v in tally.items()},
                "floor_objects": tally["decoded"][1]},
               args.workdir, f"grains_overlaps_{args.room_type}_{'decoded' if faithful else 'heldout'}")
        tally = {k: [0, 0] for k in tally}


if __name__ == "__main__":
    main()
