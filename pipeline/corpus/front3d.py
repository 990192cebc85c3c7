"""3D-FRONT houses with 3D-FUTURE furniture -> canonical tables.

A house JSON lists furniture (``uid`` -> 3D-FUTURE ``jid``), architecture meshes in world coordinates and
rooms whose ``children`` reference both. Everything is converted once, here, from 3D-FRONT's Y-up frame to
the project's Z-up frame: world ``(x, y, z) -> (x, -z, y)``; 3D-FUTURE models face +z, so model space is
``(x, y, z) -> (-x, z, y)`` (front = +Y) and an object's yaw gains pi.

Every field is checked where it is read: a malformed house structure skips the house (HouseError, with the
JSON path of the field), a malformed room skips the room and a malformed furniture entry or placement drops
that object, each recorded in the ledger's drop rows with the file, ids and JSON path.
"""
from __future__ import annotations

import json
import logging
import math
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely
from shapely.ops import unary_union

from ..errors import InputError
from ..geometry.polygon import make_ccw, merge_collinear, nearest_segment, polygon_segments, segment_interval, signed_area
from .future import FutureModels, MeshCache, norm_category
from .ledger import Ledger
from .rows import box_model_row, model_row, opening_row, room_row, wall_rows

log = logging.getLogger("planit.front3d")

WORLD = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])  # Y-up world -> Z-up world
OPENINGS = {"Door": "door", "Hole": "door", "Window": "window", "BayWindow": "window"}
ARCHITECTURE_TITLES = ("door/", "window/")  # furniture entries that are openings, not furniture
__all__ = ["FutureModels", "MeshCache", "HouseError", "parse_house", "norm_category"]


class HouseError(InputError):
    """A house file that cannot be parsed; the message names the file and the JSON path of the field."""

    def __init__(self, file, path: str, reason: str) -> None:
        super().__init__(f"{file}: {path}: {reason}" if path else f"{file}: {reason}")
        self.file, self.path, self.reason = file, path, reason


class FieldError(ValueError):
    """One field of a house JSON is unusable (``path`` is its JSON path)."""

    def __init__(self, path: str, reason: str) -> None:
        super().__init__(f"{path}: {reason}")
        self.path, self.reason = path, reason


def _numbers(value, n: int, path: str) -> np.ndarray:
    """``n`` finite numbers from a JSON list, else FieldError."""
    if not isinstance(value, list) or len(value) != n or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                                  for v in value):
        raise FieldError(path, f"expected a list of {n} numbers")
    out = np.asarray(value, float)
    if not np.isfinite(out).all():
        raise FieldError(path, "not finite")
    return out


def _field(obj: dict, key: str, kind, path: str, default=None):
    """``obj[key]`` of JSON type ``kind``; missing gives ``default`` unless that is ``...`` (required)."""
    if key not in obj:
        if default is ...:
            raise FieldError(f"{path}.{key}" if path else key, "missing")
        return default
    value = obj[key]
    if not isinstance(value, kind) or isinstance(value, bool) and kind is not bool:
        raise FieldError(f"{path}.{key}" if path else key, f"expected {getattr(kind, '__name__', kind)}, got {type(value).__name__}")
    return value


def yaw_from_quaternion(q) -> tuple[float, float]:
    """Yaw (about Z-up) of a 3D-FRONT [x, y, z, w] rotation and how far it tilts the up axis (radians)."""
    x, y, z, w = (float(c) for c in q)
    n = math.sqrt(x * x + y * y + z * z + w * w) or 1.0
    x, y, z, w = x / n, y / n, z / n, w / n
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    rz = WORLD @ r @ WORLD.T
    tilt = math.acos(max(-1.0, min(1.0, rz[2, 2])))
    return math.atan2(rz[1, 0], rz[0, 0]), tilt


def outline_of_triangles(xy_tris: list[np.ndarray]) -> np.ndarray:
    """Counter-clockwise outline of the union of floor triangles (each (3, 2)); the largest piece if several."""
    polys = [shapely.Polygon(t) for t in xy_tris if abs(signed_area(t)) > 1e-9]
    union = unary_union(polys).buffer(1e-4).buffer(-1e-4)
    if union.is_empty:
        raise ValueError("Floor meshes have no area")
    poly = max(getattr(union, "geoms", [union]), key=lambda p: p.area)
    outline = np.asarray(poly.simplify(0.01).exterior.coords)[:-1]
    return merge_collinear(make_ccw(outline), tol=1e-3)


