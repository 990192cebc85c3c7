"""Rooms as 3D-FRONT-style houses with 3D-FUTURE-style models, laid out so that a 3D-FRONT reader (the project's own
ingest, ``source: front3d``, included) reads them back.

Written under the output folder: ``houses/<room id>.json`` (one house per room: ``furniture`` with jids, ``mesh``
with the Floor, Ceiling, WallInner, Door and Window meshes in world coordinates, ``scene.room[0].children`` with
each object's ``pos``, ``rot`` (quaternion x, y, z, w) and ``scale``), ``future/<jid>/raw_model.obj`` (each model's
mesh, metres, y up, front +z, as 3D-FUTURE), ``future/model_info.json`` (categories), ``future/Models.csv`` (boxes;
the only geometry of box-only models) and ``front3d.yaml``, the ingest settings that read them back exactly
(``docs/formats.md``). The axes are the ingest's own (``pipeline/corpus/front3d.py``, ``future.py``), inverted.
"""
from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np
import yaml

from ..corpus.front3d import WORLD
from ..corpus.future import MODEL
from ..errors import InputError
from ..placement.layout import walls_of
from ..room import RoomInput
from .rooms import RoomSet, file_name
from .shapes import architecture, floor_top, inner_face

TYPES = {"bedroom": "Bedroom", "living": "LivingRoom", "dining": "DiningRoom", "library": "Library",
         "kitchen": "Kitchen", "bathroom": "Bathroom"}  # canonical room type -> 3D-FRONT's (others: CamelCase)
MESH_TYPES = {"floor": "Floor", "ceiling": "Ceiling", "wall": "WallInner", "door": "Door", "window": "Window"}
DEFAULT_THICKNESS = 0.12  # m, the 3D-FRONT ingest's default
KEEP_ALL = 1e6  # the ingest's plausibility bounds, opened so that it keeps every object the export wrote
TO_WORLD, TO_MODEL = np.linalg.inv(WORLD).T, np.linalg.inv(MODEL).T  # row vectors: project -> 3D-FRONT, 3D-FUTURE


def room_type(canonical: str) -> str:
    """3D-FRONT's name of a canonical room type (``office`` -> ``Office``: 3D-FRONT has none)."""
    return TYPES.get(canonical) or "".join(p.capitalize() for p in canonical.split("_"))


def write(rs: RoomSet, out: Path, options: dict) -> dict:
    """Houses, models and the ingest settings of every room of ``rs`` under ``out``."""
    out = Path(out)
    (out / "houses").mkdir(parents=True, exist_ok=True)
    categories: dict[str, str] = {}
    for room in rs.rooms:
        categories.update({m: c for m, c in zip(room.model_ids, room.categories) if m not in categories})
        house_file = out / "houses" / f"{file_name(room.room_id)}.json"
        house_file.write_text(json.dumps(house(room)))
    _models(rs, categories, out / "future")
    thickness = float(np.median([wall_thickness(r) for r in rs.rooms])) if rs.rooms else DEFAULT_THICKNESS
    settings = ingest_settings(sorted({r.room_type for r in rs.rooms}), thickness)
    (out / "front3d.yaml").write_text("# Read these houses back with the project's 3D-FRONT ingest (paths relative to "
                                      "this folder)\n" + yaml.safe_dump(settings, sort_keys=False))
    return {"format": "front3d", "rooms": len(rs.rooms), "objects": sum(len(r.object_ids) for r in rs.rooms),
            "models": len(categories), "files": [f"houses/{file_name(r.room_id)}.json" for r in rs.rooms]}


def ingest_settings(room_types: list[str], wall_thickness: float) -> dict:
    """The config that ingests the export as it was written: its room types mapped back, categories kept as they
    are, no object dropped (as a ceiling or wall light, for its centre outside the floor, or its scale or size), no
    mesh cache, the set's median wall thickness (each house records its own: ``extension.planit.wall_thickness``)."""
    return {"source": "front3d", "front3d": {
        "houses": "houses", "future": "future", "cache_dir": None, "wall_thickness": wall_thickness,
        "not_floor_objects": [], "category_map": {}, "room_types": {room_type(t): t for t in room_types},
        "outside_tolerance": KEEP_ALL, "scale_range": [1.0 / KEEP_ALL, KEEP_ALL], "object_extent": [1.0 / KEEP_ALL, KEEP_ALL]}}


def wall_thickness(room: RoomInput) -> float:
    """The room's wall thickness (m): the median of its walls' (the project's ingest has one setting for all)."""
    finite = room.wall_thickness[np.isfinite(room.wall_thickness)]
    return float(np.median(finite)) if len(finite) else DEFAULT_THICKNESS


