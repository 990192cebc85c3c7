"""Exports of generated rooms (issue 44): seconds of `planit export FORMAT SET` per format (a fresh process pinned to
one core with taskset: imports, reading the tables and writing every room), and the 3D-FRONT round trip on every
room (the project's own ingest reads the houses back: the same objects, poses within 1 mm and 0.1 degree, and the
same relation graph, edge by edge).

    .venv/bin/python bench/export.py results/generated/bedroom/planit [more generated sets or corpus shards ...]
        [--formats usd procthor front3d] [--no-round-trip] [--workdir bench/out/export]

Goals: every room of every set exports in all three formats; the round trip reproduces the graph on every room;
each format writes one room type's 30 rooms in at most 10 s on one core. The round trip compares the read-back room with the numbers the
reader rounds (yaws on the original's branch, floor corners moved by its 0.1 mm buffer) taken from the original
(`roundtrip.as_written`); `differing_as_read` lists the rooms whose graph differs with every number as read.
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

from pipeline import config as config_mod
from pipeline.export import FORMATS, roundtrip
from pipeline.export.rooms import load_set, table_paths

from common import OUT, ROOT, arguments, report

PLANIT = Path(sys.executable).parent / "planit"


def timed_export(fmt: str, folder: Path, out: Path) -> dict:
    """One `planit export` in a fresh process on one core: its wall seconds and the summary it wrote."""
    shutil.rmtree(out, ignore_errors=True)
    pin = ["taskset", "-c", "0"] if shutil.which("taskset") else []
    start = time.perf_counter()
    proc = subprocess.run([*pin, str(PLANIT), "export", fmt, str(folder), "--out", str(out)], capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if proc.returncode != 0:
        return {"error": proc.stderr.strip().splitlines()[-1]}
    summary = json.loads((out / "export.json").read_text())
    return {"seconds": round(seconds, 2), "rooms": summary["rooms"], "objects": summary["objects"],
            **({"unmapped": summary["unmapped"]} if "unmapped" in summary else {})}


def round_trip(folder: Path, exported: Path, cfg: dict) -> dict:
    """The 3D-FRONT export of ``folder`` read back and compared room by room."""
    original = load_set(table_paths(folder), str(folder))
    back = roundtrip.reingest(exported)
    pairs = roundtrip.by_original(back, original)
    offsets, turns, differing, as_read, edges = [0.0], [0.0], [], [], 0
    for room in original.rooms:
        b = pairs.get(room.room_id)
        if b is None:
            differing.append({"room": room.room_id, "why": "not read back"})
            continue
        offset, turn = roundtrip.pose_errors(room, b)
        missing, extra = roundtrip.graph_difference(room, b, original, back, cfg)
        if any(roundtrip.graph_difference(room, b, original, back, cfg, as_read=True)):
            as_read.append(room.room_id)
        offsets.append(offset)
        turns.append(turn)
        edges += len(roundtrip._edges(room, original, cfg, {}))
        if missing or extra or offset > 1e-3 or turn > 0.1 or b.model_ids != room.model_ids:
            differing.append({"room": room.room_id, "missing": sorted(map(str, missing))[:5],
                              "extra": sorted(map(str, extra))[:5], "offset_m": offset, "turn_deg": turn})
    return {"rooms": len(original.rooms), "read_back": len(pairs), "edges_compared": edges,
            "max_offset_m": max(offsets), "max_turn_deg": max(turns), "differing": differing,
            "differing_as_read": as_read}


def main() -> None:
    ap = arguments(__doc__, OUT / "export")
    ap.add_argument("sets", type=Path, nargs="+", help="generated sets (results/generated/<type>/<method>) or shards")
    ap.add_argument("--formats", nargs="+", choices=FORMATS, default=list(FORMATS))
    ap.add_argument("--round-trip", action=argparse.BooleanOptionalAction, default=True)
    args = ap.parse_args()
    cfg = config_mod.load(ROOT / "config" / "config.yaml")
    results = {}
    for folder in args.sets:
        name = f"{folder.parent.name}/{folder.name}"
        out = args.workdir / folder.parent.name / folder.name
        row = {fmt: timed_export(fmt, folder, out / fmt) for fmt in args.formats}
        if args.round_trip and "front3d" in row and "error" not in row["front3d"]:
            row["round_trip"] = round_trip(folder, out / "front3d", cfg)
        results[name] = row
        print(name, json.dumps(row), flush=True)
    seconds = [r[f]["seconds"] for r in results.values() for f in args.formats if "seconds" in r[f]]
    goals = {"every_room_in_every_format": all("error" not in r[f] for r in results.values() for f in args.formats),
             "graph_reproduced_on_every_room": all(not r.get("round_trip", {"differing": [1]})["differing"]
                                                   for r in results.values()),
             "max_seconds_per_set_and_format": max(seconds, default=None)}
    report({"sets": results, "goals": goals}, args.workdir, "export")


if __name__ == "__main__":
    main()
