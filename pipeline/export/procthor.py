"""Rooms as ProcTHOR-style house JSON (AI2-THOR's procedural houses): one house of one room per file,
``houses/<room id>.json``, each checked against :data:`~pipeline.export.procthor_schema.HOUSE_SCHEMA`.

Axes: Unity's, left-handed, y up: a project point ``(x, y, z)`` is ``{"x": x, "y": z, "z": y}``, so the floor
polygon's ``(x, z)`` are the project's ``(x, y)``. An object's ``position`` is the centre of its box (ProcTHOR places
assets by their box centre) and its ``rotation.y`` is ``-degrees(yaw)`` (Unity turns clockwise seen from above;
ProcTHOR's assets face their local +z at rotation 0, as the project's objects face +Y at yaw 0), plus the quarter
turns an iTHOR-ingested model's source rotation carries (``thor.py``). Objects a support parent holds are its
``children``. Objects whose category has no AI2-THOR asset are left out and counted (``unmapped``).
"""
from __future__ import annotations

import json
import math
from collections import Counter
from pathlib import Path

import numpy as np
from jsonschema import Draft202012Validator
from jsonschema.exceptions import best_match

from ..errors import InputError
from ..geometry.polygon import nearest_segment
from ..placement.layout import walls_of
from ..room import RoomInput, Walls
from . import thor
from .procthor_schema import HOUSE_SCHEMA
from .rooms import RoomSet, file_name, nesting

ROOM_TYPES = {"bedroom": "Bedroom", "living": "LivingRoom", "kitchen": "Kitchen", "bathroom": "Bathroom"}
ROOM = "room|0"
PARAMETERS = {"ceilingMaterial": {"name": "PureWhite"}, "floorColliderThickness": 1.0, "lights": [],
              "receptacleHeight": 0.7, "reflections": [], "skyboxId": "Sky1"}


def write(rs: RoomSet, out: Path, options: dict) -> dict:
    """One house per room of ``rs`` under ``out/houses``; ``options['ithor']``: the ``ithor`` config section (for the
    asset ids of iTHOR-ingested models)."""
    (Path(out) / "houses").mkdir(parents=True, exist_ok=True)
    models = {m for r in rs.rooms if rs.sources.get(r.room_id) == "ithor" for m in r.model_ids}
    ithor_models = thor.ithor_assets(models, options["ithor"]) if models else {}
    unmapped: Counter = Counter()
    names = []
    for room in rs.rooms:
        names.append(f"houses/{file_name(room.room_id)}.json")
        h, missing = house(room, rs.parents[room.room_id], ithor_models)
        unmapped.update(missing)
        check_house(h, str(Path(out) / names[-1]))
        (Path(out) / names[-1]).write_text(json.dumps(h))
    return {"format": "procthor", "rooms": len(names), "objects": sum(len(r.object_ids) for r in rs.rooms),
            "unmapped": dict(sorted(unmapped.items())), "files": names}


def house(room: RoomInput, parents: list[str | None], ithor_models: dict[str, tuple[str, float]]) -> tuple[dict, list[str]]:
    """One room as a house, and the categories of the objects left out for want of an asset."""
    walls = walls_of(room)
    ids = [wall_id(a, b) for a, b in zip(walls.a, walls.b)]
    objects, missing = _objects(room, parents, ithor_models)
    floor = [_v3(x, 0.0, y) for x, y in room.outline]
    holes = {"door": [], "window": []}
    for k, o in enumerate(room.openings):
        holes[str(o["kind"])].append(_hole(o, walls, ids, f"{o['kind']}|0|{k}"))
    return {"rooms": [{"id": ROOM, "roomType": ROOM_TYPES.get(room.room_type, room.room_type), "floorPolygon": floor,
                       "floorMaterial": {"name": "DarkWoodFloors"}, "children": [], "ceilings": []}],
            "walls": _walls(walls, ids), "doors": holes["door"], "windows": holes["window"], "objects": objects,
            "proceduralParameters": PARAMETERS,
            "metadata": {"schema": "1.0.0", "planit": {"roomId": room.room_id, "roomType": room.room_type}}}, missing


def wall_id(a: np.ndarray, b: np.ndarray) -> str:
    """ProcTHOR's wall id: ``wall|<room>|<min x>|<min z>|<max x>|<max z>`` (Unity z = project y)."""
    return f"wall|0|{min(a[0], b[0]):.2f}|{min(a[1], b[1]):.2f}|{max(a[0], b[0]):.2f}|{max(a[1], b[1]):.2f}"


def _walls(walls: Walls, ids: list[str]) -> list[dict]:
    """Each wall (its inner face, seen from the room) and its exterior twin (the same face reversed), as ProcTHOR."""
    out = []
    for wid, a, b in zip(ids, walls.a, walls.b):
        polygon = [_v3(a[0], 0.0, a[1]), _v3(b[0], 0.0, b[1]), _v3(a[0], walls.height, a[1]), _v3(b[0], walls.height, b[1])]
        out.append({"id": wid, "roomId": ROOM, "polygon": polygon, "material": {"name": "PureWhite"}})
        out.append({"id": wid.replace("wall|0|", "wall|exterior|"), "roomId": ROOM, "polygon": polygon[::-1],
                    "material": {"name": "PureWhite"}})
    return out


