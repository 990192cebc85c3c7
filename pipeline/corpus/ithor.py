"""The 120 hand-made AI2-THOR rooms (``procthor`` wheel, ``databases/ai2thor-object-metadata.json``) ->
canonical tables, with ``parentReceptacles`` kept as ground-truth support parents.

Unity is left-handed with Y up; the project is right-handed with Z up: ``(x, y, z) -> (x, z, y)``.
Decisions (docs/departures.md): parts of furniture (drawers, cabinet doors, shelves, burners, knobs,
faucets, basins) are folded into the furniture whose box holds them (else their receptacle); things stored inside drawers and cabinets are
dropped (not visible, nothing to place); wall-mounted things are dropped; windows become architecture;
an object's front is the side facing away from the nearest wall when it stands within 0.3 m of one,
else the direction its rotation gives. Boxes come from the oriented corners where present.
"""
from __future__ import annotations

import importlib.util
import json
import math
import re
from collections import Counter
from pathlib import Path

import numpy as np

from ..geometry.polygon import nearest_segment, polygon_segments, segment_interval
from .rows import box_model_row, opening_row, room_row, wall_rows

GROUPS = {"bedrooms": "bedroom", "living_rooms": "living", "kitchens": "kitchen", "bathrooms": "bathroom"}
PARTS = {"Drawer", "Cabinet", "Shelf", "StoveBurner", "StoveKnob", "Faucet", "SinkBasin", "BathtubBasin", "ShowerHead"}
HIDDEN_IN = {"Drawer", "Cabinet"}  # things inside these are stored away, not placed
WALL_MOUNTED = {"LightSwitch", "Painting", "Poster", "Mirror", "Blinds", "Curtains", "ShowerDoor", "ShowerGlass",
                "ShowerCurtain", "TowelHolder", "HandTowelHolder", "ToiletPaperHanger", "Window", "Floor"}
HEIGHT, WALL_THICKNESS = 2.5, 0.1  # m: the metadata gives neither
FLOOR_STANDING = 0.01  # m: an object whose bottom is this close to the floor stands on it
UNITY = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, 1.0, 0]])  # (x, y, z) Unity -> (x, z, y) right-handed Z-up


def metadata_path(configured: str | None) -> Path:
    """The metadata JSON: configured, or inside the installed procthor package (found without importing it)."""
    if configured:
        return Path(configured)
    spec = importlib.util.find_spec("procthor")
    if spec is None or not spec.submodule_search_locations:
        raise FileNotFoundError("source ithor needs the procthor wheel (pip install procthor==0.0.1.dev2) "
                                "or ithor.metadata pointing at ai2thor-object-metadata.json")
    return Path(list(spec.submodule_search_locations)[0]) / "databases" / "ai2thor-object-metadata.json"


def category(object_type: str) -> str:
    """'ArmChair' -> 'arm_chair'."""
    return re.sub(r"(?<!^)(?=[A-Z])", "_", object_type).lower()


def _corners(o: dict) -> np.ndarray | None:
    obb = o.get("objectOrientedBoundingBox") or {}
    pts = obb.get("cornerPoints") if isinstance(obb, dict) else None
    if not pts:
        pts = (o.get("axisAlignedBoundingBox") or {}).get("cornerPoints")
    return None if not pts else np.asarray(pts, float) @ UNITY.T


def _box(corners: np.ndarray, yaw: float) -> tuple[np.ndarray, np.ndarray]:
    """Centre and half extents of corner points in a frame rotated by ``yaw``."""
    c, s = math.cos(yaw), math.sin(yaw)
    local = corners[:, :2] @ np.array([[c, -s], [s, c]])
    lo, hi = local.min(axis=0), local.max(axis=0)
    mid = np.array([c * (lo[0] + hi[0]) / 2 - s * (lo[1] + hi[1]) / 2, s * (lo[0] + hi[0]) / 2 + c * (lo[1] + hi[1]) / 2])
    z = corners[:, 2]
    return np.array([mid[0], mid[1], (z.min() + z.max()) / 2]), np.array([(hi - lo)[0] / 2, (hi - lo)[1] / 2, np.ptp(z) / 2])


