"""Where GRAINS's overlaps come from (issue 42): the same trees the ``grains`` job decodes, their objects' boxes at
each step of the decoding, and the share of floor objects penetrating another floor object (deeper than the
placement checks' ``collision`` margin, box against box) at that step:

* ``decoded``: the decoder's own boxes (sizes and offsets as regressed, the codes' reals);
* ``decoded_snapped``: the same with the codes' bits winning over their reals (``grains.snap``);
* ``retrieved``: each box replaced by the training instance nearest to its size, at the decoded place and turn
  (GRAINS's retrieval, for the configured ``grains.snap``); against ``decoded`` (same snap), what retrieval adds;
* ``retrieved_within``: the nearest instance whose footprint fits the decoded one (``grains.retrieval: within``);
* ``resolved``: those moved apart by the repair (``grains.resolve``; the floor objects it leaves out are counted
  apart, ``resolved_left_out``);

and the colliding pairs of the decoded boxes (the configured ``grains.snap``) by how the tree relates them: placed one
against the other by a code, in one wall's group with no code between them, or in two walls' groups.

    .venv/bin/python bench/grains_overlaps.py [--room-type bedroom] [--scenes 30]

Run it in a pipeline run's folder (``results/placement/<type>/grains/model.pt`` and the corpus tables)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from pipeline import config as config_mod
from pipeline.geometry.boxes import penetration_depths
from pipeline.learning import checkpoint
from pipeline.methods.grains.hierarchy import Node, anchor, decoded_room, layout, leaves, room_rect
from pipeline.methods.grains.layout import retrieved_boxes, root_of, supports
from pipeline.methods.grains.resolve import kept_clear, separated
from pipeline.methods.grains.train import KIND, build_model
from pipeline.methods.placing import load_context
from pipeline.placement.retrieval import nearest, nearest_within
from pipeline.seeding import seed_of

from common import ROOT, arguments, report
from instantiate import corpus_of


def colliding_share(boxes: np.ndarray, on: dict[int, int], limit: float) -> tuple[int, int]:
    """(floor objects penetrating another floor object deeper than ``limit`` m, floor objects) of ``(n, 7)`` boxes;
    ``on``: supported object -> its support (left out)."""
    floor = np.array([k for k in range(len(boxes)) if k not in on], int)
    if len(floor) < 2:
        return 0, len(floor)
    depth = penetration_depths(boxes[floor])
    np.fill_diagonal(depth, 0.0)
    return int((depth > limit).any(1).sum()), len(floor)


def relations(tree: Node) -> tuple[list[int], set[tuple[int, int]]]:
    """Per leaf (in :func:`layout`'s order) the wall group it belongs to, and the leaf pairs a code relates directly
    (the anchors of a node's first and each later child, the pairs whose overlap the decoder's codes decide)."""
    wall_of: list[int] = []
    coded: set[tuple[int, int]] = set()
    index: dict[int, int] = {}
    for k, wall in enumerate(tree.children[:4]):
        for leaf in (leaves(wall.children[0]) if wall.children else []):
            index[id(leaf)] = len(wall_of)
            wall_of.append(k)

    def walk(node: Node) -> None:
        if node.kind in ("leaf", "wall", "root"):
            for child in node.children:
                walk(child)
            return
        first = index[id(anchor(node.children[0]))]
        for child in node.children[1:]:
            other = index[id(anchor(child))]
            coded.add((min(first, other), max(first, other)))
        for child in node.children:
            walk(child)

    walk(tree)
    return wall_of, coded


def colliding_pairs(boxes: np.ndarray, on: dict[int, int], limit: float, tree: Node) -> dict[str, int]:
    """Floor-object pairs penetrating deeper than ``limit`` m, by how the tree relates them: ``coded`` (one code
    places one against the other), ``same_wall`` (one wall's group, no code between them), ``across_walls``."""
    floor = np.array([k for k in range(len(boxes)) if k not in on], int)
    out = {"coded": 0, "same_wall": 0, "across_walls": 0}
    if len(floor) < 2:
        return out
    wall_of, coded = relations(tree)
    depth = penetration_depths(boxes[floor])
    for a, b in zip(*np.nonzero(np.triu(np.maximum(depth, depth.T) > limit, 1))):
        i, j = int(floor[a]), int(floor[b])
        key = "coded" if (i, j) in coded else "same_wall" if wall_of[i] == wall_of[j] else "across_walls"
        out[key] += 1
    return out


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
    tally = {k: [0, 0] for k in ("decoded", "decoded_snapped", "retrieved", "retrieved_within", "resolved")}
    for mode, faithful in (("held-out rooms", False), ("decoded rooms", True)):
        kinds: dict[str, int] = {}
        dropped = 0
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
                pairs = colliding_pairs(boxes, on, limit, tree)
                kinds = {k: kinds.get(k, 0) + v for k, v in pairs.items()}
                for key, pick in (("retrieved", nearest), ("retrieved_within", nearest_within)):
                    insts = [pick(ctx.pool, label, box[3:6]) for label, _, box in placed]
                    tally[key] = [a + c for a, c in zip(tally[key], colliding_share(retrieved_boxes(placed, insts, on),
                                                                                    on, limit))]
                # the repair, on the grains method's retrieval
                pick = nearest_within if cfg["grains"]["retrieval"] == "within" else nearest
                insts = [pick(ctx.pool, label, box[3:6]) for label, _, box in placed]
                got, rect = retrieved_boxes(placed, insts, on), room_rect(room)
                floor = [k for k, inst in enumerate(insts) if inst is not None and k not in on]
                res = cfg["grains"]["resolve"]
                clear = kept_clear(room, rect, cfg["instantiate"]["checks"]["door_clearance"] if res["doors"] else 0.0)
                moves, left_out = separated(got, floor, rect, limit, res["max_moves"], clear)
                got[:, :2] += moves[[root_of(k, on) for k in range(len(got))]]
                kept = np.array([k for k in range(len(got)) if k not in left_out and root_of(k, on) not in left_out], int)
                kept_on = {int(np.searchsorted(kept, c)): int(np.searchsorted(kept, p)) for c, p in on.items() if c in kept}
                tally["resolved"] = [a + c for a, c in zip(tally["resolved"], colliding_share(got[kept], kept_on, limit))]
                dropped += len(left_out)
        report({"room_type": args.room_type, "rooms": mode, "scenes": len(trees), "collision_margin_m": limit,
                "snap": cfg["grains"]["snap"],
                **{f"{k}_colliding_share": round(v[0] / max(v[1], 1), 4) for k, v in tally.items()},
                "floor_objects": tally["decoded"][1], "colliding_pairs_by_relation": kinds,
                "resolved_left_out": dropped},
               args.workdir, f"grains_overlaps_{args.room_type}_{'decoded' if faithful else 'heldout'}")
        tally = {k: [0, 0] for k in tally}


if __name__ == "__main__":
    main()
