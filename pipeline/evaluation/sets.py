"""The room sets the evaluation scores: every method's generated rooms, the training and the held-out real rooms of a
room type, each as RoomInputs with their objects' support parents."""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from .. import tables
from ..errors import InputError
from ..room import RoomInput, room_inputs
from ..tables import SCORED

REAL = "real_heldout"


@dataclass
class RoomSet:
    """Rooms of one set with each object's support parent and, for generated sets, the instantiation records."""
    name: str
    rooms: list[RoomInput]
    parents: list[list[str | None]]
    scenes: pd.DataFrame | None = None  # scene_id, consistency, violation (placed scenes)
    attempted: int = 0


def room_set(name: str, rooms: pd.DataFrame, architecture: pd.DataFrame, objects: pd.DataFrame,
             scenes: pd.DataFrame | None = None) -> RoomSet:
    objs = objects.sort_values("room_id", kind="stable")
    parents = {k: g["source_parent_id"].tolist() for k, g in objs.groupby("room_id", sort=False)}
    inputs = list(room_inputs(rooms, architecture, objs))
    return RoomSet(name, inputs, [parents.get(r.room_id, []) for r in inputs], scenes, len(rooms))


def load_generated(name: str, rooms: Path, architecture: Path, objects: Path, scenes: Path) -> RoomSet:
    """A method's placed scenes, partial ones included (failed ones are counted, not scored)."""
    scene_df = tables.read(scenes, "scenes").to_pandas()
    placed = set(scene_df.loc[scene_df["status"].astype(str).isin(SCORED), "scene_id"])
    room_df = tables.read(rooms, "rooms").to_pandas()
    out = room_set(name, room_df[room_df["room_id"].isin(placed)], tables.read(architecture, "architecture").to_pandas(),
                   tables.read(objects, "generated_objects").to_pandas(), scene_df[scene_df["scene_id"].isin(placed)])
    out.attempted = len(scene_df)
    return out


def generated_sets(summaries: list[Path], rooms: list[Path], architecture: list[Path], objects: list[Path],
                   scenes: list[Path]) -> list[RoomSet]:
    """Each method's rooms (its name from its summary), in the order given (the first is the gallery's)."""
    names = [json.loads(Path(s).read_text())["variant"] for s in summaries]
    return [load_generated(n, r, a, o, s) for n, r, a, o, s in zip(names, rooms, architecture, objects, scenes)]


def load_real(room_type: str, split: dict[str, str], rooms: list[Path], architecture: list[Path],
              objects: list[Path]) -> tuple[RoomSet, RoomSet]:
    """The training (fit and validation) and held-out real rooms of ``room_type``, by its split."""
    ids = sorted(split)
    if len(ids) < 2:
        raise InputError(f"room type '{room_type}': fewer than 2 rooms in its split to evaluate against")
    train = {r for r, s in split.items() if s in ("fit", "validation")}
    held = {r for r, s in split.items() if s == "heldout"}
    flt = [("room_id", "in", ids)]
    frames = [pd.concat([tables.read(p, t, filters=flt).to_pandas() for p in paths], ignore_index=True)
              for paths, t in ((rooms, "rooms"), (architecture, "architecture"), (objects, "objects"))]
    pick = lambda keep, name: room_set(name, frames[0][frames[0]["room_id"].isin(keep)], frames[1],
                                       frames[2][frames[2]["room_id"].isin(keep)])
    return pick(train, "real_train"), pick(held, REAL)
