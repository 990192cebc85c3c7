"""Canonical tables -> per-room :class:`~pipeline.room.RoomInput` arrays (one pass, no per-row pandas), and the one
reader of the kept rooms over every shard."""
from __future__ import annotations

from pathlib import Path
from typing import Iterator

import numpy as np
import pandas as pd

from .. import tables
from .model import BOX_COLUMNS, POSE_COLUMNS, RoomInput


def room_slices(frame: pd.DataFrame) -> dict[str, slice]:
    """Row ranges of each room in a frame whose rows are grouped by room_id (e.g. sorted by it)."""
    ids = frame["room_id"].to_numpy()
    if not len(ids):
        return {}
    change = np.flatnonzero(ids[1:] != ids[:-1]) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [len(ids)]])
    return {ids[s]: slice(s, e) for s, e in zip(starts, ends)}


def room_inputs(rooms: pd.DataFrame, architecture: pd.DataFrame, objects: pd.DataFrame) -> Iterator[RoomInput]:
    """One RoomInput per row of ``rooms`` (in its order), gathering its walls, openings and objects."""
    arch = architecture.sort_values(["room_id", "element_id"], kind="stable").reset_index(drop=True)
    objs = objects.sort_values(["room_id"], kind="stable").reset_index(drop=True)
    a_slices, o_slices = room_slices(arch), room_slices(objs)
    kind = arch["kind"].astype(str).to_numpy()
    a_ids = arch["element_id"].astype(str).to_numpy()
    a_xy = arch[["x0", "y0", "x1", "y1"]].to_numpy(float)
    a_z = arch[["z0", "z1"]].to_numpy(float)
    a_thick = arch["thickness"].astype(float).to_numpy()
    o_ids = objs["object_id"].astype(str).to_numpy()
    o_cat = objs["category"].astype(str).to_numpy()
    o_model = objs["model_id"].astype(str).to_numpy()
    o_box = objs[BOX_COLUMNS].to_numpy(float)
    o_pose = objs[POSE_COLUMNS].to_numpy(float)
    empty = slice(0, 0)
    for room in rooms.itertuples(index=False):
        sa, so = a_slices.get(room.room_id, empty), o_slices.get(room.room_id, empty)
        k = kind[sa]
        wall = k == "wall"
        openings = [{"element_id": e, "kind": kd, "x0": xy[0], "y0": xy[1], "x1": xy[2], "y1": xy[3], "z0": z[0], "z1": z[1]}
                    for e, kd, xy, z in zip(a_ids[sa][~wall], k[~wall], a_xy[sa][~wall], a_z[sa][~wall])]
        yield RoomInput(
            room_id=room.room_id, room_type=str(room.room_type), height=float(room.height),
            outline=np.column_stack([np.asarray(room.floor_x, float), np.asarray(room.floor_y, float)]),
            wall_ids=a_ids[sa][wall].tolist(), wall_segments=a_xy[sa][wall].reshape(-1, 2, 2),
            wall_thickness=a_thick[sa][wall], openings=openings,
            object_ids=o_ids[so].tolist(), categories=o_cat[so].tolist(), model_ids=o_model[so].tolist(),
            boxes=o_box[so].reshape(-1, 7), poses=o_pose[so].reshape(-1, 7))


def load_rooms(rooms: list[Path], architecture: list[Path], objects: list[Path],
               ids: set[str] | None = None) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame, dict[str, RoomInput]]:
    """Canonical rows of the kept rooms (``ids``: only these) over every shard, as one RoomInput per room."""
    flt = [("room_id", "in", sorted(ids))] if ids is not None else None
    room_df = pd.concat([tables.read(p, "rooms", filters=flt).to_pandas() for p in rooms], ignore_index=True)
    arch = pd.concat([tables.read(p, "architecture", filters=flt).to_pandas() for p in architecture], ignore_index=True)
    objs = pd.concat([tables.read(p, "objects", filters=flt).to_pandas() for p in objects], ignore_index=True)
    return room_df, arch, objs, {r.room_id: r for r in room_inputs(room_df, arch, objs)}
