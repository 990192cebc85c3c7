"""Corpus generation, ingest and filter timings on the default config (>= 2000 procedural rooms).

    .venv/bin/python bench/corpus.py [--workdir bench/out]
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import pandas as pd

from pipeline import config as config_mod
from pipeline.stages import filter as filter_stage, ingest

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--workdir", type=Path, default=ROOT / "bench" / "out")
    args = ap.parse_args()
    cfg = config_mod.load(ROOT / "config" / "config.yaml", json.dumps({"shards": 1}))
    t = time.perf_counter()
    counts = ingest.run(cfg, args.workdir / "ingest")
    t_ingest = time.perf_counter() - t
    t = time.perf_counter()
    report = filter_stage.run(cfg, args.workdir / "ingest", args.workdir / "filter")
    t_filter = time.perf_counter() - t
    gt = pd.read_parquet(args.workdir / "ingest" / "ground_truth.parquet")
    planted = gt[gt["relation"] == "defect"].set_index("room_id")["label"]
    rep = report.set_index("room_id")
    caught = sum(rule in rep.loc[room, "rules"] for room, rule in planted.items())
    clean = rep.drop(index=planted.index)
    result = {"rooms": counts["rooms"], "objects": counts["objects"], "ingest_seconds": round(t_ingest, 2),
              "clean_rooms_kept": round(float((clean["status"] == "kept").mean()), 4),
              "planted_defects_caught_by_their_rule": f"{caught}/{len(planted)}",
              "ingest_rooms_per_s": round(counts["rooms"] / t_ingest, 1), "filter_seconds": round(t_filter, 2),
              "filter_rooms_per_s": round(counts["rooms"] / t_filter, 1),
              "kept": int((report["status"] == "kept").sum())}
    (args.workdir / "corpus.json").write_text(json.dumps(result, indent=2))
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