def room_id(group: str, index: int) -> str:
    return f"ithor_{GROUPS[group]}_{index:02d}"


def parse_room(group: str, index: int, objects: list[dict], cfg: dict, report: Counter) -> dict[str, list]:
    """One AI2-THOR room as canonical rows: {'rooms', 'architecture', 'objects', 'models', 'ground_truth'}."""
    rid, room_type = room_id(group, index), GROUPS[group]
    out = {"rooms": [], "architecture": [], "objects": [], "models": [], "ground_truth": []}
    floor = next((o for o in objects if o.get("objectType") == "Floor"), None)
    if floor is None:
        report.drop("room", "no Floor object", room=rid, status="skipped")
        return out
    fc = _corners(floor)
    floor_z = float(fc[:, 2].max())
    lo, hi = fc[:, :2].min(axis=0) + cfg["floor_shrink"], fc[:, :2].max(axis=0) - cfg["floor_shrink"]
    outline = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
    segs = polygon_segments(outline)
    out["architecture"] = wall_rows(rid, outline, HEIGHT, WALL_THICKNESS)
    ids = {}
    for o in objects:
        if o.get("objectType") == "Window":
            c = _corners(o)
            if c is not None:
                out["architecture"].append(_window(rid, len(out["architecture"]) - len(segs), c, segs, floor_z))
            continue
        row = _object(rid, len(out["objects"]), o, objects, outline, floor_z, report)
        if row is not None:
            ids[o["objectId"]] = row["object_id"]
            out["objects"].append(row)
            out["models"].append(box_model_row(row["model_id"], row["category"], "ithor", [-row["hx"], -row["hy"], 0.0],
                                               [row["hx"], row["hy"], 2 * row["hz"]]))
    out["ground_truth"] = _support_truth(rid, out["objects"], objects, ids, report)
    out["rooms"].append(room_row(rid, "ithor", (room_type, group), outline, HEIGHT, len(out["objects"])))
    report[("room", "read", room_type)] += 1
    return out


def _object(rid: str, k: int, o: dict, objects: list[dict], outline: np.ndarray, floor_z: float,
            report: Counter) -> dict | None:
    """An ``objects`` row for one AI2-THOR object, or None (counted in ``report``) for what is not placed."""
    t = o.get("objectType")
    if t in WALL_MOUNTED:
        if t != "Floor":
            report.drop("object", "wall-mounted", room=rid, item=o.get("objectId"))
        return None
    if t in PARTS:
        report.drop("object", "part folded into its furniture", room=rid, item=o.get("objectId"))
        return None
    by_type = {x["objectId"]: x.get("objectType") for x in objects}
    if any(by_type.get(p) in HIDDEN_IN for p in o.get("parentReceptacles") or []):
        report.drop("object", "stored inside a drawer or cabinet", room=rid, item=o.get("objectId"))
        return None
    corners = _corners(o)
    if corners is None:
        report.drop("object", "no bounding box", room=rid, item=o.get("objectId"))
        return None
    corners = corners - [0.0, 0.0, floor_z]
    yaw = -math.radians(float((o.get("rotation") or {}).get("y", 0.0)))
    centre, half = _box(corners, yaw)
    if min(half) <= 1e-3:
        report.drop("object", "degenerate box", room=rid, item=o.get("objectId"))
        return None
    yaw, centre, half = _face_away_from_wall(yaw, centre, half, corners, outline)
    oid = f"obj_{k:02d}"
    report[("object", "kept", category(t))] += 1
    return {"room_id": rid, "object_id": oid, "category": category(t), "model_id": f"{rid}/{oid}",
            "cx": centre[0], "cy": centre[1], "cz": centre[2], "hx": half[0], "hy": half[1], "hz": half[2], "yaw": yaw,
            "px": centre[0], "py": centre[1], "pz": centre[2] - half[2], "sx": 1.0, "sy": 1.0, "sz": 1.0,
            "source_parent_id": None, "_source": o}


