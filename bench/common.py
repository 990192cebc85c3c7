"""What every benchmark script shares: the repository root, its command line, the one-shard default
config, and how a result is reported (printed and written as JSON under the work folder)."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from pipeline import config as config_mod
from pipeline.corpus.ingest import OUTPUTS as INGEST_OUTPUTS
from pipeline.stage import Files

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "bench" / "out"


def arguments(doc: str, workdir: Path = OUT) -> argparse.ArgumentParser:
    """A parser whose help is the script's docstring, with ``--workdir``."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--workdir", type=Path, default=workdir)
    return ap


def search_flags(ap: argparse.ArgumentParser) -> None:
    """``--[no-]early-backtrack``, ``--restarts N``, ``--[no-]pose-rules``, ``--[no-]keep-relations``,
    ``--[no-]relations-first`` and ``--[no-]free-support``: the search settings a bench may set (default: the
    config's)."""
    ap.add_argument("--early-backtrack", action=argparse.BooleanOptionalAction)
    ap.add_argument("--restarts", type=int)
    ap.add_argument("--keep-relations", action=argparse.BooleanOptionalAction)
    ap.add_argument("--relations-first", action=argparse.BooleanOptionalAction)
    ap.add_argument("--free-support", action=argparse.BooleanOptionalAction)


def search_overrides(args) -> dict:
    """The ``instantiate`` keys :func:`search_flags` set on the command line (nested sections partly: merge them with
    :func:`pipeline.config.deep_merge`)."""
    out = {k: v for k, v in (("early_backtrack", args.early_backtrack), ("restarts", args.restarts),
                             ("keep_relations", args.keep_relations), ("free_support", args.free_support))
           if v is not None}
    return out | ({} if args.relations_first is None else {"checks": {"relations_first": args.relations_first}})


def search_suffix(args) -> str:
    """The report name's suffix for the search flags given (none: the config's settings)."""
    return ({True: "_early_backtrack", False: "_no_early_backtrack", None: ""}[args.early_backtrack]
            + (f"_restarts{args.restarts}" if args.restarts is not None else "")
            + {True: "_keep_relations", False: "_no_keep_relations", None: ""}[args.keep_relations]
            + {True: "_relations_first", False: "_collisions_first", None: ""}[args.relations_first]
            + {True: "_free_support", False: "_no_free_support", None: ""}[args.free_support])


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
    counts = ingest.run(cfg, Files(), Files({n: p[n] for n in INGEST_OUTPUTS}), shard=0)
    ingest_summary.run(cfg, Files(rooms=[p["rooms"]], objects=[p["objects"]], models=[p["models"]],
                                  reports=[p["ingest_report"]], drops=[p["drops"]]),
                       Files(counts=p["counts"], report=p["summary"], drops=p["all_drops"]))
    t_ingest = time.perf_counter() - t
    t = time.perf_counter()
    filter_rooms.run(cfg, Files(rooms=p["rooms"], architecture=p["architecture"], objects=p["objects"], models=p["models"],
                                counts=p["counts"]), Files(rooms=p["kept"], report=p["filter_report"]))
    return counts, pd.read_parquet(p["filter_report"]), t_ingest, time.perf_counter() - t


def corpus_paths(config: dict) -> dict:
    """The kept corpus's canonical tables per shard, the symmetry and category-size tables (workflow layout)."""
    shards = range(config["shards"])
    rooms = [Path(f"results/filter/shards/rooms-{k}.parquet") for k in shards]
    if not all(p.exists() for p in rooms):
        raise SystemExit(f"{rooms[0].parent}: the filter's {config['shards']} shard(s) are not all there; run the "
                         "pipeline first, or give the config it ran with (--config; default config/config.yaml)")
    return {"rooms": rooms, "splits": Path("results/splits"),
            **{t: [Path(f"results/ingest/shards/{t}-{k}.parquet") for k in shards] for t in ("architecture", "objects", "models")},
            "symmetry": Path("results/graphs/ingested/symmetry.parquet"),
            "category_sizes": Path("results/graphs/ingested/stats/category_sizes.parquet")}
