"""Compare two results/ folders: the same Parquet files, equal as tables (schema and rows), same JSON metrics.

    python tests/slurm/compare_runs.py RESULTS_A RESULTS_B
"""
import json
import sys
from pathlib import Path

import pyarrow.parquet as pq


def main(a: Path, b: Path) -> int:
    fa = sorted(p.relative_to(a) for p in a.rglob("*.parquet"))
    fb = sorted(p.relative_to(b) for p in b.rglob("*.parquet"))
    if fa != fb:
        print(f"different table files: {sorted(set(fa) ^ set(fb))}")
        return 1
    bad = []
    for rel in fa:
        ta, tb = pq.read_table(a / rel), pq.read_table(b / rel)
        if not ta.equals(tb):
            bad.append(str(rel))
    for rel in sorted(p.relative_to(a) for p in a.rglob("metrics/*.json")):
        if json.loads((a / rel).read_text()) != json.loads((b / rel).read_text()):
            bad.append(str(rel))
    if bad:
        print(f"{len(bad)} output(s) differ: {bad}")
        return 1
    print(f"{len(fa)} tables identical")
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]), Path(sys.argv[2])))
