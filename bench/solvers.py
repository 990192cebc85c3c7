"""The annealing methods' rows (issue 29) beside PlanIT's and the real rooms', from a finished run's evaluation and
benchmarks: category KL with its floor, collisions, out of bounds, walkable share, functional checks, the
classifier, seconds per scene, and the learn_program / generate job seconds.

    .venv/bin/python bench/solvers.py [RUN_FOLDER]      # default: the current folder (reads results/, benchmarks/)

Prints one Markdown table per room type (the figures in docs/benchmarks.md come from it)."""
from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

SETS = ("planit", "grains", "grains_decoded", "infinigen", "saog", "real_heldout")
COLUMNS = ("scenes", "category_kl", "cooccurrence_similarity", "object_collision_rate", "out_of_bounds_rate", "walkable_share",
           "functional_all", "sca", "seconds_per_scene")


def job_seconds(run: Path, rule: str, name: str) -> str:
    path = run / "benchmarks" / rule / f"{name}.tsv"
    if not path.exists():
        return ""
    with open(path) as fh:
        return f"{float(next(csv.DictReader(fh, delimiter=chr(9)))['s']):.0f}"


def cell(value) -> str:
    if isinstance(value, dict):
        value = value.get("accuracy")
    return "" if value is None else f"{value:.3g}" if isinstance(value, float) else str(value)


def main() -> None:
    run = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    for path in sorted((run / "results" / "eval").glob("*/metrics.json")):
        m, room_type = json.loads(path.read_text()), path.parent.name
        print(f"\n{room_type} (category KL floor {m['floors']['category_kl']['mean']:.3f})\n")
        print("| set | " + " | ".join(COLUMNS) + " | learn_program s | generate s |")
        print("| --- |" + " ---: |" * (len(COLUMNS) + 2))
        for name in SETS:
            s = m["sets"].get(name)
            if s is None:
                continue
            learn = job_seconds(run, "learn_program", f"{room_type}-{name}") or job_seconds(run, "train_placement", f"{room_type}-{name}")
            gen = job_seconds(run, "generate", f"{room_type}-{name}")
            print(f"| {name} | " + " | ".join(cell(s.get(c)) for c in COLUMNS) + f" | {learn} | {gen} |")


if __name__ == "__main__":
    main()
