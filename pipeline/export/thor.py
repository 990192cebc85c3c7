"""AI2-THOR asset ids for exported objects, doors and windows.

A model ingested from the iTHOR rooms (``ithor_<type>_<k>/obj_<j>``, ``pipeline/corpus/ithor.py``) gets the asset the
room placed there and the quarter turns the ingest added to face it away from its wall, so its asset id and its
rotation round-trip. Any other object gets, by its category (``THOR_TYPES``, else the type whose snake-case name is
the category), the asset of the ``procthor`` package's asset database closest in size; a category with no AI2-THOR
type has no asset. Doors and windows get the wall-hole asset closest to their opening's width and height.
"""
from __future__ import annotations

import json
import math
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..corpus import ithor
from ..corpus.ledger import Ledger

THOR_TYPES = {  # project category -> AI2-THOR object type, where the names differ
    "armchair": "ArmChair", "books": "Book", "bookshelf": "ShelvingUnit", "shelf": "ShelvingUnit",
    "coffee_maker": "CoffeeMachine", "dining_chair": "Chair", "office_chair": "Chair", "dryer": "ClothesDryer",
    "hamper": "LaundryHamper", "laundry_basket": "LaundryHamper", "monitor": "Desktop", "nightstand": "SideTable",
    "plant": "HousePlant", "small_plant": "HousePlant", "refrigerator": "Fridge", "round_table": "DiningTable",
    "meeting_table": "DiningTable", "table_lamp": "DeskLamp", "trash_can": "GarbageCan", "tv": "Television",
    "tv_stand": "TVStand", "soap": "SoapBar", "sink_cabinet": "Sink", "toilet_brush": "ScrubBrush",
    "washing_machine": "WashingMachine", "floor_lamp": "FloorLamp", "coffee_table": "CoffeeTable",
    "dining_table": "DiningTable", "side_table": "SideTable",
}


@lru_cache(maxsize=1)
def databases() -> Path:
    """The ``procthor`` package's databases folder (found without importing it: that pulls in a simulator)."""
    return ithor.metadata_path(None).parent


@lru_cache(maxsize=1)
def asset_sizes() -> dict[str, list[tuple[str, np.ndarray]]]:
    """AI2-THOR object type -> its assets as ``(asset id, (3,) box size x, y, z in the asset's frame, m)``."""
    data = json.loads((databases() / "asset-database.json").read_text())
    return {t: sorted((a["assetId"], np.array([a["boundingBox"][k] for k in "xyz"], float)) for a in assets)
            for t, assets in data.items()}


@lru_cache(maxsize=1)
def hole_sizes() -> dict[str, np.ndarray]:
    """Door and window asset id -> ``(2,)`` width and height of its wall hole (m)."""
    data = json.loads((databases() / "wall-holes.json").read_text())
    return {k: np.array([v["max"]["x"] - v["min"]["x"], v["max"]["y"] - v["min"]["y"]]) for k, v in sorted(data.items())}


def thor_type(category: str) -> str | None:
    """The AI2-THOR object type of a project category, or None."""
    by_name = {ithor.category(t): t for t in asset_sizes()}
    return THOR_TYPES.get(category) or by_name.get(category)


def closest_asset(category: str, size: np.ndarray) -> str | None:
    """The asset of the category's type closest to a ``(3,)`` size (Unity x, y, z: width, height, depth), or None."""
    t = thor_type(category)
    if t is None or t not in asset_sizes():
        return None
    return min(asset_sizes()[t], key=lambda a: (float(np.abs(a[1] - size).sum()), a[0]))[0]


def hole_asset(kind: str, width: float, height: float) -> str:
    """The door (``Doorway*``) or window (``Window*``) asset whose hole is closest to ``width`` x ``height``."""
    prefix = "Doorway" if kind == "door" else "Window"
    holes = {k: v for k, v in hole_sizes().items() if k.startswith(prefix)}
    return min(holes, key=lambda k: (float(np.abs(holes[k] - [width, height]).sum()), k))


def ithor_assets(model_ids: set[str], cfg: dict) -> dict[str, tuple[str, float]]:
    """Model id of an iTHOR-ingested object -> ``(asset id, rotation offset in degrees)``: the source room's asset and
    the quarter turns its ingest added (``cfg``: the ``ithor`` config section the corpus was ingested with)."""
    rooms = {m.split("/")[0] for m in model_ids}
    data, _ = ithor.load(cfg)
    out: dict[str, tuple[str, float]] = {}
    for group in ithor.GROUPS:
        for k, objects in enumerate(data.get(group, [])):
            if ithor.room_id(group, k) in rooms:
                out.update(_room_assets(ithor.parse_room(group, k, objects, cfg, Ledger("ithor"))["objects"], objects))
    return out


def _room_assets(rows: list[dict], objects: list[dict]) -> dict[str, tuple[str, float]]:
    """Each ingested row matched to the source object of its category whose box centre is nearest its own."""
    sources = [(ithor.category(o["objectType"]), _centre(o), o) for o in objects if o.get("assetId") and _centre(o) is not None]
    out = {}
    for row in rows:
        same = [(float(np.linalg.norm(c - [row["cx"], row["cy"]])), o) for cat, c, o in sources if cat == row["category"]]
        if same:
            o = min(same, key=lambda s: s[0])[1]
            turn = float((o.get("rotation") or {}).get("y", 0.0)) + math.degrees(row["yaw"])
            out[row["model_id"]] = (o["assetId"], (round(turn / 90.0) * 90.0) % 360.0)
    return out


def _centre(o: dict) -> np.ndarray | None:
    """The floor-plane ``(2,)`` centre of an AI2-THOR object's box corners, in the project's axes."""
    obb = o.get("objectOrientedBoundingBox") or {}
    pts = (obb.get("cornerPoints") if isinstance(obb, dict) else None) or (o.get("axisAlignedBoundingBox") or {}).get("cornerPoints")
    return None if not pts else (np.asarray(pts, float) @ ithor.UNITY.T)[:, :2].mean(axis=0)
