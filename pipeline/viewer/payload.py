"""A room as the inspector draws it: a JSON-able dict of its architecture (outline, merged walls, doors and windows),
its objects (box, mesh in world coordinates as base64 float32 / uint32 arrays, superstructure role, insertion
order) and one or more relation graphs (edge rows: anchor, target, relation, status and the rule that decided it,
gap). Also the difference of a planned and an extracted graph (kept, lost, unplanned edges). Pure NumPy."""
from __future__ import annotations

import base64

import numpy as np
import pandas as pd

from ..geometry import meshes
from ..room import RoomInput, Walls

EDGE_FIELDS = ("source", "target", "edge_type", "direction", "distance", "status", "rule", "gap")


def _b64(a: np.ndarray) -> str:
    return base64.b64encode(np.ascontiguousarray(a).tobytes()).decode()


def object_mesh(mesh, pose: np.ndarray) -> dict | None:
    """An object's mesh ``(vertices (n, 3), faces (m, 3))`` placed by ``pose (7,)``, as base64 arrays (None without)."""
    if mesh is None or not len(mesh[1]):
        return None
    v = meshes.transform(mesh[0], pose[:3], pose[3], pose[4:]).astype(np.float32)
    return {"v": _b64(v.reshape(-1)), "f": _b64(np.asarray(mesh[1], np.uint32).reshape(-1))}


def edge_rows(edges: pd.DataFrame) -> list[dict]:
    """Graph edge rows (extracted, final or generated tables) as the viewer's edges (missing fields None)."""
    out = []
    for r in edges.to_dict("records"):
        row = {k: r.get(k) for k in EDGE_FIELDS}
        out.append({k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in row.items()})
    return out


def _key(e: dict) -> tuple:
    return e["source"], e["target"], e["edge_type"], e.get("direction"), e.get("distance")


def difference(planned: list[dict], extracted: list[dict], placed: set[str]) -> list[dict]:
    """The planned edges between placed nodes as ``kept`` (extraction finds them exactly) or ``lost``, and the
    extracted support and spatial edges at an object that the plan lacks as ``unplanned``."""
    found = {_key(e) for e in extracted}
    plan = [e for e in planned if e["source"] in placed and e["target"] in placed and e.get("status", "kept") == "kept"]
    out = [{**e, "status": "kept" if _key(e) in found else "lost"} for e in plan]
    planned_keys = {_key(e) for e in plan}
    return out + [{**e, "status": "unplanned"} for e in extracted
                  if _key(e) not in planned_keys and e["edge_type"] in ("support", "spatial")]


def room_payload(title: str, room: RoomInput, walls: Walls, mesh_of, graphs: dict[str, list[dict]],
                 roles: dict[str, str] | None = None, box_models: set | None = None) -> dict:
    """The viewer's room: ``mesh_of(model_id)`` gives a mesh or None (a box is drawn); ``roles``: object id ->
    superstructure role (hub, spoke, chain...); objects keep the room's order (a generated room's insertion order)."""
    roles, box_models = roles or {}, box_models or set()
    objects = [{"id": oid, "category": cat, "model": model, "box": [float(x) for x in box], "order": k,
                "role": roles.get(oid) if roles.get(oid) not in (None, "none") else None,
                "mesh": None if model in box_models else object_mesh(mesh_of(model), pose)}
               for k, (oid, cat, model, box, pose) in enumerate(zip(room.object_ids, room.categories, room.model_ids,
                                                                    room.boxes, room.poses))]
    wall_rows = [{"id": w, "a": a.tolist(), "b": b.tolist(), "normal": n.tolist(), "thickness": float(t)}
                 for w, a, b, n, t in zip(walls.ids, walls.a, walls.b, walls.normal, walls.thickness)]
    openings = [{"id": o["element_id"], "kind": o["kind"], "a": [o["x0"], o["y0"]], "b": [o["x1"], o["y1"]],
                 "z0": float(o["z0"]), "z1": float(o["z1"]), "wall": _wall_of(o, walls)} for o in room.openings]
    return {"title": title, "room_id": room.room_id, "room_type": room.room_type, "height": float(room.height),
            "outline": room.outline.tolist(), "walls": wall_rows, "openings": openings, "objects": objects,
            "graphs": graphs}


def _wall_of(opening: dict, walls: Walls) -> str | None:
    """The wall whose segment passes nearest the opening's middle."""
    if not walls.ids:
        return None
    mid = np.array([(opening["x0"] + opening["x1"]) / 2, (opening["y0"] + opening["y1"]) / 2])
    d = walls.b - walls.a
    t = np.clip(((mid - walls.a) * d).sum(1) / np.maximum((d * d).sum(1), 1e-12), 0, 1)
    return walls.ids[int(np.argmin(np.linalg.norm(walls.a + t[:, None] * d - mid, axis=1)))]
