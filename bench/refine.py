"""Graph statistics + refinement speed on the default corpus (after bench/extraction.py built it):
rooms/s for one shard, single process.

    .venv/bin/python bench/refine.py [--workdir bench/out]
"""
from __future__ import annotations

import time

from pipeline.stage import Files
from pipeline.stages import extract_graphs, graph_statistics, refine_graphs, shard_statistics

from common import arguments, default_config, report, shard_paths


def main() -> None:
    ap = arguments(__doc__)
    args = ap.parse_args()
    w = args.workdir
    p = shard_paths(w)
    cfg = default_config()
    raw = {n: w / "raw1" / f"{n}-0.parquet" for n in ("nodes", "edges")}
    t = time.perf_counter()
    ex = extract_graphs.run(cfg, Files(rooms=p["kept"], architecture=p["architecture"], objects=p["objects"],
                                       models=p["models"], symmetry=p["symmetry"]),
                            Files(nodes=raw["nodes"], edges=raw["edges"], summary=w / "raw1" / "summary-0.json"), shard=0)
    t_extract = time.perf_counter() - t
    stats = {n: w / "stats1" / f"{n}.parquet" for n in graph_statistics.STAT_TABLES}
    t = time.perf_counter()
    shard_statistics.run(cfg, Files(nodes=raw["nodes"], edges=raw["edges"]),
                         Files(counts=w / "stats1" / "partial-0.parquet", candidates=w / "stats1" / "candidates-0.parquet"))
    graph_statistics.run(cfg, Files(partial=[w / "stats1" / "partial-0.parquet"], nodes=[raw["nodes"]]), Files(stats))
    t_stats = time.perf_counter() - t
    outs = {n: w / "final1" / f"{n}-0.parquet" for n in ("nodes", "edges", "superstructures")}
    outs["summary"] = w / "final1" / "summary-0.json"
    t = time.perf_counter()
    summary = refine_graphs.run(cfg, Files(nodes=raw["nodes"], edges=raw["edges"], candidates=w / "stats1" / "candidates-0.parquet",
                                           **stats), Files(outs), shard=0)
    t_refine = time.perf_counter() - t
    result = {"rooms": summary["rooms"], "extract_stage_seconds": round(t_extract, 2),
              "extract_stage_rooms_per_s": round(ex["rooms"] / t_extract, 1),
              "graph_statistics_seconds": round(t_stats, 2), "refine_seconds": round(t_refine, 2),
              "refine_rooms_per_s": round(summary["rooms"] / t_refine, 1), "cyclic_rooms": summary["cyclic_rooms"],
              "repaired_nodes": summary["repaired"]}
    report(result, w, "refine")


if __name__ == "__main__":
    main()
