"""The whole workflow on N procedural rooms, end to end on this machine: wall time, time per rule, peak memory per job.

    .venv/bin/python bench/scale.py --rooms 20000 [--shards 8] [--cores 2] [--workdir bench/out/scale-20000]

Rooms are split over the five room types in the default config's proportions. Per-job seconds and peak
resident memory come from Snakemake's own benchmark files (``benchmarks/<rule>/*.tsv``).
"""
from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

from pipeline.stages import runtime

from common import ROOT, arguments, report

MIX = {"bedroom": 500, "living": 400, "office": 350, "bathroom": 400, "kitchen": 400}


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--rooms", type=int, default=20000)
    ap.add_argument("--shards", type=int, default=8)
    ap.add_argument("--cores", type=int, default=2)
    args = ap.parse_args()
    work = args.workdir if args.workdir.name.startswith("scale") else args.workdir / f"scale-{args.rooms}"
    work.mkdir(parents=True, exist_ok=True)
    total = sum(MIX.values())
    rooms = {t: n * args.rooms // total for t, n in MIX.items()}
    rooms["bedroom"] += args.rooms - sum(rooms.values())  # exactly --rooms
    cfg = work / "config.yaml"
    cfg.write_text((ROOT / "config" / "config.yaml").read_text() + f"\n# bench/scale.py\nshards: {args.shards}\n"
                   f"procedural:\n  rooms: {rooms}\n")
    t0 = time.perf_counter()
    subprocess.run([str(Path(sys.executable).parent / "snakemake"), "--snakefile", str(ROOT / "Snakefile"), "-d", str(work),
                    "--configfile", str(cfg), "--cores", str(args.cores), "-q"], check=True)
    wall = time.perf_counter() - t0
    rules = runtime.per_rule(runtime.read_benchmarks(work / "benchmarks")).iloc[2:]  # per rule, summary rows aside
    result = {"rooms": sum(rooms.values()), "shards": args.shards, "cores": args.cores, "wall_seconds": round(wall, 1),
              "job_seconds_per_rule": dict(zip(rules.rule, rules.job_seconds)),
              "peak_rss_mb_per_rule": dict(zip(rules.rule, rules.peak_rss_mb)),
              "peak_rss_mb": float(rules.peak_rss_mb.max()) if len(rules) else 0.0}
    report(result, args.workdir, f"scale-{args.rooms}")


if __name__ == "__main__":
    main()