def wall_mesh_coverage(segs: np.ndarray, footprints: list[np.ndarray], tolerance: float) -> np.ndarray:
    """Share of each outline segment's length (segs: (n, 2, 2)) lying within ``tolerance`` of the floor-plane
    footprint (convex hull of the (k, 2) vertices) of any wall mesh."""
    hulls = [shapely.MultiPoint(f).convex_hull for f in footprints if len(f)]
    if not hulls:
        return np.zeros(len(segs))
    band = unary_union(hulls).buffer(tolerance)
    lines = [shapely.LineString(s) for s in segs]
    return np.array([line.intersection(band).length / line.length if line.length else 0.0 for line in lines])




# ------------------------------------------------------------------------------------------- houses
@dataclass
class Context:
    """What every house of one ingest job shares: the 3D-FUTURE model table and meshes, the ``front3d`` config,
    the ledger, and the model rows built so far (one per model id, reported once per model)."""
    future_models: FutureModels
    meshes: MeshCache
    cfg: dict
    ledger: Ledger
    models: dict


@dataclass
class House:
    file: Path
    uid: str
    furniture: dict[str, tuple[int, dict]]  # uid -> (index in 'furniture', entry)
    meshes: dict[str, tuple[int, dict]]  # uid -> (index in 'mesh', mesh)
    rooms: list  # scene.room


