"""Canonical table rows, built one way for every source (procedural, 3D-FRONT, AI2-THOR, SUNCG).

Each reader converts its format to the project's frame (metres, Z up, floor at z = 0) and then calls these
builders, so a column means the same whatever the source (docs/data-model.md).
"""
from __future__ import annotations

import numpy as np

from ..geometry import meshes as M
from ..geometry.polygon import extents, polygon_segments, signed_area


def room_row(room_id: str, source: str, types: tuple[str, str], outline: np.ndarray, height: float, n_objects: int,
             shard: int | None = None) -> dict:
    """A ``rooms`` row; ``types``: its room type and the source's own; ``outline`` is the (k, 2) counter-clockwise
    floor outline."""
    room_type, source_room_type = types
    outline = np.asarray(outline, float)
    ex, ey = extents(outline)
    return {"room_id": room_id, "source": source, "room_type": room_type, "source_room_type": source_room_type,
            "floor_x": outline[:, 0].tolist(), "floor_y": outline[:, 1].tolist(), "height": float(height),
            "floor_area": signed_area(outline), "extent_x": ex, "extent_y": ey, "n_objects": int(n_objects),
            "shard": shard}


def wall_rows(room_id: str, outline: np.ndarray, height: float, thickness: float) -> list[dict]:
    """One ``architecture`` row per outline edge: ``wall_<i>`` from vertex i to vertex i + 1."""
    return [{"room_id": room_id, "element_id": f"wall_{i}", "kind": "wall", "x0": float(s[0][0]), "y0": float(s[0][1]),
             "x1": float(s[1][0]), "y1": float(s[1][1]), "z0": 0.0, "z1": float(height), "thickness": float(thickness),
             "wall_id": None} for i, s in enumerate(polygon_segments(outline))]


def opening_row(room_id: str, kind: str, k: int, ends: tuple, span: tuple[float, float], wall_id: str) -> dict:
    """A door or window (``<kind>_<k>``) from ``p0`` to ``p1`` (``ends``, each (2,)) along wall ``wall_id``, from
    height ``z0`` to ``z1`` (``span``, m)."""
    (p0, p1), (z0, z1) = ends, span
    return {"room_id": room_id, "element_id": f"{kind}_{k}", "kind": kind, "x0": float(p0[0]), "y0": float(p0[1]),
            "x1": float(p1[0]), "y1": float(p1[1]), "z0": float(z0), "z1": float(z1), "thickness": None, "wall_id": wall_id}


def model_row(model_id: str, category: str, source: str, vertices: np.ndarray, faces: np.ndarray,
              kind: str = "mesh", path: str | None = None) -> dict:
    """A ``models`` row from a model-space mesh (front +Y, Z up), with its bounds."""
    v = np.asarray(vertices, float).reshape(-1, 3)
    lo, hi = v.min(axis=0), v.max(axis=0)
    return {"model_id": model_id, "category": category, "source": source,
            "vertices": v.astype(np.float32).ravel().tolist(), "faces": np.asarray(faces, np.int32).ravel().tolist(),
            "mesh_kind": kind, "mesh_path": path, "min_x": float(lo[0]), "min_y": float(lo[1]), "min_z": float(lo[2]),
            "max_x": float(hi[0]), "max_y": float(hi[1]), "max_z": float(hi[2])}


def box_model_row(model_id: str, category: str, source: str, lo, hi, path: str | None = None) -> dict:
    """A ``models`` row whose mesh is the box from ``lo`` to ``hi`` (3,) in model space (``box_fallback``)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    v, f = M.box(hi - lo, (lo + hi) / 2)
    return model_row(model_id, category, source, v, f, "box_fallback", path)
