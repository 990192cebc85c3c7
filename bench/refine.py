"""Graph statistics + refinement speed on the default corpus (after bench/extraction.py built it):
rooms/s for one shard, single process.

    .venv/bin/python bench/refine.py [--workdir bench/out]
"""
from __future__ import annotations

import time

from pipeline.stages import extract, graphs

from common import arguments, default_config, report


def main() -> None:
    ap = arguments(__doc__)
    args = ap.parse_args()
    w = args.workdir
    cfg = default_config()
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
    report(result, w, "refine")


if __name__ == "__main__":
    main()
