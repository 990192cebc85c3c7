"""3D-FRONT ingest throughput on the 9-house sample (../shared/data/3d-front-sample): rooms/s with an empty mesh
cache and with a warm one (parsed OBJ meshes are cached as .npz, so a re-run does not re-parse them), and how
many outline walls a WallInner mesh backs.

    .venv/bin/python bench/front3d.py [--sample ../shared/data/3d-front-sample] [--repeat 5]
"""
from __future__ import annotations

import shutil
import statistics
import time
from pathlib import Path

import pandas as pd

from pipeline import config as config_mod
from pipeline.corpus.ingest import OUTPUTS
from pipeline.stage import Files
from pipeline.stages import ingest

from common import OUT, ROOT, arguments, report


def main() -> None:
    ap = arguments(__doc__, OUT / "front3d")
    ap.add_argument("--sample", type=Path, default=ROOT.parent / "shared" / "data" / "3d-front-sample")
    ap.add_argument("--repeat", type=int, default=5, help="runs: the first with an empty cache, the rest warm (>= 2)")
    args = ap.parse_args()
    if args.repeat < 2:
        ap.error("--repeat must be at least 2: one cold run, then warm ones")
    cache = args.workdir / "cache"
    shutil.rmtree(cache, ignore_errors=True)
    cfg = config_mod.validate({"source": "front3d", "shards": 1, "front3d": {"houses": str(args.sample / "houses"),
                                                                "future": str(args.sample / "3d-future"), "cache_dir": str(cache)}})
    times = []
    for _ in range(args.repeat):
        t = time.perf_counter()
        counts = ingest.run(cfg, Files(), Files({n: args.workdir / "ingest" / f"{n}.parquet" for n in OUTPUTS}), shard=0)
        times.append(time.perf_counter() - t)
    warm = statistics.median(times[1:])
    rep = pd.read_parquet(args.workdir / "ingest" / "ingest_report.parquet")
    walls = rep[rep.kind == "wall"].set_index("status")["count"]
    result = {"houses": len(list((args.sample / "houses").glob("*.json"))), "rooms": counts["rooms"],
              "objects": counts["objects"], "first_run_seconds": round(times[0], 2),
              "warm_runs_median_seconds": round(warm, 2), "rooms_per_s_warm": round(counts["rooms"] / warm, 1),
              "walls_backed": int(walls.get("backed", 0)), "walls_open": int(walls.get("open", 0))}
    report(result, args.workdir, "front3d")


if __name__ == "__main__":
    main()
