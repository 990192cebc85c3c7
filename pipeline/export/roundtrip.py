"""The 3D-FRONT round trip: an exported folder read back by the project's own ingest (``source: front3d``, with the
``front3d.yaml`` the export wrote), and each room compared with its original: the same objects (category, model),
poses and relation graph (extracted again from both by the project's extraction, edge by edge). The ingest numbers
objects ``obj_<k>`` in the order the export wrote them and walls ``wall_<i>`` from wherever its floor outline starts,
so ids are matched before comparing: objects by order, walls and openings by where they lie."""
from __future__ import annotations

import json
import math
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from .. import config as config_mod
from ..corpus.ingest import ingest_front3d
from ..extraction import extract_room
from ..geometry.raycast import intersector_class
from ..placement.layout import walls_of
from ..room import RoomInput, room_inputs
from ..tables import empty, model_mesh
from .rooms import RoomSet, bounds_of, file_name

TOLERANCE = 1e-3  # m: walls and openings match where their ends lie this close
YAW_TOLERANCE = 1e-9  # rad: two yaws this close are the same angle
SNAP = 2e-4  # m: the ingest's floor outline comes back within this of the written one (its buffer is 1e-4)


def reingest(folder: Path) -> RoomSet:
    """An exported 3D-FRONT folder ingested again with the settings the export wrote beside it, each house with the
    wall thickness it records (``extension.planit.wall_thickness``; the ingest has one setting per run)."""
    settings = yaml.safe_load((Path(folder) / "front3d.yaml").read_text())["front3d"]
    groups: dict[float, list[Path]] = {}
    for house in sorted((Path(folder) / settings["houses"]).glob("*.json")):
        extension = json.loads(house.read_text()).get("extension", {}).get("planit", {})
        groups.setdefault(extension.get("wall_thickness", settings["wall_thickness"]), []).append(house)
    parts = []
    for thickness, houses in groups.items():
        with tempfile.TemporaryDirectory() as tmp:
            for house in houses:
                (Path(tmp) / house.name).symlink_to(house.resolve())
            section = settings | {"houses": tmp, "future": str(Path(folder) / settings["future"]), "wall_thickness": thickness}
            parts.append(ingest_front3d(config_mod.validate({"source": "front3d", "shards": 1, "front3d": section}), 0, 1))
    frames = {k: pd.concat([p[k].to_pandas() for p in parts] or [empty(k).to_pandas()], ignore_index=True)
              for k in ("rooms", "architecture", "objects")}
    rooms = list(room_inputs(frames["rooms"], frames["architecture"], frames["objects"]))
    models = list({m["model_id"]: m for p in parts for m in p["models"].to_pylist()}.values())
    return RoomSet(str(folder), rooms, {r.room_id: [None] * len(r.object_ids) for r in rooms},
                   {r.room_id: "front3d" for r in rooms}, {m["model_id"]: model_mesh(m) for m in models},
                   {m["model_id"] for m in models if m["mesh_kind"] == "box_fallback"}, bounds_of(models))


def by_original(back: RoomSet, original: RoomSet) -> dict[str, RoomInput]:
    """The read-back rooms by the id of the room each was exported from (its house file is named after it)."""
    names = {file_name(r.room_id): r.room_id for r in original.rooms}
    return {names[r.room_id.rsplit("_", 1)[0]]: r for r in back.rooms if r.room_id.rsplit("_", 1)[0] in names}


def pose_errors(original: RoomInput, back: RoomInput) -> tuple[float, float]:
    """Largest origin and box-centre error (m) and largest yaw error (degrees) over the objects, in order."""
    if original.object_ids and len(original.object_ids) != len(back.object_ids):
        return math.inf, math.inf
    if not original.object_ids:
        return 0.0, 0.0
    offset = np.abs(np.concatenate([original.poses[:, :3] - back.poses[:, :3], original.boxes[:, :6] - back.boxes[:, :6]], 1))
    turn = np.angle(np.exp(1j * (original.poses[:, 3] - back.poses[:, 3])))
    return float(offset.max()), float(np.degrees(np.abs(turn)).max())


