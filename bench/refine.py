"""Graph statistics + refinement speed on the default corpus (after bench/extraction.py built it):
rooms/s for one shard, single process.

    .venv/bin/python bench/refine.py [--workdir bench/out]
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from pipeline import config as config_mod
from pipeline.stages import extract, graphs

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--workdir", type=Path, default=ROOT / "bench" / "out")
    args = ap.parse_args()
    w = args.workdir
    cfg = config_mod.load(ROOT / "config" / "config.yaml", json.dumps({"shards": 1}))
    t = time.perf_counter()
    ex = extract.run(cfg, 0, w / "ingest", w / "filter", w / "raw1", w / "symmetry" / "symmetry.parquet")
    t_extract = time.perf_counter() - t
    t = time.perf_counter()
    graphs.run_statistics(cfg, w / "raw1", w / "stats1")
    t_stats = time.perf_counter() - t
    t = time.perf_counter()
    summary = graphs.run_refine(cfg, 0, w / "raw1", w / "stats1", w / "final1")
    t_refine = time.perf_counter() - t
    result = {"rooms": summary["rooms"], "extract_stage_seconds": round(t_extract, 2),
              "extract_stage_rooms_per_s": round(ex["rooms"] / t_extract, 1),
              "graph_statistics_seconds": round(t_stats, 2), "refine_seconds": round(t_refine, 2),
              "refine_rooms_per_s": round(summary["rooms"] / t_refine, 1), "cyclic_rooms": summary["cyclic_rooms"],
              "repaired_nodes": summary["repaired"]}
    (w / "refine.json").write_text(json.dumps(result, indent=2))
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
