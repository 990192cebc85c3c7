"""One run's evaluation, the figures issue 40 names, per room type for chosen methods beside the held-out real rooms:
functional_all, the single functional check furthest from real (and its gap), graph consistency, relaxed share,
collisions, the walkable share (door-connected share of the free floor), the largest off-axis gap to the training
rooms, category KL against its floor, SCA with the power check's verdict, median seconds per scene.

    .venv/bin/python bench/eval_table.py RUN [--methods planit planit_prior] [--types bedroom living ...]

RUN: a work folder with results/eval/<type>/metrics.json. Prints Markdown.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

REAL = "real_heldout"


def worst_check(entry: dict, real: dict) -> tuple[str, float]:
    """The functional check (``fn:`` column) with the largest shortfall against the real rooms, and that gap."""
    gaps = {k: real[k] - entry[k] for k in entry if k.startswith("fn:") and entry.get(k) is not None
            and real.get(k) is not None}
    if not gaps:
        return "-", 0.0
    k = max(gaps, key=gaps.get)
    return k[3:], gaps[k]


def median_seconds(run: Path, room_type: str, name: str) -> float | None:
    """The generated set's median seconds per scene (its summary.json), None for real rooms or where absent."""
    path = run / "results" / "generated" / room_type / name / "summary.json"
    return json.loads(path.read_text()).get("median_seconds") if path.exists() else None


def row(name: str, entry: dict, real: dict, metrics: dict, median: float | None) -> str:
    floor = metrics["floors"]["category_kl"]["mean"]
    check, gap = worst_check(entry, real) if name != REAL else ("-", 0.0)
    off = entry.get("off_axis_gap")
    sca = entry.get("sca") or {}
    fmt = lambda v, d=3: "-" if v is None else f"{v:.{d}f}"
    return (f"| {name} | {entry.get('scenes')}/{entry.get('attempted')} | {fmt(entry.get('functional_all'), 2)} | "
            f"{check} {-gap:+.2f} | {fmt(entry.get('consistency'))} | {fmt(entry.get('relaxed_share'))} | "
            f"{fmt(entry.get('object_collision_rate'))} | {fmt(entry.get('walkable_share'))} | {fmt(off, 2)} | "
            f"{entry['category_kl'] / floor:.1f}x | "
            f"{fmt(sca.get('accuracy'), 1)} | {fmt(median, 2)} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", type=Path)
    ap.add_argument("--methods", nargs="+", default=["planit", "planit_prior"])
    ap.add_argument("--types", nargs="+", default=["bedroom", "living", "office", "kitchen", "bathroom"])
    args = ap.parse_args()
    print("| set | scenes/attempted | functional_all | worst check vs real | consistency | relaxed | collisions | "
          "walkable | off-axis gap | KL / floor | SCA % | median s/scene |")
    print("|---" * 12 + "|")
    for room_type in args.types:
        path = args.run / "results" / "eval" / room_type / "metrics.json"
        if not path.exists():
            continue
        metrics = json.loads(path.read_text())
        sets, real = metrics["sets"], metrics["sets"][REAL]
        print(f"| **{room_type}** (power check {'passed' if metrics['power'].get('passed') else 'FAILED'}) |" + " |" * 11)
        for name in [*args.methods, REAL]:
            if name in sets:
                print(row(name, sets[name], real, metrics, median_seconds(args.run, room_type, name)))


if __name__ == "__main__":
    main()
