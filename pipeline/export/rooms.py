"""The rooms an export writes, read once: a generated set's tables (``rooms.parquet``, ``architecture.parquet``,
``objects.parquet``, ``models.parquet``) or a corpus's shards of them (``rooms-<k>.parquet`` ...), as
:class:`~pipeline.room.RoomInput` arrays with their meshes and support parents."""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import tables
from ..errors import InputError
from ..geometry.meshes import Mesh
from ..room import BOX_COLUMNS, POSE_COLUMNS, RoomInput, load_rooms, merge_walls

TABLES = ("rooms", "architecture", "objects", "models")
BOUNDS = ["model_id", "min_x", "min_y", "min_z", "max_x", "max_y", "max_z"]


@dataclass
class RoomSet:
    """Rooms to export and what they need: meshes in model space (z-up, front +Y) and each object's support parent."""
    where: str  # the folder (for messages)
    rooms: list[RoomInput]
    parents: dict[str, list[str | None]]  # room id -> support parent of each object (aligned with object_ids) or None
    sources: dict[str, str]  # room id -> the corpus source of its architecture (procedural, front3d, ithor, ...)
    meshes: dict[str, Mesh]  # model id -> (vertices (n, 3), faces (m, 3))
    box_models: set[str]  # models whose mesh is only their box (mesh_kind box_fallback)
    bounds: dict[str, np.ndarray]  # model id -> (2, 3) model-space box (min, max) as the models table records it
    skipped: dict[str, str] = field(default_factory=dict)  # room id -> why it is not exported (an open wall loop)


def table_paths(folder: Path) -> dict[str, list[Path]]:
    """The four tables of a generated set's folder, or of a corpus's shards (one file per shard)."""
    folder = Path(folder)
    if (folder / "rooms.parquet").exists():
        return {t: [folder / f"{t}.parquet"] for t in TABLES}
    shards = sorted(folder.glob("rooms-*.parquet"))
    if not shards:
        raise InputError(f"{folder}: neither a generated set (rooms.parquet, architecture.parquet, objects.parquet, "
                         "models.parquet) nor a corpus's shards (rooms-<k>.parquet ...)")
    return {t: [p.with_name(p.name.replace("rooms-", f"{t}-", 1)) for p in shards] for t in TABLES}


def load_set(paths: dict[str, list[Path]], where: str) -> RoomSet:
    """Every room of the tables (a generated set's scored scenes, or a corpus's rooms) with its meshes; a missing
    file or model, or a non-finite pose, is an InputError naming the file and field."""
    for p in (p for t in TABLES for p in paths[t]):
        if not p.exists():
            raise InputError(f"{p}: not found ({where} needs the tables {', '.join(TABLES)})")
    room_df, _, objs, inputs = load_rooms(paths["rooms"], paths["architecture"], paths["objects"])
    meshes, box_models = tables.read_meshes_of(paths["models"], objs["model_id"].dropna())
    objects_file = _names(paths["objects"])
    for room in inputs.values():
        _check_room(room, meshes, objects_file, _names(paths["models"]))
    parent = dict(zip(zip(objs["room_id"].astype(str), objs["object_id"].astype(str)), objs["source_parent_id"]))
    parents = {rid: [_str(parent.get((rid, oid))) for oid in r.object_ids] for rid, r in inputs.items()}
    sources = dict(zip(room_df["room_id"].astype(str), room_df["source"].astype(str)))
    skipped = {rid: why for rid, r in inputs.items() if (why := _unusable(r)) is not None}
    return RoomSet(where, [r for rid, r in inputs.items() if rid not in skipped], parents, sources, meshes, box_models,
                   _bounds(paths["models"], meshes), skipped)


def _unusable(room: RoomInput) -> str | None:
    """Why a room cannot be exported (its walls form no closed loop: a corpus's defective rooms), or None."""
    try:
        merge_walls(room.wall_segments, room.wall_ids, room.wall_thickness, room.height)
    except ValueError as exc:
        return str(exc)
    return None


def _bounds(paths: list[Path], meshes: dict) -> dict[str, np.ndarray]:
    """The models' recorded boxes (float64; their vertices are float32) of the models in ``meshes``."""
    flt = [("model_id", "in", sorted(meshes))] if meshes else None
    return bounds_of([r for p in paths for r in tables.read(p, "models", filters=flt, columns=BOUNDS).to_pylist()]
                     if meshes else [])


def bounds_of(rows: list[dict]) -> dict[str, np.ndarray]:
    """Model id -> ``(2, 3)`` box of ``models`` table rows."""
    return {r["model_id"]: np.array([[r[c] for c in BOUNDS[1:4]], [r[c] for c in BOUNDS[4:]]], float) for r in rows}


def _names(paths: list[Path]) -> str:
    return str(paths[0]) if len(paths) == 1 else f"{paths[0].parent}/{paths[0].name.split('-')[0]}-*.parquet"


def _str(value) -> str | None:
    return value if isinstance(value, str) and value else None


def _check_room(room: RoomInput, meshes: dict, objects_file: str, models_file: str) -> None:
    """Every object has a model with a mesh and finite box and pose numbers."""
    for k, (oid, model) in enumerate(zip(room.object_ids, room.model_ids)):
        where = f"{objects_file}: room {room.room_id}, object {oid}"
        if model not in meshes or not len(meshes[model][1]):
            raise InputError(f"{where}: field model_id: model '{model}' has no mesh in {models_file}")
        values = np.concatenate([room.boxes[k], room.poses[k]])
        bad = [c for c, v in zip(BOX_COLUMNS + POSE_COLUMNS, values) if not np.isfinite(v)]
        if bad:
            raise InputError(f"{where}: field {bad[0]}: not a finite number")


def nesting(object_ids: list[str], parents: list[str | None]) -> list[tuple[int, int]]:
    """``(object index, parent index or -1)`` with every parent before its children: an object nests under its
    support parent where that parent is in the room and no cycle runs through it; otherwise it is a root."""
    index = {oid: k for k, oid in enumerate(object_ids)}
    parent = [index.get(p, -1) if p is not None else -1 for p in parents]
    for k in range(len(parent)):  # break cycles: follow each chain at most n steps
        seen, j = {k}, parent[k]
        while j >= 0 and j not in seen:
            seen.add(j)
            j = parent[j]
        if j >= 0:
            parent[k] = -1
    order: list[tuple[int, int]] = []
    placed: set[int] = set()
    while len(order) < len(parent):
        for k in range(len(parent)):
            if k not in placed and (parent[k] < 0 or parent[k] in placed):
                order.append((k, parent[k]))
                placed.add(k)
    return order


def file_name(room_id: str) -> str:
    """A room id as a file name (characters other than letters, digits, '.', '_' and '-' become '_')."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", room_id)
