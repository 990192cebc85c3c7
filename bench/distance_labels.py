"""Spatial edges per distance label (adjacent / proximal / distant) in the raw graphs of one or more runs.

    .venv/bin/python bench/distance_labels.py NAME=WORKDIR [NAME=WORKDIR ...] [--workdir bench/out]

Each WORKDIR is a Snakemake work folder; every ``raw/edges-<k>.parquet`` below its ``results/`` counts (the
layout of older versions too). Object -> object and wall -> object edges are counted apart.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from common import arguments, report


def counts(workdir: Path) -> dict:
    files = sorted(Path(workdir, "results").rglob("raw/edges-*.parquet"))
    edges = pd.concat([pd.read_parquet(f, columns=["source", "edge_type", "distance"]) for f in files])
    spatial = edges[edges["edge_type"].astype(str) == "spatial"]
    anchor = spatial["source"].astype(str).str.startswith("wall").map({True: "wall_to_object", False: "object_to_object"})
    table = spatial.groupby([anchor, spatial["distance"].astype(str)]).size()
    return {kind: {label: int(n) for label, n in table[kind].items()} for kind in table.index.levels[0] if kind in table}


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("runs", nargs="+", help="NAME=WORKDIR")
    args = ap.parse_args()
    result = {name: counts(Path(folder)) for name, folder in (r.split("=", 1) for r in args.runs)}
    report(result, args.workdir, "distance_labels")


if __name__ == "__main__":
    main()