def _support_truth(rid: str, rows: list[dict], objects: list[dict], ids: dict[str, str], report: Counter) -> list[dict]:
    """Ground-truth support parents from ``parentReceptacles`` (parts resolve to their furniture); sets each row's
    ``source_parent_id``."""
    by_id = {o["objectId"]: o for o in objects}
    holder = _holders(objects)

    def owner(oid: str | None, depth: int = 0) -> str | None:
        """The furniture an id stands for: parts resolve to the receptacle that holds them."""
        o = by_id.get(oid)
        if o is None or depth > 5:
            return None
        if o["objectType"] not in PARTS:
            return oid
        if holder.get(oid) is not None:  # a part belongs to the furniture whose box holds it (a basin: its sink)
            return holder[oid]
        return next((r for p in o.get("parentReceptacles") or [] if (r := owner(p, depth + 1)) is not None), None)

    gt = []
    for r in rows:
        parents = r.pop("_source").get("parentReceptacles") or []
        if r["cz"] - r["hz"] <= FLOOR_STANDING and parents:
            # e.g. a chair "in" a desk's receptacle volume: it stands on the floor, PlanIT's support is static support
            report[("object", "kept", "parentReceptacles of a floor-standing object ignored")] += 1
            continue
        parent = next((owner(p) for p in parents if owner(p) in ids), None)
        if parent is not None and ids[parent] != r["object_id"]:
            r["source_parent_id"] = ids[parent]
            gt.append({"room_id": rid, "relation": "support", "anchor_id": ids[parent], "target_id": r["object_id"],
                       "direction": None, "group_id": None, "label": None})
    return gt


def _holders(objects: list[dict]) -> dict[str, str]:
    """Part id -> the smallest non-part object whose axis-aligned box contains the part's centre."""
    boxes = []
    for o in objects:
        aabb = (o.get("axisAlignedBoundingBox") or {}).get("cornerPoints")
        if aabb and o["objectType"] not in PARTS | WALL_MOUNTED:
            pts = np.asarray(aabb, float)
            boxes.append((float(np.prod(np.ptp(pts, axis=0))), pts.min(axis=0) - 1e-3, pts.max(axis=0) + 1e-3, o["objectId"]))
    boxes.sort(key=lambda b: b[0])
    out = {}
    for o in objects:
        if o["objectType"] not in PARTS:
            continue
        c = (o.get("axisAlignedBoundingBox") or {}).get("center")
        if not c:
            continue
        p = np.array([c["x"], c["y"], c["z"]])
        out[o["objectId"]] = next((oid for _, lo, hi, oid in boxes if np.all(p >= lo) and np.all(p <= hi)), None)
    return out


def _face_away_from_wall(yaw, centre, half, corners, outline):
    """Within 0.3 m of a wall, turn the box by a multiple of 90 degrees so its back (-Y) faces that wall."""
    lo, hi = outline.min(axis=0), outline.max(axis=0)
    gaps = {0: corners[:, 1].min() - lo[1], 1: hi[0] - corners[:, 0].max(), 2: hi[1] - corners[:, 1].max(),
            3: corners[:, 0].min() - lo[0]}  # walls at -y, +x, +y, -x
    side, gap = min(gaps.items(), key=lambda kv: kv[1])
    if gap > 0.3:
        return yaw, centre, half
    want = [0.0, math.pi / 2, math.pi, -math.pi / 2][side]  # yaw whose front points away from that wall
    turn = round((want - yaw) / (math.pi / 2))
    new = yaw + turn * math.pi / 2
    if turn % 2:
        half = half[[1, 0, 2]]
    return math.atan2(math.sin(new), math.cos(new)), centre, half


def _window(rid: str, k: int, corners: np.ndarray, segs: np.ndarray, floor_z: float) -> dict:
    w = int(nearest_segment(corners[:, :2].mean(axis=0), segs)[1])
    p0, p1 = segment_interval(corners[:, :2], segs[w])
    return opening_row(rid, "window", k, (p0, p1), (corners[:, 2].min() - floor_z, corners[:, 2].max() - floor_z),
                       f"wall_{w}")


def load(cfg: dict) -> tuple[dict, Path]:
    path = metadata_path(cfg["metadata"])
    try:
        return json.loads(path.read_text()), path
    except (OSError, json.JSONDecodeError) as exc:
        raise FileNotFoundError(f"{path}: cannot read the AI2-THOR metadata ({exc})") from exc
