"""The tests two runs of pytest ``--durations=0`` both hold, compared one by one (setup, call and teardown summed):
what bench/test_side_by_side.sh prints its logs for.

    .venv/bin/python bench/test_durations.py BEFORE.log AFTER.log
"""
from __future__ import annotations

import re
import sys

LINE = re.compile(r"\s*([\d.]+)s (call|setup|teardown)\s+(\S+)")


def durations(path: str) -> dict[str, float]:
    """Test id -> seconds (setup + call + teardown) from a pytest log with ``--durations=0``."""
    out: dict[str, float] = {}
    for line in open(path, encoding="utf-8"):
        if m := LINE.match(line):
            out[m.group(3)] = out.get(m.group(3), 0.0) + float(m.group(1))
    return out


def main() -> None:
    before, after = durations(sys.argv[1]), durations(sys.argv[2])
    common = sorted(set(before) & set(after))
    print(f"tests timed: {len(before)} before, {len(after)} after, {len(common)} in both")
    print(f"the tests in both: {sum(before[t] for t in common):.1f} s before, {sum(after[t] for t in common):.1f} s after")
    print(f"only after: {len(set(after) - set(before))} tests, {sum(after[t] for t in set(after) - set(before)):.1f} s")
    for t in sorted(common, key=lambda t: after[t] - before[t])[-5:]:
        print(f"{before[t]:7.1f} {after[t]:7.1f}  {t}")


if __name__ == "__main__":
    main()
