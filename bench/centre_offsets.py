"""How far objects stand off their anchors' centre lines, per centre-line rule: the training rooms' rules
(``instantiate.snap``'s settings, as ``planit generate`` learns them), and for each rule the median and 90th
percentile of the offsets (m) in the held-out real rooms and in each generated set of a finished run.

    cd RUN && .venv/bin/python bench/centre_offsets.py --room-type office [--methods planit planit_prior]
        [--generated results/generated/office]

A rule's offsets are read by the one function the rules are learned by
(:func:`pipeline.placement.support.centre_offsets`): an office chair in front of its desk, its offset across it.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pipeline import config as config_mod
from pipeline.evaluation.sets import load_generated
from pipeline.methods.planit.layout import pose_rules
from pipeline.placement.support import centre_offsets

from common import ROOT, arguments, report
from instantiate import corpus_of


def spread(rooms: list, rules: dict, cfg: dict) -> dict:
    """Per rule key and axis with a share: ``"pairs: median / p90"`` of ``rooms``' pairs' offsets (m)."""
    pairs, _ = centre_offsets(rooms, cfg["instantiate"]["checks"]["learned_support"]["tolerance"],
                              cfg["floor_contact"], math.radians(cfg["instantiate"]["snap"]["centre_facing_angle"]))
    out = {}
    for key, rule in rules.items():
        for axis, name in ((0, "across"), (1, "along")):
            if key[2] == "back" or not rule[axis]:
                continue
            off = np.abs(pairs.get(key, (np.zeros((0, 2)),) * 2)[axis][:, 0])
            out[f"{'/'.join(key)} {name}"] = (f"{len(off)}: {np.median(off):.3f} / {np.percentile(off, 90):.3f}"
                                               if len(off) else "0")
    return out


def main() -> None:
    ap = arguments(__doc__, Path("bench/out"))
    ap.add_argument("--room-type", required=True)
    ap.add_argument("--methods", nargs="*", default=["planit", "planit_prior"])
    ap.add_argument("--generated", type=Path, help="the folder of the methods' folders (default: results/generated/TYPE)")
    ap.add_argument("--config", default=str(ROOT / "config" / "config.yaml"))
    args = ap.parse_args()
    cfg = config_mod.load(args.config)
    corpus = corpus_of(cfg, args.room_type)
    rules = pose_rules(cfg, corpus).centring
    sets = {"real_heldout": corpus.heldout()}
    for m in args.methods:
        g = (args.generated or Path("results/generated") / args.room_type) / m
        sets[m] = load_generated(m, g / "rooms.parquet", g / "architecture.parquet", g / "objects.parquet",
                                 g / "scenes.parquet").rooms
    result = {"room_type": args.room_type,
              "rules": {"/".join(k): list(v[:2]) for k, v in rules.items()},
              "offsets (pairs: median / p90, m)": {name: spread(rooms, rules, cfg) for name, rooms in sets.items()}}
    report(result, args.workdir, f"centre_offsets_{args.room_type}")


if __name__ == "__main__":
    main()
