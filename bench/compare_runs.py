"""Compare two runs' results/ folders value by value: every Parquet table (wall-clock columns aside), every JSON
and CSV file (timing keys and columns aside), and the trained weights of every model file.

    .venv/bin/python bench/compare_runs.py RESULTS_BEFORE RESULTS_AFTER [--rename OLD=NEW ...] [--unordered GLOB ...]

``--rename OLD=NEW`` maps a path prefix of the first run to the second's (a folder renamed between them);
``--unordered GLOB``: tables matching GLOB are compared as sets of rows (their row order changed on purpose). The exit
status is 0 when everything that exists in the first run exists in the second with the same values.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq

TIMING = {"seconds", "median_seconds", "train_seconds", "graphs_per_s", "strings_per_s", "trees_per_s", "seconds_per_scene",
          "seconds_to_within_2pct_of_best"}
SKIP = {"runtime.csv"}  # the run's own wall-clock table


def _strip(value):
    if isinstance(value, dict):
        return {k: _strip(v) for k, v in value.items() if k not in TIMING}
    if isinstance(value, list):
        return [_strip(v) for v in value]
    return value


def same_table(a: Path, b: Path, unordered: bool = False) -> bool:
    ta, tb = pq.read_table(a), pq.read_table(b)
    drop = lambda t: t.drop_columns([c for c in TIMING if c in t.column_names])
    if not unordered:
        return drop(ta).equals(drop(tb))
    rows = lambda t: sorted(map(repr, drop(t).to_pylist()))
    return ta.schema.equals(tb.schema) and rows(ta) == rows(tb)


def same_csv(a: Path, b: Path) -> bool:
    """The same rows (in any order: the graph report's ties were listed in an arbitrary order before 2026-12)."""
    fa, fb = pd.read_csv(a), pd.read_csv(b)
    drop = lambda f: f.drop(columns=[c for c in f.columns if c in TIMING])
    rows = lambda f: f.astype(str).sort_values(list(f.columns)).reset_index(drop=True)
    return list(fa.columns) == list(fb.columns) and rows(drop(fa)).equals(rows(drop(fb)))


def same_json(a: Path, b: Path) -> bool:
    return _strip(json.loads(a.read_text())) == _strip(json.loads(b.read_text()))


def _tensors(path: Path) -> dict:
    """Every tensor of a model file, by its key path (old untyped dicts and typed checkpoints alike)."""
    import torch

    raw = torch.load(path, map_location="cpu", weights_only=False)
    out = {}

    def walk(v, key):
        if isinstance(v, torch.Tensor):
            out[key.split("/state_dict")[-1].split("/model")[-1].split("/state")[-1]] = v
        elif isinstance(v, dict):
            for k, x in v.items():
                walk(x, f"{key}/{k}")
        elif isinstance(v, (list, tuple)):
            for i, x in enumerate(v):
                walk(x, f"{key}/{i}")

    walk(raw.get("state", raw) if isinstance(raw, dict) else raw, "")
    return out


def same_weights(a: Path, b: Path) -> bool:
    ta, tb = _tensors(a), _tensors(b)
    va, vb = sorted(ta.values(), key=lambda t: (tuple(t.shape), float(t.double().sum()))), \
        sorted(tb.values(), key=lambda t: (tuple(t.shape), float(t.double().sum())))
    return len(va) == len(vb) and all(x.shape == y.shape and bool((x == y).all()) for x, y in zip(va, vb))


CHECKS = {".parquet": same_table, ".csv": same_csv, ".json": same_json}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before", type=Path)
    ap.add_argument("after", type=Path)
    ap.add_argument("--rename", action="append", default=[], help="OLD=NEW path prefix of the first run in the second")
    ap.add_argument("--unordered", action="append", default=[], help="GLOB of tables compared as sets of rows")
    args = ap.parse_args()
    renames = [r.split("=", 1) for r in args.rename]
    counts, bad = {}, []
    for f in sorted(args.before.rglob("*")):
        rel = str(f.relative_to(args.before))
        if not f.is_file() or f.name in SKIP or f.name == "checkpoint.pt" or f.suffix not in (*CHECKS, ".pt"):
            continue
        for old, new in renames:
            rel = new + rel[len(old):] if rel.startswith(old) else rel
        g = args.after / rel
        check = same_weights if f.suffix == ".pt" else CHECKS[f.suffix]
        if any(Path(rel).match(p) for p in args.unordered):
            check = lambda x, y: same_table(x, y, unordered=True)
        if not g.exists() or not check(f, g):
            bad.append(rel + ("" if g.exists() else " (missing)"))
        counts[f.suffix] = counts.get(f.suffix, 0) + 1
    print(" ".join(f"{n} {k[1:]}" for k, n in sorted(counts.items())), "compared;",
          f"{len(bad)} differ" + (f": {bad}" if bad else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
