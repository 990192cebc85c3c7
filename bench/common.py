"""What every benchmark script shares: the repository root, its command line, the one-shard default
config, and how a result is reported (printed and written as JSON under the work folder)."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from pipeline import config as config_mod

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "bench" / "out"


def arguments(doc: str, workdir: Path = OUT) -> argparse.ArgumentParser:
    """A parser whose help is the script's docstring, with ``--workdir``."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--workdir", type=Path, default=workdir)
    return ap


def search_flags(ap: argparse.ArgumentParser) -> None:
    """``--[no-]early-backtrack`` and ``--restarts N``: the search settings a bench may set (default: the config's)."""
    ap.add_argument("--early-backtrack", action=argparse.BooleanOptionalAction)
    ap.add_argument("--restarts", type=int)


def search_overrides(args) -> dict:
    """The ``instantiate`` keys :func:`search_flags` set on the command line."""
    return {k: v for k, v in (("early_backtrack", args.early_backtrack), ("restarts", args.restarts)) if v is not None}


def search_suffix(args) -> str:
    """The report name's suffix for the search flags given (none: the config's settings)."""
    return ({True: "_early_backtrack", False: "_no_early_backtrack", None: ""}[args.early_backtrack]
            + (f"_restarts{args.restarts}" if args.restarts is not None else ""))


def default_config() -> dict:
    """config/config.yaml with a single shard (benchmarks time one process)."""
    return config_mod.load(ROOT / "config" / "config.yaml", json.dumps({"shards": 1}))


def report(result: dict, workdir: Path, name: str) -> None:
    """Print ``result`` and write it to ``workdir/name.json``."""
    workdir.mkdir(parents=True, exist_ok=True)
    text = json.dumps(result, indent=2)
    (workdir / f"{name}.json").write_text(text)
    print(text)


def shard_paths(workdir: Path) -> dict[str, Path]:
    """Where the one-shard benchmark corpus lives under ``workdir``."""
    names = ("rooms", "architecture", "objects", "models", "ground_truth", "ingest_report", "drops")
    paths = {n: workdir / "ingest" / f"{n}-0.parquet" for n in names}
    paths.update(counts=workdir / "ingest" / "category_counts.parquet", summary=workdir / "ingest" / "report.parquet",
                 all_drops=workdir / "ingest" / "drops.parquet",
                 kept=workdir / "filter" / "rooms-0.parquet", filter_report=workdir / "filter" / "report-0.parquet",
                 symmetry=workdir / "symmetry" / "symmetry.parquet", agreement=workdir / "symmetry" / "agreement.json")
    return paths


def ingest_and_filter(cfg: dict, p: dict[str, Path]) -> tuple[dict, object, float, float]:
    """Run the ingest, ingest-summary and filter stages on one shard; returns counts, the filter report and the
    seconds of ingest and of filter."""
    import time

    import pandas as pd

    from pipeline.stages import filter_rooms, ingest, ingest_summary

    t = time.perf_counter()
    counts = ingest.run(cfg, 0, {n: p[n] for n in ingest.OUTPUTS})
    ingest_summary.run([p["rooms"]], [p["objects"]], [p["models"]], [p["ingest_report"]], [p["drops"]], p["counts"],
                       p["summary"], p["all_drops"])
    t_ingest = time.perf_counter() - t
    t = time.perf_counter()
    filter_rooms.run(cfg, p["rooms"], p["architecture"], p["objects"], p["models"], p["counts"], p["kept"], p["filter_report"])
    return counts, pd.read_parquet(p["filter_report"]), t_ingest, time.perf_counter() - t
