"""Compare two results/ folders as tables (schema and rows, wall-clock columns aside) and their JSON metrics.

    python tests/slurm/compare_runs.py RESULTS_A RESULTS_B              every table file, row for row
    python tests/slurm/compare_runs.py --gathered RESULTS_A RESULTS_B   only dataset-level tables, ignoring shard
                                                                        numbers and row order (runs with different
                                                                        shard counts must agree on these)
"""
import json
import sys
from pathlib import Path

import pyarrow.parquet as pq

GATHERED = ["ingest/ingest_report.parquet", "ingest/category_counts.parquet", "filter/report.parquet",
            "graphs/ingested/symmetry.parquet", "graphs/ingested/nodes.parquet", "graphs/ingested/edges.parquet",
            "graphs/ingested/superstructures.parquet", *(f"graphs/ingested/stats/{n}.parquet" for n in
                                                         ("cooccurrence", "relations", "hub_patterns", "category_sizes"))]


def _canonical(path: Path):
    """A table without shard numbers, rows in a canonical order."""
    df = pq.read_table(path).to_pandas()
    df = df.drop(columns=[c for c in df.columns if c == "shard"])
    df = df.astype({c: object for c in df.columns if str(df[c].dtype) == "category"})
    keys = [c for c in df.columns if not df[c].map(lambda v: isinstance(v, (list, tuple)) or hasattr(v, "tolist")).any()]
    return df.sort_values(keys, na_position="first", kind="stable").reset_index(drop=True)


TIMINGS = ("seconds",)  # wall-clock columns (instantiation's seconds per scene) differ between any two runs


def _table(path: Path):
    t = pq.read_table(path)
    return t.drop_columns([c for c in TIMINGS if c in t.column_names])


def _same(a: Path, b: Path, gathered: bool) -> bool:
    if not gathered:
        return _table(a).equals(_table(b))
    x, y = _canonical(a), _canonical(b)
    return list(x.columns) == list(y.columns) and x.map(repr).equals(y.map(repr))


def main(a: Path, b: Path, gathered: bool = False) -> int:
    if gathered:
        fa = fb = [Path(p) for p in GATHERED]
    else:
        fa = sorted(p.relative_to(a) for p in a.rglob("*.parquet"))
        fb = sorted(p.relative_to(b) for p in b.rglob("*.parquet"))
    if fa != fb:
        print(f"different table files: {sorted(set(fa) ^ set(fb))}")
        return 1
    bad = [str(rel) for rel in fa if not _same(a / rel, b / rel, gathered)]
    for rel in sorted(p.relative_to(a) for p in a.rglob("metrics/**/*.json")):
        if json.loads((a / rel).read_text()) != json.loads((b / rel).read_text()):
            bad.append(str(rel))
    if bad:
        print(f"{len(bad)} output(s) differ: {bad}")
        return 1
    print(f"{len(fa)} tables identical")
    return 0


if __name__ == "__main__":
    args = sys.argv[1:]
    flag = "--gathered" in args
    paths = [Path(p) for p in args if p != "--gathered"]
    sys.exit(main(paths[0], paths[1], flag))
