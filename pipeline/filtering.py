"""Room filters (paper §4.1; authors' code, see docs/departures.md). Pure functions over canonical tables.

Each rule returns, per room, whether it rejects the room and why. Rules run in ``RULES`` order; a room's
report row names the first rule that rejected it and lists every rule it fails.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from .geometry import boxes
from .geometry.collision import CollisionTest, deepest_penetration
from .geometry.polygon import poke_out, wall_loop
from .room import room_slices

RULES = ("unknown_room_type", "wall_loop", "room_height", "room_size", "too_few_objects", "too_many_objects",
         "mislabeled", "rare_category", "outside_room", "interpenetration")


def category_room_counts(rooms: pd.DataFrame, objects: pd.DataFrame) -> pd.DataFrame:
    """Rooms of each type that hold each category (a room counts once): ``room_type, category, rooms``."""
    pairs = objects[["room_id", "category"]].astype({"category": str}).drop_duplicates()
    pairs = pairs.merge(rooms[["room_id", "room_type"]].astype({"room_type": str}), on="room_id")
    return (pairs.groupby(["room_type", "category"]).size().rename("rooms").reset_index()
            .sort_values(["room_type", "category"], ignore_index=True))


def _room_reasons(room, segs: np.ndarray, objs: dict, cfg: dict, rare: set) -> list[tuple[str, str]]:
    """Every rule ``room`` (a rooms row) fails, with its detail. ``segs`` (w, 2, 2) are its walls; ``objs`` holds its
    objects' arrays (``ids``, ``categories``, ``boxes`` (n, 7), ``parents``, ``poses`` (n, 7), ``meshes``: per
    object its model's mesh or None)."""
    out: list[tuple[str, str]] = []
    rtype = room.room_type
    if rtype not in cfg["min_floor_objects"]:
        out.append(("unknown_room_type", f"room type '{rtype}' has no filter settings"))
        return out
    closed, why, _ = wall_loop(segs, cfg["wall_closure_tolerance"])
    if not closed:
        out.append(("wall_loop", why))
    if room.height > cfg["max_height"]:
        out.append(("room_height", f"height {room.height:.2f} m > {cfg['max_height']} m"))
    big, small = max(room.extent_x, room.extent_y), min(room.extent_x, room.extent_y)
    if big > cfg["max_extent"] or small < cfg["min_extent"]:
        out.append(("room_size", f"extents {room.extent_x:.2f} x {room.extent_y:.2f} m outside "
                                 f"[{cfg['min_extent']}, {cfg['max_extent']}] m"))
    b = objs["boxes"]
    floor = int(boxes.on_floor(b, cfg["floor_contact"]).sum())
    if floor < cfg["min_floor_objects"][rtype]:
        out.append(("too_few_objects", f"{floor} floor objects < {cfg['min_floor_objects'][rtype]}"))
    if len(b) > cfg["max_objects"][rtype]:
        out.append(("too_many_objects", f"{len(b)} objects > {cfg['max_objects'][rtype]}"))
    required = cfg["required_categories"].get(rtype) or []
    cats = set(objs["categories"])
    if required and not cats & set(required):
        out.append(("mislabeled", f"a {rtype} without any of {sorted(required)}"))
    rare_here = sorted(c for c in cats if (rtype, c) in rare)
    if rare_here:
        out.append(("rare_category", f"rare in {rtype}: {', '.join(rare_here)}"))
    if len(b):
        out += _placement_reasons(room, objs, cfg)
    return out