def house(room: RoomInput) -> dict:
    """One room as a 3D-FRONT house: furniture (one entry per model), architecture meshes, the room's children."""
    models = list(dict.fromkeys(room.model_ids))
    furniture = [_furniture(k, m, room.categories[room.model_ids.index(m)]) for k, m in enumerate(models)]
    meshes = _meshes(room)
    children = [{"ref": f"{models.index(m)}/model", "instanceid": f"furniture/{i}", **pose(room.poses[i])}
                for i, m in enumerate(room.model_ids)]
    children += [{"ref": m["uid"], "instanceid": f"mesh/{i}", "pos": [0.0, 0.0, 0.0], "rot": [0.0, 0.0, 0.0, 1.0],
                  "scale": [1.0, 1.0, 1.0]} for i, m in enumerate(meshes)]
    kind = room_type(room.room_type)
    return {"uid": room.room_id, "jobid": "", "design_version": "planit", "code_version": "planit",
            "north_vector": [0, 1, 0], "furniture": furniture, "mesh": meshes, "material": [],
            "extension": {"planit": {"wall_thickness": wall_thickness(room), "room_id": room.room_id}},
            "scene": {"ref": "-1", "pos": [0.0, 0.0, 0.0], "rot": [0.0, 0.0, 0.0, 1.0], "scale": [1.0, 1.0, 1.0],
                      "room": [{"type": kind, "instanceid": f"{kind}-0", "pos": [0.0, 0.0, 0.0],
                                "rot": [0.0, 0.0, 0.0, 1.0], "scale": [1.0, 1.0, 1.0], "children": children,
                                "empty": 0}]}}


def pose(p: np.ndarray) -> dict:
    """A child's ``pos`` (y up), ``rot`` ([x, y, z, w], about +y) and ``scale`` (3D-FUTURE's axes) from a project
    pose ``(px, py, pz, yaw, sx, sy, sz)``: 3D-FUTURE models face +z, so the rotation is ``yaw - pi``."""
    half = (float(p[3]) - math.pi) / 2
    return {"pos": (np.asarray(p[:3], float) @ TO_WORLD).tolist(), "rot": [0.0, math.sin(half), 0.0, math.cos(half)],
            "scale": [float(p[4]), float(p[6]), float(p[5])]}


def _furniture(k: int, model: str, category: str) -> dict:
    return {"uid": f"{k}/model", "jid": model, "aid": [], "title": category, "category": category, "valid": True}


def _meshes(room: RoomInput) -> list[dict]:
    """The Floor, Ceiling, WallInner (inner faces), Door and Window meshes in 3D-FRONT's world (y up)."""
    walls = walls_of(room)
    v, f = floor_top(room.outline)
    parts = [("floor", "floor", (v, f)), ("ceiling", "ceiling", (v + [0.0, 0.0, room.height], f[:, ::-1]))]
    parts += [(w, "wall", inner_face(a, b, 0.0, walls.height)) for w, a, b in zip(walls.ids, walls.a, walls.b)]
    parts += [p for p in architecture(room, walls) if p[1] in ("door", "window")]
    return [{"uid": f"{element}/{kind}", "jid": "", "type": MESH_TYPES[kind],
             "xyz": (np.asarray(v, float) @ TO_WORLD).ravel().tolist(),
             "faces": np.asarray(f, int).ravel().tolist()} for element, kind, (v, f) in parts]


def _models(rs: RoomSet, categories: dict[str, str], future: Path) -> None:
    """``<jid>/raw_model.obj`` for each model with a mesh, ``model_info.json`` and ``Models.csv`` for all."""
    future.mkdir(parents=True, exist_ok=True)
    boxes = io.StringIO()
    table = csv.writer(boxes, lineterminator="\n")
    table.writerow(["id", "minPoint", "maxPoint"])
    for model in categories:
        box = rs.bounds[model] @ TO_MODEL
        table.writerow([model, ",".join(repr(float(x)) for x in box.min(axis=0)), ",".join(repr(float(x)) for x in box.max(axis=0))])
        if model not in rs.box_models:
            folder = future / model_folder(model, rs.where)
            folder.mkdir(parents=True, exist_ok=True)
            v = exact_vertices(rs.meshes[model][0], rs.bounds[model]) @ TO_MODEL
            (folder / "raw_model.obj").write_text(obj_text(v, rs.meshes[model][1]))
    (future / "Models.csv").write_text(boxes.getvalue())
    info = [{"model_id": m, "category": c, "super-category": c, "style": None, "theme": None, "material": None}
            for m, c in categories.items()]
    (future / "model_info.json").write_text(json.dumps(info))


def model_folder(model: str, where: str) -> str:
    """A model id as its 3D-FUTURE folder: a relative path inside ``future/`` (InputError otherwise)."""
    parts = Path(model).parts
    if not model or Path(model).is_absolute() or ".." in parts or "\\" in model:
        raise InputError(f"{where}: models table: field model_id: '{model}' cannot be a 3D-FUTURE folder name")
    return model


def exact_vertices(vertices: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """``(n, 3)`` float32 vertices with the coordinates at the model's recorded ``(2, 3)`` box (float64) written as
    that box's values: the same float32 mesh, whose box a reader computes exactly as the models table records it."""
    v = np.array(vertices, float)
    for side in bounds:
        at = v.astype(np.float32) == side.astype(np.float32)
        v[at] = np.broadcast_to(side, v.shape)[at]
    return v


def obj_text(vertices: np.ndarray, faces: np.ndarray) -> str:
    """A Wavefront OBJ of ``(n, 3)`` vertices (shortest repr: every float64 exactly) and ``(m, 3)`` triangles."""
    v, f = np.asarray(vertices, float).reshape(-1, 3), np.asarray(faces, np.int64).reshape(-1, 3) + 1
    return ("v %r %r %r\n" * len(v)) % tuple(v.ravel().tolist()) + ("f %d %d %d\n" * len(f)) % tuple(f.ravel().tolist())
