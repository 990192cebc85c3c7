"""Legacy SUNCG houses (``house.json``, format suncg@1.0.0) -> canonical tables.

A house lists levels of nodes; Room nodes name their objects in ``nodeIndices``; Object nodes carry
``modelId``, a column-major 4x4 ``transform`` and a world ``bbox`` (Y-up, metres times ``scaleToMeters``).
The room's architecture is NOT in house.json: SUNCG shipped it as separate files per room,
``room/<house id>/<room modelId>f.obj`` (floor), ``...w.obj`` (walls) and ``...c.obj`` (ceiling). This reader
needs the floor file (``suncg.room_folder``); without it the house is reported, naming the missing file.
Objects become boxes (the object meshes are another separate download), categories are model ids unless a
``ModelCategoryMapping.csv`` sits beside house.json.
"""
from __future__ import annotations

import csv
import json
import math
from collections import Counter
from pathlib import Path
from typing import NamedTuple

import numpy as np

from .front3d import WORLD, HouseError, outline_of_triangles
from .ledger import Ledger
from .rows import box_model_row, room_row, wall_rows

WALL_THICKNESS = 0.1  # m: house.json gives none
ROOM_TYPES = {"Bedroom": "bedroom", "Living_Room": "living", "Office": "office", "Kitchen": "kitchen",
              "Bathroom": "bathroom", "Toilet": "bathroom"}


def floor_file(room_folder: Path | None, house_id: str, room_model: str) -> Path:
    base = room_folder if room_folder is not None else Path("room")
    return base / house_id / f"{room_model}f.obj"


def parse_house(file: Path, room_folder: Path | None, report: Counter) -> dict[str, list]:
    try:
        house = json.loads(Path(file).read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise HouseError(file, "", f"not readable JSON ({exc})") from exc
    for key in ("id", "levels"):
        if key not in house:
            raise HouseError(file, key, "missing")
    scale = float(house.get("scaleToMeters", 1.0))
    categories = _categories(Path(file).parent / "ModelCategoryMapping.csv")
    out = {"rooms": [], "architecture": [], "objects": [], "models": []}
    for level in house["levels"]:
        nodes = level.get("nodes", [])
        for room in (n for n in nodes if n.get("type") == "Room" and n.get("valid", 1)):
            types = room.get("roomTypes") or []
            rtype = next((ROOM_TYPES[t] for t in types if t in ROOM_TYPES), None)
            if rtype is None:
                report.drop("room", f"room types {types} not mapped", file=file, house=house["id"], room=room.get("id"),
                            status="skipped")
                continue
            floor = floor_file(room_folder, house["id"], room.get("modelId", ""))
            if not floor.exists():
                raise HouseError(file, f"room {room.get('id')}", f"architecture file {floor} not found (SUNCG's room "
                                 "meshes <room modelId>f.obj / w.obj / c.obj are a separate download; set suncg.room_folder)")
            _room(out, _House(house["id"], scale, categories, report), room, nodes, floor, rtype)
    return out


def _categories(path: Path) -> dict[str, str]:
    if not path.exists():
        return {}
    with open(path, newline="") as fh:
        return {r["model_id"]: (r.get("fine_grained_class") or r.get("category") or r["model_id"]).lower()
                for r in csv.DictReader(fh) if r.get("model_id")}


class _House(NamedTuple):
    """What every room of one house reads: its id, its scale to metres, the model -> category map, the ledger."""
    id: str
    scale: float
    categories: dict[str, str]
    report: Ledger


def _room(out: dict, house: _House, room: dict, nodes: list, floor: Path, rtype: str) -> None:
    """One room of a house level into ``out``'s tables: floor mesh ``floor`` as outline, the ``nodes`` it indexes."""
    import trimesh

    house_id, scale, categories, report = house

    mesh = trimesh.load(floor, force="mesh", process=False)
    v = np.asarray(mesh.vertices, float) * scale @ WORLD.T
    outline = outline_of_triangles([v[t, :2] for t in np.asarray(mesh.faces)])
    floor_z = float(v[:, 2].min())
    room_id = f"{house_id}_{room['id']}"
    height = float(room.get("bbox", {}).get("max", [0, 2.7, 0])[1]) * scale - floor_z
    out["architecture"] += wall_rows(room_id, outline, height, WALL_THICKNESS)
    objects = []
    for idx in room.get("nodeIndices", []):
        if idx >= len(nodes):
            report.drop("object", "nodeIndices points past the level's nodes", house=house_id, room=room_id, item=str(idx))
            continue
        n = nodes[idx]
        if n.get("type") != "Object" or not n.get("valid", 1) or "bbox" not in n or "transform" not in n:
            report.drop("object", "not a valid object with bbox and transform", house=house_id, room=room_id,
                        item=n.get("id"))
            continue
        t = np.asarray(n["transform"], float).reshape(4, 4).T  # column-major
        r = WORLD @ t[:3, :3] @ WORLD.T
        yaw = math.atan2(r[1, 0], r[0, 0]) + math.pi  # SUNCG models face +z like 3D-FUTURE's
        lo = np.asarray(n["bbox"]["min"], float) * scale @ WORLD.T
        hi = np.asarray(n["bbox"]["max"], float) * scale @ WORLD.T
        lo, hi = np.minimum(lo, hi), np.maximum(lo, hi)
        c = (lo + hi) / 2 - [0, 0, floor_z]
        ext = hi - lo  # world AABB: exact for yaw in multiples of 90 degrees (SUNCG's common case)
        k = round(yaw / (math.pi / 2))
        if k % 2:
            ext = ext[[1, 0, 2]]
        oid = f"obj_{len(objects):02d}"
        mid = f"suncg/{n['modelId']}/{ext[0]:.3f}x{ext[1]:.3f}x{ext[2]:.3f}"
        out["models"].append(box_model_row(mid, categories.get(n["modelId"], n["modelId"]), "suncg",
                                           [-ext[0] / 2, -ext[1] / 2, 0.0], [ext[0] / 2, ext[1] / 2, ext[2]]))
        objects.append({"room_id": room_id, "object_id": oid, "category": categories.get(n["modelId"], n["modelId"]),
                        "model_id": mid, "cx": c[0], "cy": c[1], "cz": c[2], "hx": ext[0] / 2, "hy": ext[1] / 2,
                        "hz": ext[2] / 2, "yaw": yaw, "px": c[0], "py": c[1], "pz": c[2] - ext[2] / 2, "sx": 1.0, "sy": 1.0,
                        "sz": 1.0, "source_parent_id": None})
    out["rooms"].append(room_row(room_id, "suncg", (rtype, ",".join(room.get("roomTypes", []))), outline, height, len(objects)))
    out["objects"] += objects
    report[("room", "read", rtype)] += 1