def _placement_reasons(room, objs: dict, cfg: dict) -> list[tuple[str, str]]:
    """outside_room (footprints) and interpenetration (meshes where both have one, else boxes)."""
    out = []
    b, ids, parents = objs["boxes"], objs["ids"], objs["parents"]
    corners = boxes.footprint_corners(b[:, 0], b[:, 1], b[:, 3], b[:, 4], b[:, 6])
    poke = poke_out(np.column_stack([room.floor_x, room.floor_y]), corners.reshape(-1, 2)).reshape(-1, 4).max(1)
    worst = int(np.argmax(poke))
    if poke[worst] > cfg["outside_tolerance"]:
        out.append(("outside_room", f"{ids[worst]} pokes {poke[worst]:.2f} m out of the room"))
    depth = boxes.penetration_depths(b)
    related = (parents[:, None] == ids[None, :]) | (parents[None, :] == ids[:, None])
    depth[related] = 0.0
    test = CollisionTest.of(cfg["penetration"], cfg["max_penetration"], cfg.get("intersector"))
    worst = deepest_penetration(depth, objs, test, exact=True)  # its depth is reported
    if worst is not None:
        i, j, d, measure = worst
        out.append(("interpenetration", f"{ids[i]} and {ids[j]} interpenetrate by {d:.2f} m ({measure})"))
    return out


def filter_rooms(rooms: pd.DataFrame, architecture: pd.DataFrame, objects: pd.DataFrame, cfg: dict,
                 counts: pd.DataFrame, meshes: dict | None = None) -> pd.DataFrame:
    """One report row per room: kept or rejected, first rule, every rule, detail, shard (kept rooms).

    ``counts`` holds the dataset-wide :func:`category_room_counts` (the rare-category rule needs every room,
    while a filter job sees one shard). ``meshes``: model id -> ``(vertices, faces)`` for models with a real mesh
    (others, and every model when None, are measured as boxes); ``cfg['intersector']``: the ray backend's class.
    """
    meshes = meshes or {}
    rare = set(map(tuple, counts.loc[counts["rooms"] < cfg["min_category_rooms"], ["room_type", "category"]]
                   .astype(str).to_numpy()))
    walls = architecture[architecture["kind"].astype(str) == "wall"].sort_values("room_id", kind="stable")
    objs = objects.sort_values("room_id", kind="stable")
    w_slices, o_slices = room_slices(walls), room_slices(objs)
    segs = walls[["x0", "y0", "x1", "y1"]].to_numpy(float).reshape(-1, 2, 2)
    arrays = {"ids": objs["object_id"].astype(str).to_numpy(), "categories": objs["category"].astype(str).to_numpy(),
              "boxes": objs[["cx", "cy", "cz", "hx", "hy", "hz", "yaw"]].to_numpy(float),
              "parents": objs["source_parent_id"].astype(object).to_numpy(),
              "poses": objs[["px", "py", "pz", "yaw", "sx", "sy", "sz"]].to_numpy(float),
              "meshes": [meshes.get(m) for m in objs["model_id"].astype(object)]}  # a list: sliced per room like the arrays
    empty = slice(0, 0)
    rows = []
    for room in rooms.itertuples(index=False):
        so = o_slices.get(room.room_id, empty)
        reasons = _room_reasons(room, segs[w_slices.get(room.room_id, empty)], {k: v[so] for k, v in arrays.items()},
                                cfg, rare)
        kept = not reasons
        rows.append({"room_id": room.room_id, "room_type": room.room_type, "status": "kept" if kept else "rejected",
                     "rule": None if kept else reasons[0][0], "rules": [r for r, _ in reasons],
                     "detail": "" if kept else "; ".join(f"{r}: {d}" for r, d in reasons),
                     "shard": room.shard if kept else None})
    return pd.DataFrame(rows, columns=["room_id", "room_type", "status", "rule", "rules", "detail", "shard"])


def rule_counts(report: pd.DataFrame) -> pd.DataFrame:
    """Rooms per (room type, outcome): 'kept' or the first rejecting rule."""
    outcome = report["rule"].astype(object).where(report["status"] == "rejected", "kept")
    return (report.assign(outcome=outcome).groupby(["room_type", "outcome"], observed=True).size()
            .rename("rooms").reset_index())
