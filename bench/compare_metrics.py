"""Two runs' evaluation tables side by side: for every room type and every method in both runs, each quality figure
of the first run with its 95% interval, the second run's figure, and whether it moved outside that interval (the
check that a speed-up did not change outcomes; issue 41). SCA is compared to its interval the same way.

    .venv/bin/python bench/compare_metrics.py RUN_BEFORE RUN_AFTER [--figures category_kl functional_all ...]

RUN_* are work folders (holding results/eval/<type>/metrics.json). Prints one Markdown table per room type; exits 1
when a figure moved outside its interval, 0 otherwise.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

FIGURES = ("category_kl", "functional_all", "consistency", "object_collision_rate", "violation", "sca",
           "seconds_per_scene")
TIMING = {"seconds_per_scene"}  # reported, never a move


def load(run: Path) -> dict[str, dict]:
    """Room type -> that type's metrics.json ``sets`` (method -> figures, with ``intervals`` and ``sca``)."""
    return {p.parent.name: json.loads(p.read_text())["sets"] for p in sorted(run.glob("results/eval/*/metrics.json"))}


def figure(entry: dict, name: str) -> tuple[float, tuple[float, float] | None]:
    """A method's figure and its 95% interval (None when the run has none)."""
    if name == "sca":
        sca = entry.get("sca") or {}  # a set too small for the classifier holds no accuracy
        ci = (sca["low"], sca["high"]) if sca.get("low") is not None else None
        return float("nan") if sca.get("accuracy") is None else float(sca["accuracy"]), ci
    ci = (entry.get("intervals") or {}).get(name)
    ci = ci if ci and None not in ci else None
    value = entry.get(name)
    return float("nan") if value is None else float(value), tuple(ci) if ci else None


def compare(before: dict, after: dict, figures=FIGURES) -> tuple[list[str], int]:
    """Markdown lines for every room type in both runs, and the number of figures that moved outside their interval."""
    lines, moved = [], 0
    for room_type in sorted(set(before) & set(after)):
        lines += [f"\n### {room_type}\n", "| method | " + " | ".join(figures) + " |", "|---" * (len(figures) + 1) + "|"]
        for method in sorted(set(before[room_type]) & set(after[room_type])):
            cells = []
            for name in figures:
                a, ci = figure(before[room_type][method], name)
                b, _ = figure(after[room_type][method], name)
                out = ci is not None and name not in TIMING and not math.isnan(b) and not ci[0] - 1e-9 <= b <= ci[1] + 1e-9
                moved += out
                band = f" [{ci[0]:.3g}, {ci[1]:.3g}]" if ci else ""
                cells.append(f"{a:.3g}{band} -> {b:.3g}{' **moved**' if out else ''}")
            lines.append(f"| {method} | " + " | ".join(cells) + " |")
    return lines, moved


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("before", type=Path)
    ap.add_argument("after", type=Path)
    ap.add_argument("--figures", nargs="+", default=list(FIGURES))
    args = ap.parse_args(argv)
    before, after = load(args.before), load(args.after)
    if not before or not after:
        sys.exit(f"no results/eval/*/metrics.json under {args.before if not before else args.after}")
    lines, moved = compare(before, after, args.figures)
    print("\n".join(lines))
    print(f"\n{moved} figure(s) outside the first run's 95% interval")
    return 1 if moved else 0


if __name__ == "__main__":
    sys.exit(main())
