"""3D-FRONT houses with 3D-FUTURE furniture -> canonical tables.

A house JSON lists furniture (``uid`` -> 3D-FUTURE ``jid``), architecture meshes in world coordinates and
rooms whose ``children`` reference both. Everything is converted once, here, from 3D-FRONT's Y-up frame to
the project's Z-up frame: world ``(x, y, z) -> (x, -z, y)``; 3D-FUTURE models face +z, so model space is
``(x, y, z) -> (-x, z, y)`` (front = +Y) and an object's yaw gains pi.
"""
from __future__ import annotations

import csv
import hashlib
import json
import logging
import math
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import shapely
from shapely.ops import unary_union

from ..geometry.polygon import (make_ccw, merge_collinear, polygon_segments, segment_distances, segment_interval,
                                signed_area)

from ..errors import InputError
from .rows import box_model_row, model_row, opening_row, room_row, wall_rows

log = logging.getLogger("planit.front3d")

WORLD = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])  # Y-up world -> Z-up world
MODEL = np.array([[-1.0, 0, 0], [0, 0, 1.0], [0, 1.0, 0]])  # Y-up model (front +z) -> Z-up model (front +y)
CM_EXTENT = 5.0  # m: a model whose extent exceeds this is in centimetres
OPENINGS = {"Door": "door", "Hole": "door", "Window": "window", "BayWindow": "window"}


class HouseError(InputError):
    """A house file that cannot be parsed; the message names the file and the field."""


def norm_category(name: str | None) -> str | None:
    """3D-FUTURE category as the field writes it: lower case, ' / ' -> '/'."""
    return None if not name else name.strip().lower().replace(" / ", "/")


@dataclass
class Catalogue:
    """3D-FUTURE model metadata: categories and boxes (model space, Z-up, metres)."""
    category: dict[str, str] = field(default_factory=dict)
    box: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)

    @classmethod
    def load(cls, future: Path, models_csv: Path | None, category_csv: Path | None, model_info: Path | None) -> "Catalogue":
        cat = cls()
        info = model_info or future / "model_info.json"
        if info.exists():
            data = json.loads(info.read_text())
            if isinstance(data, list):  # the 3D-FUTURE release: [{model_id, category, super-category, ...}]
                for m in data:
                    c = norm_category(m.get("category")) or norm_category(m.get("super-category"))
                    if m.get("model_id") and c:
                        cat.category[m["model_id"]] = c
        mapping = category_csv or future / "ModelCategoryMapping.csv"
        if mapping.exists():
            with open(mapping, newline="") as fh:
                for row in csv.DictReader(fh):
                    c = norm_category(row.get("category")) or norm_category(row.get("super-category"))
                    if c:
                        cat.category.setdefault(row["model_id"], c)
        boxes = models_csv or future / "Models.csv"
        if boxes.exists():
            with open(boxes, newline="") as fh:
                for row in csv.DictReader(fh):
                    try:
                        lo = np.array([float(v) for v in row["minPoint"].split(",") if v.strip() != ""])
                        hi = np.array([float(v) for v in row["maxPoint"].split(",") if v.strip() != ""])
                    except (KeyError, ValueError) as exc:
                        raise HouseError(f"{boxes}: model {row.get('id')}: bad minPoint/maxPoint ({exc})") from exc
                    if lo.shape != (3,) or hi.shape != (3,):
                        continue  # malformed rows (a few have an empty coordinate) fall back to no box
                    if (hi - lo).max() > CM_EXTENT:
                        lo, hi = lo / 100.0, hi / 100.0
                    corners = np.array([lo, hi]) @ MODEL.T
                    cat.box[row["id"]] = (corners.min(axis=0), corners.max(axis=0))
        return cat


