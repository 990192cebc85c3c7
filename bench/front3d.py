"""3D-FRONT ingest throughput on the 9-house sample (../shared/data/3d-front-sample): rooms/s with an empty mesh
cache and with a warm one (parsed OBJ meshes are cached as .npz, so a re-run does not re-parse them).

    .venv/bin/python bench/front3d.py [--sample ../shared/data/3d-front-sample] [--repeat 5]
"""
from __future__ import annotations

import argparse
import json
import shutil
import time
from pathlib import Path

from pipeline import config as config_mod
from pipeline.stages import ingest

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sample", type=Path, default=ROOT.parent / "shared" / "data" / "3d-front-sample")
    ap.add_argument("--workdir", type=Path, default=ROOT / "bench" / "out" / "front3d")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    cache = args.workdir / "cache"
    shutil.rmtree(cache, ignore_errors=True)
    cfg = config_mod.validate({"source": "front3d", "front3d": {"houses": str(args.sample / "houses"),
                                                                "future": str(args.sample / "3d-future"), "cache_dir": str(cache)}})
    times = []
    for _ in range(args.repeat):
        t = time.perf_counter()
        counts = ingest.run(cfg, args.workdir / "ingest")
        times.append(time.perf_counter() - t)
    result = {"houses": len(list((args.sample / "houses").glob("*.json"))), "rooms": counts["rooms"],
              "objects": counts["objects"], "first_run_seconds": round(times[0], 2),
              "warm_runs_median_seconds": round(sorted(times[1:])[len(times[1:]) // 2], 2),
              "rooms_per_s_warm": round(counts["rooms"] / sorted(times[1:])[len(times[1:]) // 2], 1)}
    (args.workdir / "front3d.json").write_text(json.dumps(result, indent=2))
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
