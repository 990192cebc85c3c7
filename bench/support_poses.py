"""How objects stand on their supports: per (support category, object category), the range of their turns relative
to the support (degrees) and of their centres' offsets from its centre lines across its width and along its depth
(m), in the training rooms, the held-out real rooms and each generated set of a finished run. The figures behind the
turns on supports and the edge rules' clip across the width (docs/benchmarks.md: monitors beside or turned off their
desk).

    cd RUN && .venv/bin/python bench/support_poses.py --room-type office [--pairs desk/monitor desk/keyboard]
        [--methods planit planit_prior]

Pairs are read by the function the rules are learned by (:func:`pipeline.placement.support.support_pairs`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from pipeline import config as config_mod
from pipeline.evaluation.sets import load_generated
from pipeline.geometry.frames import to_local, wrap
from pipeline.placement.layout import box_frame
from pipeline.placement.support import support_pairs

from common import ROOT, arguments, report
from instantiate import corpus_of


def ranges(rooms: list, pairs: set[str], tolerance: float, floor_contact: float) -> dict:
    """Per ``support/object`` pair: ``n``, turn (deg), across and along (m) as ``[min, max]``."""
    seen: dict[str, list[tuple[float, float, float]]] = {}
    for room in rooms:
        b, cats = room.boxes.reshape(-1, 7), room.categories
        for k, j, _ in support_pairs(room, tolerance, floor_contact):
            name = f"{cats[j]}/{cats[k]}"
            if name in pairs:
                u, v = to_local(box_frame(b[j]), b[k, :2])
                seen.setdefault(name, []).append((float(np.degrees(wrap(b[k, 6] - b[j, 6]))), float(u), float(v)))
    span = lambda x: [round(float(np.min(x)), 3), round(float(np.max(x)), 3)]
    return {name: {"n": len(rows), **{axis: span(np.array(rows)[:, i]) for i, axis in
                                      enumerate(("turn_deg", "across_m", "along_m"))}}
            for name, rows in sorted(seen.items())}


def main() -> None:
    ap = arguments(__doc__, Path("bench/out"))
    ap.add_argument("--room-type", required=True)
    ap.add_argument("--pairs", nargs="*", default=["desk/monitor", "desk/keyboard"])
    ap.add_argument("--methods", nargs="*", default=["planit", "planit_prior"])
    ap.add_argument("--config", default=str(ROOT / "config" / "config.yaml"))
    args = ap.parse_args()
    cfg = config_mod.load(args.config)
    corpus = corpus_of(cfg, args.room_type)
    sets = {"real_train": corpus.training(), "real_heldout": corpus.heldout()}
    for m in args.methods:
        g = Path("results/generated") / args.room_type / m
        sets[m] = load_generated(m, g / "rooms.parquet", g / "architecture.parquet", g / "objects.parquet",
                                 g / "scenes.parquet").rooms
    tolerance = cfg["instantiate"]["checks"]["learned_support"]["tolerance"]
    report({"room_type": args.room_type, "sets": {name: ranges(rooms, set(args.pairs), tolerance, cfg["floor_contact"])
                                                  for name, rooms in sets.items()}},
           args.workdir, f"support_poses_{args.room_type}")


if __name__ == "__main__":
    main()