def _hole(o: dict, walls: Walls, ids: list[str], hid: str) -> dict:
    """A door or window in the wall it lies along: its hole from (start, bottom) to (end, top) in that wall's frame,
    clipped to the wall (an iTHOR window may reach above the room's assumed height)."""
    ends = np.array([[o["x0"], o["y0"]], [o["x1"], o["y1"]]], float)
    w = int(nearest_segment(ends.mean(axis=0), walls.segments)[1])
    t = np.clip(np.sort((ends - walls.a[w]) @ walls.dir[w]), 0.0, walls.length[w])  # clipped to the wall
    z0, z1 = max(float(o["z0"]), 0.0), min(float(o["z1"]), walls.height)
    hole = {"id": hid, "assetId": thor.hole_asset(str(o["kind"]), float(t[1] - t[0]), z1 - z0), "room0": ROOM,
            "room1": ROOM, "wall0": ids[w], "wall1": ids[w].replace("wall|0|", "wall|exterior|"),
            "holePolygon": [_v3(t[0], z0, 0.0), _v3(t[1], z1, 0.0)], "assetPosition": _v3(t.mean(), (z0 + z1) / 2, 0.0)}
    return hole | ({"openable": False, "openness": 0} if o["kind"] == "door" else {})


def _objects(room: RoomInput, parents: list[str | None], ithor_models: dict) -> tuple[list[dict], list[str]]:
    """The objects with an asset, nested under their support parents (an unmapped parent passes its children up)."""
    top: list[dict] = []
    node: dict[int, dict | None] = {}
    up: dict[int, int] = {}
    missing = []
    for k, p in nesting(room.object_ids, parents):
        up[k] = p if p < 0 or node[p] is not None else up[p]
        node[k] = _object(room, k, ithor_models)
        if node[k] is None:
            missing.append(room.categories[k])
            continue
        (node[up[k]]["children"] if up[k] >= 0 else top).append(node[k])
    return top, missing


def _object(room: RoomInput, k: int, ithor_models: dict) -> dict | None:
    """One object: its asset, box centre and rotation (degrees about Unity's +y), or None without an asset."""
    cx, cy, cz, hx, hy, hz, yaw = (float(v) for v in room.boxes[k])
    asset, turn = ithor_models.get(room.model_ids[k]) or (thor.closest_asset(room.categories[k], np.array([2 * hx, 2 * hz, 2 * hy])), 0.0)
    if asset is None:
        return None
    rotation = (turn - math.degrees(yaw)) % 360.0
    return {"id": room.object_ids[k], "assetId": asset, "position": _v3(cx, cz, cy), "rotation": _v3(0.0, rotation, 0.0),
            "kinematic": True, "children": []}


def _v3(x: float, y: float, z: float) -> dict:
    return {"x": float(x), "y": float(y), "z": float(z)}


def check_house(house: dict, where: str) -> None:
    """A house against the schema, then its references (ids unique; walls, doors and windows in known rooms and
    walls; holes inside their wall): an InputError naming the file and the JSON path of the first fault."""
    error = best_match(Draft202012Validator(HOUSE_SCHEMA).iter_errors(house))
    if error is not None:
        raise InputError(f"{where}: {error.json_path.removeprefix('$.')}: {error.message}")
    rooms = {r["id"] for r in house["rooms"]}
    walls = {}
    for i, w in enumerate(house["walls"]):
        _known(w["roomId"], rooms, where, f"walls[{i}].roomId")
        if w["id"] in walls:
            raise InputError(f"{where}: walls[{i}].id: '{w['id']}' repeats an earlier wall's id")
        walls[w["id"]] = w
    for key in ("doors", "windows"):
        for i, h in enumerate(house[key]):
            for side in ("0", "1"):
                _known(h["room" + side], rooms, where, f"{key}[{i}].room{side}")
                _known(h["wall" + side], walls, where, f"{key}[{i}].wall{side}")
            _inside(h, walls[h["wall0"]], where, f"{key}[{i}].holePolygon")


def _known(ref: str, known, where: str, path: str) -> None:
    if ref not in known:
        raise InputError(f"{where}: {path}: '{ref}' names no such entry")


def _inside(hole: dict, wall: dict, where: str, path: str) -> None:
    """The hole's corners lie within the wall's length and height (1 mm slack)."""
    p = wall["polygon"]
    length = math.hypot(p[1]["x"] - p[0]["x"], p[1]["z"] - p[0]["z"])
    height = max(q["y"] for q in p)
    lo, hi = hole["holePolygon"]
    if not (-1e-3 <= lo["x"] <= hi["x"] <= length + 1e-3 and -1e-3 <= lo["y"] <= hi["y"] <= height + 1e-3):
        raise InputError(f"{where}: {path}: hole ({lo['x']:.3f}, {lo['y']:.3f})-({hi['x']:.3f}, {hi['y']:.3f}) m "
                         f"lies outside its wall (length {length:.3f} m, height {height:.3f} m)")
