"""Corpus generation, ingest and filter timings on the default config (>= 2000 procedural rooms).

    .venv/bin/python bench/corpus.py [--workdir bench/out]
"""
from __future__ import annotations

import pandas as pd

from common import arguments, default_config, ingest_and_filter, report, shard_paths


def main() -> None:
    ap = arguments(__doc__)
    args = ap.parse_args()
    cfg = default_config()
    p = shard_paths(args.workdir)
    counts, filter_report, t_ingest, t_filter = ingest_and_filter(cfg, p)
    gt = pd.read_parquet(p["ground_truth"])
    planted = gt[gt["relation"] == "defect"].set_index("room_id")["label"]
    rep = filter_report.set_index("room_id")
    caught = sum(rule in rep.loc[room, "rules"] for room, rule in planted.items())
    clean = rep.drop(index=planted.index)
    result = {"rooms": counts["rooms"], "objects": counts["objects"], "ingest_seconds": round(t_ingest, 2),
              "clean_rooms_kept": round(float((clean["status"] == "kept").mean()), 4),
              "planted_defects_caught_by_their_rule": f"{caught}/{len(planted)}",
              "ingest_rooms_per_s": round(counts["rooms"] / t_ingest, 1), "filter_seconds": round(t_filter, 2),
              "filter_rooms_per_s": round(counts["rooms"] / t_filter, 1),
              "kept": int((filter_report["status"] == "kept").sum())}
    report(result, args.workdir, "corpus")


if __name__ == "__main__":
    main()