def load_house(file: Path, ledger: Ledger) -> House:
    """The house's structure, checked; duplicate or malformed furniture and mesh entries are dropped (recorded)."""
    try:
        house = json.loads(Path(file).read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise HouseError(file, "", f"not readable JSON ({exc})") from exc
    try:
        if not isinstance(house, dict):
            raise FieldError("$", f"expected an object, got {type(house).__name__}")
        uid = _field(house, "uid", str, "", ...)
        entries = {}
        for key in ("furniture", "mesh"):
            entries[key] = _entries(file, uid, _field(house, key, list, "", ...), key, ledger)
        rooms = _field(_field(house, "scene", dict, "", ...), "room", list, "scene", ...)
    except FieldError as exc:
        raise HouseError(file, exc.path, exc.reason) from exc
    return House(Path(file), uid, entries["furniture"], entries["mesh"], rooms)


def _entries(file, uid: str, items: list, key: str, ledger: Ledger) -> dict[str, tuple[int, dict]]:
    """``furniture`` or ``mesh`` entries by uid; an entry that is not an object with a string uid, or repeats a
    uid (the first is kept), is dropped with its JSON path."""
    out: dict[str, tuple[int, dict]] = {}
    level = "object" if key == "furniture" else "mesh"
    for i, item in enumerate(items):
        ref = item.get("uid") if isinstance(item, dict) else None
        if not isinstance(ref, str):
            ledger.drop(level, f"{key} entry without a string uid", file=file, house=uid, field=f"{key}[{i}]")
        elif ref in out:
            ledger.drop(level, f"duplicate {key} uid (the first is kept)", file=file, house=uid, item=ref,
                        field=f"{key}[{i}].uid")
        else:
            out[ref] = (i, item)
    return out


def parse_house(file: Path, ctx: Context) -> dict[str, list]:
    """Rooms of one house as canonical rows: {'rooms', 'architecture', 'objects'} (models go to ``ctx.models``).

    Room ids are ``<file stem>_<instanceid>``: unique across files even when two files hold the same house uid;
    a room without an instanceid is ``room<index>``, a repeated instanceid gets ``-2``, ``-3``... (reported).
    """
    house = load_house(file, ctx.ledger)
    out = {"rooms": [], "architecture": [], "objects": []}
    seen: Counter = Counter()
    for i, room in enumerate(house.rooms):
        path = f"scene.room[{i}]"
        if not isinstance(room, dict):
            ctx.ledger.drop("room", "room entry is not an object", file=file, house=house.uid, field=path)
            continue
        name = room.get("instanceid") if isinstance(room.get("instanceid"), str) and room.get("instanceid") else f"room{i}"
        seen[name] += 1
        if seen[name] > 1:
            ctx.ledger[("room", "renamed", "duplicate instanceid in its house: -<n> appended")] += 1
            name = f"{name}-{seen[name]}"
        rid = f"{house.file.stem}_{name}"
        try:
            rows, why = _room(house, rid, room, path, ctx)
        except FieldError as exc:
            rows, why = None, f"bad field: {exc.reason}"
            ctx.ledger.drop("room", why, file=file, house=house.uid, room=rid, field=exc.path, status="skipped")
            continue
        if rows is None:
            ctx.ledger.drop("room", why, file=file, house=house.uid, room=rid, field=path, status="skipped")
            continue
        for k in out:
            out[k] += rows[k]
        ctx.ledger[("room", "read", rows["rooms"][0]["room_type"])] += 1
    return {**out, "house_id": house.uid}


def _room(house: House, rid: str, room: dict, path: str, ctx: Context):
    """Canonical rows of one room, or (None, reason) for a room that cannot be read."""
    cfg = ctx.cfg
    rtype_src = _field(room, "type", str, path, "")
    rtype = cfg["room_types"].get(rtype_src)
    if rtype is None:
        return None, f"room type '{rtype_src}' not mapped"
    children = [(j, c) for j, c in enumerate(_field(room, "children", list, path, [])) if isinstance(c, dict)]
    room_meshes = [house.meshes[c["ref"]] for _, c in children if isinstance(c.get("ref"), str) and c["ref"] in house.meshes]
    floors = [m for m in room_meshes if m[1].get("type") == "Floor"]
    if not floors:
        return None, "no Floor mesh"
    placed = [(j, c) for j, c in children if isinstance(c.get("ref"), str) and c["ref"] in house.furniture]
    if not placed:
        return None, "no furniture"
    try:
        outline = outline_of_triangles([t for m in floors for t in _triangles(house, m)])
    except ValueError as exc:
        return None, str(exc)
    floor_z = min(float(xyz[:, 2].min()) for xyz in (_mesh_xyz(house, m) for m in floors) if len(xyz))
    ceilings = [xyz[:, 2].max() for xyz in (_mesh_xyz(house, m) for m in room_meshes if m[1].get("type") == "Ceiling")
                if len(xyz)]
    height = float(max(ceilings)) - floor_z if ceilings else cfg["default_height"]
    where = {"outline": outline, "floor": shapely.Polygon(outline).buffer(cfg["outside_tolerance"]), "floor_z": floor_z,
             "cmap": category_map(cfg, rtype), "rid": rid}
    objects = [o for j, c in placed
               if (o := _object(house, f"{path}.children[{j}]", c, where, ctx)) is not None]
    if not objects:
        return None, "no furniture with a mesh or box inside the floor outline"
    segs = polygon_segments(outline)
    _report_walls(segs, [_mesh_xyz(house, m)[:, :2] for m in room_meshes if m[1].get("type") == "WallInner"], cfg, ctx.ledger)
    return {"rooms": [room_row(rid, "front3d", (rtype, rtype_src), outline, height, len(objects))],
            "architecture": wall_rows(rid, outline, height, cfg["wall_thickness"])
            + _openings(rid, house, room_meshes, segs, floor_z, cfg),
            "objects": [dict(o, object_id=f"obj_{k:02d}") for k, o in enumerate(objects)]}, ""


def _mesh_xyz(house: House, mesh: tuple[int, dict]) -> np.ndarray:
    """A house mesh's vertices in the project's Z-up world, (n, 3); a malformed one skips the house."""
    i, m = mesh
    xyz = m.get("xyz")
    if not isinstance(xyz, list) or len(xyz) % 3:
        raise HouseError(house.file, f"mesh[{i}].xyz", "bad 'xyz': expected a list of numbers, 3 per vertex")
    try:
        return _numbers(xyz, len(xyz), f"mesh[{i}].xyz").reshape(-1, 3) @ WORLD.T
    except FieldError as exc:
        raise HouseError(house.file, exc.path, "bad 'xyz': " + exc.reason) from exc


def _triangles(house: House, mesh: tuple[int, dict]) -> list[np.ndarray]:
    """(3, 2) floor-plane triangles of a house mesh; faces out of range or malformed skip the house."""
    xyz = _mesh_xyz(house, mesh)
    i, m = mesh
    faces = m.get("faces")
    if not isinstance(faces, list) or len(faces) % 3 or not all(isinstance(f, int) and not isinstance(f, bool) for f in faces):
        raise HouseError(house.file, f"mesh[{i}].faces", "bad 'faces': expected a list of vertex indices, 3 per face")
    f = np.asarray(faces, np.int64).reshape(-1, 3)
    if len(f) and (f.min() < 0 or f.max() >= len(xyz)):
        raise HouseError(house.file, f"mesh[{i}].faces", f"bad 'faces': index out of range (mesh has {len(xyz)} vertices)")
    return [xyz[t, :2] for t in f]


def _report_walls(segs: np.ndarray, wall_footprints: list[np.ndarray], cfg: dict, ledger: Ledger) -> None:
    """Count each outline wall as backed by a WallInner mesh or open."""
    backed = wall_mesh_coverage(segs, wall_footprints, cfg["wall_mesh_tolerance"]) >= cfg["wall_mesh_min_coverage"]
    ledger[("wall", "backed", "a WallInner mesh runs along it")] += int(backed.sum())
    ledger[("wall", "open", "no WallInner mesh along it (open to a neighbour, or the mesh is another room's)")] += int((~backed).sum())


def _openings(rid: str, house: House, room_meshes: list, segs: np.ndarray, floor_z: float, cfg: dict) -> list[dict]:
    """Door and window meshes of the room, projected onto their nearest wall."""
    rows, counts = [], Counter()
    for mesh in room_meshes:
        kind = OPENINGS.get(mesh[1].get("type"))
        if kind is None:
            continue
        xyz = _mesh_xyz(house, mesh)
        if not len(xyz):
            continue
        dist, w = nearest_segment(xyz[:, :2].mean(axis=0), segs)
        w = int(w)
        if dist > cfg["opening_max_offset"]:
            continue  # not on this room's walls
        p0, p1 = segment_interval(xyz[:, :2], segs[w])
        if np.linalg.norm(p1 - p0) < cfg["opening_min_width"]:
            continue
        rows.append(opening_row(rid, kind, counts[kind], (p0, p1), (xyz[:, 2].min() - floor_z, xyz[:, 2].max() - floor_z),
                                f"wall_{w}"))
        counts[kind] += 1
    return rows


def category_map(cfg: dict, room_type: str) -> dict[str, str]:
    """The category map for a room type: the '*' entries, overridden by the room type's own."""
    maps = cfg["category_map"]
    return {**maps.get("*", {}), **maps.get(room_type, {})}


# ------------------------------------------------------------------------------------------- furniture
def _object(house: House, path: str, child: dict, where: dict, ctx: Context) -> dict | None:
    """An ``objects`` row for one placed furniture entry, or None: every drop is recorded with its JSON path."""
    k, furn = house.furniture[child["ref"]]
    fpath = f"furniture[{k}]"
    drop = lambda reason, field: ctx.ledger.drop("object", reason, file=house.file, house=house.uid,  # noqa: E731
                                                 room=where["rid"], item=child["ref"], field=field)
    title = norm_category(furn.get("title")) or ""
    jid = furn.get("jid")
    if furn.get("valid") is False:
        return drop("not in 3D-FUTURE (valid: false)", f"{fpath}.valid")
    if not isinstance(jid, str) or not jid:
        return drop("no model id (jid)", f"{fpath}.jid")
    if furn.get("valid") is not True and title.startswith(ARCHITECTURE_TITLES):
        return drop("door or window entry: architecture, not furniture", f"{fpath}.title")
    category = _category(furn, jid, ctx.future_models)
    if category is None:
        return drop("no category (catalogue, title or super-category)", f"{fpath}.title")
    blocked = next((p for p in ctx.cfg["not_floor_objects"] if p in category or p in title), None)
    if blocked is not None:
        return drop(f"not a floor object ('{blocked}' in its category or title)", f"{fpath}.title")
    category = where["cmap"].get(category, category)
    model = _model(jid, category, house, fpath, ctx)
    if model is None:
        return drop("no mesh and no box for its model" + ("" if furn.get("valid") else " (no valid flag)"), f"{fpath}.jid")
    try:
        row, tilt = _placement(where["rid"], model, category, child, path, where["floor_z"], ctx.cfg)
    except FieldError as exc:
        return drop(f"bad placement: {exc.reason}", exc.path)
    if tilt > math.radians(5):
        ctx.ledger[("object", "kept", "tilted more than 5 degrees: yaw kept only")] += 1
    if not where["floor"].contains(shapely.Point(row["cx"], row["cy"])):
        return drop("centre outside its room's floor outline", f"{path}.pos")
    ctx.ledger[("object", "kept", category)] += 1
    if furn.get("valid") is not True:
        ctx.ledger[("object", "kept", "no valid flag, but its model has a mesh or box")] += 1
    return row


def _category(furn: dict, jid: str, future_models: FutureModels) -> str | None:
    """The model table's fine category, else the furniture's own title (its part before ' - '), else the
    model table's super-category, else the entry's category field. A coarse 'others' yields to the title."""
    title = norm_category(furn.get("title"))
    title = title.split(" - ")[0].strip() if title else None
    fine = future_models.category.get(jid)
    if fine and fine not in ("others", "other"):
        return fine
    return title or fine or future_models.super_category.get(jid) or norm_category(furn.get("category"))


def _model(jid: str, category: str, house: House, fpath: str, ctx: Context) -> dict | None:
    """The ``models`` row of a 3D-FUTURE model (its mesh, else its Models.csv box), built once per job; every mesh
    problem is recorded once per model."""
    if jid in ctx.models:
        return ctx.models[jid]
    mesh, problem = ctx.meshes.get(jid)
    if problem is not None:
        status = "kept" if mesh is not None else ("fallback" if jid in ctx.future_models.box else "dropped")
        ctx.ledger.drop("model", f"mesh {problem}", file=ctx.meshes.path(jid), house=house.uid, item=jid,
                        field=f"{fpath}.jid", status=status)
    if mesh is not None:
        ctx.models[jid] = model_row(jid, category, "front3d", mesh[0], mesh[1], "mesh", mesh[2])
    elif jid in ctx.future_models.box:
        ctx.models[jid] = box_model_row(jid, category, "front3d", *ctx.future_models.box[jid])
        ctx.ledger[("model", "fallback", "box from Models.csv (no usable raw_model.obj)")] += 1
    else:
        ctx.models[jid] = None  # neither: looked up once, every object using it is dropped
    return ctx.models[jid]


def _placement(rid: str, model: dict, category: str, child: dict, path: str, floor_z: float,
               cfg: dict) -> tuple[dict, float]:
    """The object's row (box and pose) from a room child's pos / rot / scale, and its tilt (rad); FieldError for a
    bad or absurd one."""
    pos = _numbers(child.get("pos"), 3, f"{path}.pos") @ WORLD.T
    rot = _numbers(child.get("rot", [0, 0, 0, 1]), 4, f"{path}.rot")
    if np.linalg.norm(rot) < 1e-6:
        raise FieldError(f"{path}.rot", "zero quaternion")
    sx, sy, sz = _numbers(child.get("scale", [1, 1, 1]), 3, f"{path}.scale")
    lo_s, hi_s = cfg["scale_range"]
    if not all(lo_s <= abs(v) <= hi_s for v in (sx, sy, sz)):
        raise FieldError(f"{path}.scale", f"scale {[sx, sy, sz]} outside [{lo_s}, {hi_s}] in magnitude")
    yaw, tilt = yaw_from_quaternion(rot)
    yaw += math.pi  # Y-up models face +z, ours +y: see the module docstring
    scale = np.array([sx, sz, sy])
    lo = np.array([model["min_x"], model["min_y"], model["min_z"]])
    hi = np.array([model["max_x"], model["max_y"], model["max_z"]])
    half = np.abs(scale) * (hi - lo) / 2
    min_e, max_e = cfg["object_extent"]
    if not (2 * half.max() >= min_e and 2 * half.max() <= max_e and 2 * half.min() > 0):
        raise FieldError(f"{path}.scale", f"size {np.round(2 * half, 4).tolist()} m outside [{min_e}, {max_e}] m")
    centre_local = scale * (lo + hi) / 2
    c, s = math.cos(yaw), math.sin(yaw)
    p = pos - [0.0, 0.0, floor_z]
    centre = p + [c * centre_local[0] - s * centre_local[1], s * centre_local[0] + c * centre_local[1], centre_local[2]]
    return {"room_id": rid, "object_id": None, "category": category, "model_id": model["model_id"],
            "cx": centre[0], "cy": centre[1], "cz": centre[2], "hx": half[0], "hy": half[1], "hz": half[2],
            "yaw": yaw, "px": p[0], "py": p[1], "pz": p[2], "sx": scale[0], "sy": scale[1], "sz": scale[2],
            "source_parent_id": None}, tilt
