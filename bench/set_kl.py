"""Category KL of generated rooms against one split's real rooms (every ingested object of the split's rooms), for
sets placed outside the pipeline's own folders (a job's command rerun with one setting changed):

    .venv/bin/python bench/set_kl.py RUN TYPE SPLIT SET_DIR [SET_DIR ...]

RUN: a pipeline run's folder (its results/ingest/shards and results/splits); SPLIT: heldout or validation; each
SET_DIR holds a generate job's objects.parquet and scenes.parquet (only the scenes placed, partial included, count).
Prints one line per set: its rooms, objects per room and KL (``distributions.category_kl``, the evaluation's)."""
from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd

from pipeline import tables
from pipeline.evaluation.distributions import category_kl


def split_categories(run: Path, room_type: str, split: str) -> list[str]:
    """One category label per ingested object of the room type's rooms in ``split``."""
    rooms = pd.read_parquet(run / "results" / "splits" / f"{room_type}.parquet")
    ids = set(rooms.loc[rooms["split"] == split, "room_id"])
    if not ids:
        raise SystemExit(f"{run}/results/splits/{room_type}.parquet: no room in split '{split}'")
    objects = pd.concat(pd.read_parquet(p) for p in sorted((run / "results" / "ingest" / "shards").glob("objects-*.parquet")))
    return objects.loc[objects["room_id"].isin(ids), "category"].astype(str).tolist()


def main() -> None:
    if len(sys.argv) < 5:
        raise SystemExit(__doc__)
    run, room_type, split = Path(sys.argv[1]), sys.argv[2], sys.argv[3]
    real = split_categories(run, room_type, split)
    for folder in map(Path, sys.argv[4:]):
        scenes = pd.read_parquet(folder / "scenes.parquet")
        placed = set(scenes.loc[scenes["status"].astype(str).isin(tables.SCORED), "scene_id"])
        objects = pd.read_parquet(folder / "objects.parquet")
        cats = objects.loc[objects["room_id"].isin(placed), "category"].astype(str).tolist()
        print(f"{folder}: rooms {len(placed)}, objects per room {len(cats) / max(len(placed), 1):.1f}, "
              f"KL vs {split} {category_kl(real, cats):.3f}")


if __name__ == "__main__":
    main()