class MeshCache:
    """3D-FUTURE ``raw_model.obj`` meshes in Z-up model space, parsed once and cached as .npz by file
    size and modification time, so a re-run does not re-parse OBJ files."""

    def __init__(self, future: Path, cache_dir: Path | None) -> None:
        self.future = future
        self.cache_dir = cache_dir
        self.hits = self.parsed = 0

    def get(self, model_id: str) -> tuple[np.ndarray, np.ndarray, str] | None:
        path = self.future / model_id / "raw_model.obj"
        if not path.exists():
            path = self.future / "models" / model_id / "raw_model.obj"
        if not path.exists():
            return None
        stat = path.stat()
        key = hashlib.sha1(f"{path.resolve()}:{stat.st_size}:{stat.st_mtime_ns}".encode()).hexdigest()[:16]
        cached = self.cache_dir / f"{model_id}-{key}.npz" if self.cache_dir else None
        if cached is not None and cached.exists():
            with np.load(cached) as z:
                self.hits += 1
                return z["v"], z["f"], str(path)
        import trimesh

        try:
            mesh = trimesh.load(path, force="mesh", process=False)
        except Exception as exc:  # trimesh raises many kinds for broken OBJ files
            log.warning("%s: unreadable mesh (%s); using the box", path, exc)
            return None
        v = np.asarray(mesh.vertices, float)
        f = np.asarray(mesh.faces, np.int64)
        if len(v) == 0 or len(f) == 0:
            return None
        if np.ptp(v, axis=0).max() > CM_EXTENT:
            v = v / 100.0
        v = v @ MODEL.T
        self.parsed += 1
        if cached is not None:
            cached.parent.mkdir(parents=True, exist_ok=True)
            tmp = cached.with_name(cached.name + ".tmp.npz")
            np.savez_compressed(tmp, v=v.astype(np.float32), f=f.astype(np.int32))
            tmp.replace(cached)
        return v, f, str(path)


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


def _mesh_xyz(mesh: dict, file: Path) -> np.ndarray:
    """A house mesh's vertices in the project's Z-up world, (n, 3)."""
    try:
        return np.asarray(mesh["xyz"], float).reshape(-1, 3) @ WORLD.T
    except (KeyError, ValueError) as exc:
        raise HouseError(f"{file}: mesh {mesh.get('uid')}: bad 'xyz' ({exc})") from exc


def _outline(floor_meshes: list[dict], file: Path) -> np.ndarray:
    tris = []
    for m in floor_meshes:
        xyz = _mesh_xyz(m, file)
        try:
            faces = np.asarray(m["faces"], np.int64).reshape(-1, 3)
        except (KeyError, ValueError) as exc:
            raise HouseError(f"{file}: mesh {m.get('uid')}: bad 'faces' ({exc})") from exc
        tris += [xyz[t, :2] for t in faces]
    return outline_of_triangles(tris)


def wall_mesh_coverage(segs: np.ndarray, footprints: list[np.ndarray], tolerance: float) -> np.ndarray:
    """Share of each outline segment's length (segs: (n, 2, 2)) lying within ``tolerance`` of the floor-plane
    footprint (convex hull of the (k, 2) vertices) of any wall mesh."""
    hulls = [shapely.MultiPoint(f).convex_hull for f in footprints if len(f)]
    if not hulls:
        return np.zeros(len(segs))
    band = unary_union(hulls).buffer(tolerance)
    lines = [shapely.LineString(s) for s in segs]
    return np.array([line.intersection(band).length / line.length if line.length else 0.0 for line in lines])