def id_map(original: RoomInput, back: RoomInput) -> dict[str, str]:
    """Read-back node id -> original id: objects by order, walls by their start, openings by their midpoint and
    heights."""
    out = dict(zip(back.object_ids, original.object_ids))
    w0, w1 = walls_of(original), walls_of(back)
    for i, a in enumerate(w1.a):
        d = np.linalg.norm(w0.a - a, axis=1)
        if d.min() < TOLERANCE:
            out[w1.ids[i]] = w0.ids[int(np.argmin(d))]
    place = lambda o: np.array([o["x0"] + o["x1"], o["y0"] + o["y1"], 2 * o["z0"], 2 * o["z1"]]) / 2  # noqa: E731
    free = list(original.openings)
    for o in back.openings:  # one to one: identical openings (3D-FRONT repeats some) pair in turn
        near = [p for p in free if p["kind"] == o["kind"] and np.abs(place(p) - place(o)).max() < TOLERANCE]
        if near:
            out[o["element_id"]] = near[0]["element_id"]
            free.remove(near[0])
    return out


def same_yaws(original: RoomInput, back: RoomInput) -> RoomInput:
    """The read-back room with each yaw written as the original's where the two are the same angle (within
    ``YAW_TOLERANCE``): the ingest returns yaws in [0, 2 pi], so -pi/2 reads back as 3 pi/2, whose sine and cosine
    differ from the original's in the last bit, which is enough to flip the extraction's exact ties (an object
    touching two sides of another at a corner)."""
    if len(original.object_ids) != len(back.object_ids) or not len(back.object_ids):
        return back
    same = np.abs(np.angle(np.exp(1j * (back.poses[:, 3] - original.poses[:, 3])))) < YAW_TOLERANCE
    poses, boxes = back.poses.copy(), back.boxes.copy()
    poses[same, 3], boxes[same, 6] = original.poses[same, 3], original.boxes[same, 6]
    return replace(back, poses=poses, boxes=boxes)


def as_written(original: RoomInput, back: RoomInput) -> RoomInput:
    """The read-back room with the numbers the reader rounds taken from the original where the two agree: yaws
    (:func:`same_yaws`), and the floor outline's, walls' and openings' corners within ``SNAP`` (the ingest takes the
    outline of the floor triangles' union buffered 0.1 mm out and back in, which moves a corner by up to 0.04 mm:
    enough, like a yaw's last bit, to flip an exact tie of the extraction), and openings' heights."""
    room = same_yaws(original, back)
    ends = lambda o: np.array([[o["x0"], o["y0"]], [o["x1"], o["y1"]]])  # noqa: E731
    ref = np.concatenate([original.outline, *[ends(o) for o in original.openings]])
    heights = np.array([[o[k], 0.0] for o in original.openings for k in ("z0", "z1")]).reshape(-1, 2)
    openings = [o | dict(zip(("x0", "y0", "x1", "y1"), _snap(ends(o), ref).ravel().tolist()))
                | dict(zip(("z0", "z1"), _snap(np.array([[o["z0"], 0.0], [o["z1"], 0.0]]), heights)[:, 0].tolist()))
                for o in room.openings]
    return replace(room, outline=_snap(room.outline, ref), openings=openings,
                   wall_segments=_snap(room.wall_segments.reshape(-1, 2), ref).reshape(-1, 2, 2))


def _snap(points: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``(n, 2)`` points, each replaced by its nearest ``(m, 2)`` reference point where that lies within SNAP."""
    if not len(points) or not len(ref):
        return points
    d = np.linalg.norm(points[:, None] - ref[None], axis=2)
    near = d.argmin(axis=1)
    return np.where((d.min(axis=1) < SNAP)[:, None], ref[near], points)


def graph_difference(original: RoomInput, back: RoomInput, rs: RoomSet, back_set: RoomSet, cfg: dict,
                     as_read: bool = False) -> tuple[set, set]:
    """Edges (source, target, type, direction, distance) the original's graph has that the read-back one lacks, and
    the other way round; both extracted with the ``extract`` settings of ``cfg`` and its symmetry table, the
    read-back room :func:`as_written` (``as_read``: with every number as the ingest returned it)."""
    names = id_map(original, back)
    a = _edges(original, rs, cfg, {})
    b = _edges(back if as_read else as_written(original, back), back_set, cfg, names)
    return a - b, b - a


def _edges(room: RoomInput, rs: RoomSet, cfg: dict, names: dict[str, str]) -> set[tuple]:
    table = cfg["extract"]["symmetry"]["table"]
    extract = {**cfg["extract"], "floor_contact": cfg["floor_contact"]}
    g = extract_room(room, rs.meshes.get, lambda c, m: (table.get(c, "none"), "table"), extract,
                     intersector_class(extract["backend"]), rs.box_models)
    rename = lambda n: names.get(n, n)  # noqa: E731
    return {(rename(e["source"]), rename(e["target"]), e["edge_type"], e.get("direction"), e.get("distance")) for e in g.edges}