def _load_house(file: Path) -> dict:
    try:
        house = json.loads(Path(file).read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise HouseError(f"{file}: not readable JSON ({exc})") from exc
    for key in ("uid", "furniture", "mesh", "scene"):
        if key not in house:
            raise HouseError(f"{file}: missing field '{key}'")
    if "room" not in house["scene"]:
        raise HouseError(f"{file}: missing field 'scene.room'")
    return house


def parse_house(file: Path, catalogue: Catalogue, meshes: MeshCache, cfg: dict, report: Counter) -> dict[str, list]:
    """Rooms of one house as canonical rows: {'rooms', 'architecture', 'objects', 'models'}.

    Rooms without a Floor mesh, of an unmapped type or without valid furniture are skipped (counted in
    ``report`` with the reason). A malformed house raises HouseError naming the file and field.
    """
    house = _load_house(file)
    furniture = {f["uid"]: f for f in house["furniture"] if "uid" in f}
    arch_meshes = {m["uid"]: m for m in house["mesh"] if "uid" in m}
    out = {"rooms": [], "architecture": [], "objects": [], "models": {}}
    for room in house["scene"]["room"]:
        rtype_src = room.get("type", "")
        rtype = cfg["room_types"].get(rtype_src)
        if rtype is None:
            report[("room", "skipped", f"room type '{rtype_src}' not mapped")] += 1
            continue
        children = room.get("children", [])
        room_meshes = [arch_meshes[c["ref"]] for c in children if c.get("ref") in arch_meshes]
        valid = [c for c in children if c.get("ref") in furniture and furniture[c["ref"]].get("valid")
                 and furniture[c["ref"]].get("jid")]
        rid = f"{house['uid']}_{room.get('instanceid', rtype_src)}"
        rows, why = _room(rid, rtype, rtype_src, room_meshes, valid, furniture, catalogue, meshes, out["models"], cfg,
                          report, file)
        if rows is None:
            report[("room", "skipped", why)] += 1
            continue
        for k in ("rooms", "architecture", "objects"):
            out[k] += rows[k]
        report[("room", "read", rtype)] += 1
    return out


def _room(rid, rtype, rtype_src, room_meshes, valid, furniture, catalogue, meshes, models, cfg, report, file):
    """Canonical rows of one room, or (None, reason) for a room that cannot be read."""
    floors = [m for m in room_meshes if m.get("type") == "Floor"]
    if not floors:
        return None, "no Floor mesh"
    if not valid:
        return None, "no valid furniture"
    try:
        outline = _outline(floors, file)
    except ValueError as exc:
        return None, str(exc)
    floor_z = min(float(_mesh_xyz(m, file)[:, 2].min()) for m in floors)
    ceilings = [xyz[:, 2].max() for xyz in (_mesh_xyz(m, file) for m in room_meshes if m.get("type") == "Ceiling")
                if len(xyz)]
    height = float(max(ceilings)) - floor_z if ceilings else cfg["default_height"]
    cmap = category_map(cfg, rtype)
    objects = [o for o in (_object(rid, k, furniture[c["ref"]], c, catalogue, meshes, models, floor_z, cmap, report)
                           for k, c in enumerate(valid)) if o is not None]
    floor = shapely.Polygon(outline).buffer(cfg["outside_tolerance"])
    inside = [o for o in objects if floor.contains(shapely.Point(o["cx"], o["cy"]))]
    if len(inside) < len(objects):
        report[("object", "dropped", "centre outside its room's floor outline")] += len(objects) - len(inside)
    if not inside:
        return None, "no furniture with a mesh or box inside the floor outline"
    segs = polygon_segments(outline)
    _report_walls(segs, room_meshes, cfg, report, file)
    return {"rooms": [room_row(rid, "front3d", rtype, rtype_src, outline, height, len(inside))],
            "architecture": wall_rows(rid, outline, height, cfg["wall_thickness"])
            + _openings(rid, room_meshes, segs, floor_z, cfg, file),
            "objects": [dict(o, object_id=f"obj_{k:02d}") for k, o in enumerate(inside)]}, ""


def _report_walls(segs: np.ndarray, room_meshes: list[dict], cfg: dict, report: Counter, file: Path) -> None:
    """Count each outline wall as backed by a WallInner mesh or open."""
    backed = wall_mesh_coverage(segs, [_mesh_xyz(m, file)[:, :2] for m in room_meshes if m.get("type") == "WallInner"],
                                cfg["wall_mesh_tolerance"]) >= cfg["wall_mesh_min_coverage"]
    report[("wall", "backed", "a WallInner mesh runs along it")] += int(backed.sum())
    report[("wall", "open", "no WallInner mesh along it (open to a neighbour, or the mesh is another room's)")] += int((~backed).sum())


def _openings(room_id: str, room_meshes: list[dict], segs: np.ndarray, floor_z: float, cfg: dict,
              file: Path) -> list[dict]:
    """Door and window meshes of the room, projected onto their nearest wall."""
    rows, counts = [], Counter()
    for m in room_meshes:
        kind = OPENINGS.get(m.get("type"))
        if kind is None:
            continue
        xyz = _mesh_xyz(m, file)
        if not len(xyz):
            continue
        dist = segment_distances(xyz[:, :2].mean(axis=0), segs)
        w = int(np.argmin(dist))
        if dist[w] > cfg["opening_max_offset"]:
            continue  # not on this room's walls
        p0, p1 = segment_interval(xyz[:, :2], segs[w])
        if np.linalg.norm(p1 - p0) < cfg["opening_min_width"]:
            continue
        rows.append(opening_row(room_id, kind, counts[kind], p0, p1, xyz[:, 2].min() - floor_z, xyz[:, 2].max() - floor_z,
                                f"wall_{w}"))
        counts[kind] += 1
    return rows


def category_map(cfg: dict, room_type: str) -> dict[str, str]:
    """The category map for a room type: the '*' entries, overridden by the room type's own."""
    maps = cfg["category_map"]
    return {**maps.get("*", {}), **maps.get(room_type, {})}


def _object(room_id, k, furn, child, catalogue, meshes, models, floor_z, cmap, report) -> dict | None:
    jid = furn["jid"]
    category = catalogue.category.get(jid) or norm_category(furn.get("category")) or norm_category(furn.get("title"))
    if not category:
        report[("object", "dropped", "no category")] += 1
        return None
    category = cmap.get(category, category)
    if jid not in models:
        mesh = meshes.get(jid)
        if mesh is not None:
            models[jid] = model_row(jid, category, "front3d", mesh[0], mesh[1], "mesh", mesh[2])
        elif jid in catalogue.box:
            models[jid] = box_model_row(jid, category, "front3d", *catalogue.box[jid])
            report[("model", "fallback", "box from Models.csv (no raw_model.obj)")] += 1
        else:
            report[("object", "dropped", "no mesh and no box for its model")] += 1
            return None
    m = models[jid]
    try:
        pos = np.asarray(child["pos"], float) @ WORLD.T
        yaw, tilt = yaw_from_quaternion(child.get("rot", [0, 0, 0, 1]))
        sx, sy, sz = (float(s) for s in child.get("scale", [1, 1, 1]))
    except (KeyError, ValueError, TypeError) as exc:
        report[("object", "dropped", f"bad pos/rot/scale ({type(exc).__name__})")] += 1
        return None
    if tilt > math.radians(5):
        report[("object", "kept", "tilted more than 5 degrees: yaw kept only")] += 1
    yaw += math.pi  # Y-up models face +z, ours +y: see the module docstring
    scale = np.array([sx, sz, sy])
    lo = np.array([m["min_x"], m["min_y"], m["min_z"]])
    hi = np.array([m["max_x"], m["max_y"], m["max_z"]])
    centre_local = scale * (lo + hi) / 2
    half = np.abs(scale) * (hi - lo) / 2
    c, s = math.cos(yaw), math.sin(yaw)
    p = pos - [0.0, 0.0, floor_z]
    centre = p + [c * centre_local[0] - s * centre_local[1], s * centre_local[0] + c * centre_local[1], centre_local[2]]
    report[("object", "kept", category)] += 1
    return {"room_id": room_id, "object_id": f"obj_{k:02d}", "category": category, "model_id": jid,
            "cx": centre[0], "cy": centre[1], "cz": centre[2], "hx": half[0], "hy": half[1], "hz": half[2],
            "yaw": yaw, "px": p[0], "py": p[1], "pz": p[2], "sx": scale[0], "sy": scale[1], "sz": scale[2],
            "source_parent_id": None}
