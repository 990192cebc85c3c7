"""3D-FUTURE models: the model table (categories, boxes) and the furniture meshes, in the project's Z-up model space.

3D-FUTURE models face +z with Y up; model space here is ``(x, y, z) -> (-x, z, y)`` (front = +Y, Z up).
"""
from __future__ import annotations

import csv
import hashlib
import json
import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError

log = logging.getLogger("planit.front3d")

MODEL = np.array([[-1.0, 0, 0], [0, 0, 1.0], [0, 1.0, 0]])  # Y-up model (front +z) -> Z-up model (front +y)
CM_EXTENT = 5.0  # m: a model whose extent exceeds this is in centimetres


def norm_category(name) -> str | None:
    """3D-FUTURE category as the field writes it: lower case, ' / ' -> '/' (None for anything but a string)."""
    return name.strip().lower().replace(" / ", "/") if isinstance(name, str) and name.strip() else None


@dataclass
class FutureModels:
    """3D-FUTURE model metadata: fine and super categories, boxes (model space, Z-up, metres)."""
    category: dict[str, str] = field(default_factory=dict)
    super_category: dict[str, str] = field(default_factory=dict)
    box: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)

    @classmethod
    def load(cls, future: Path, models_csv: Path | None, category_csv: Path | None, model_info: Path | None) -> "FutureModels":
        cat = cls()
        info = model_info or future / "model_info.json"
        if info.exists():
            data = json.loads(info.read_text())
            if isinstance(data, list):  # the 3D-FUTURE release: [{model_id, category, super-category, ...}]
                for m in data:
                    cat._add(m.get("model_id"), m.get("category"), m.get("super-category"))
        mapping = category_csv or future / "ModelCategoryMapping.csv"
        if mapping.exists():
            with open(mapping, newline="") as fh:
                for row in csv.DictReader(fh):
                    cat._add(row.get("model_id"), row.get("category"), row.get("super-category"))
        boxes = models_csv or future / "Models.csv"
        if boxes.exists():
            cat._load_boxes(boxes)
        return cat

    def _add(self, model_id, fine, coarse) -> None:
        if not isinstance(model_id, str):
            return
        if norm_category(fine):
            self.category.setdefault(model_id, norm_category(fine))
        if norm_category(coarse):
            self.super_category.setdefault(model_id, norm_category(coarse))

    def _load_boxes(self, path: Path) -> None:
        with open(path, newline="") as fh:
            for row in csv.DictReader(fh):
                try:
                    lo = np.array([float(v) for v in row["minPoint"].split(",") if v.strip() != ""])
                    hi = np.array([float(v) for v in row["maxPoint"].split(",") if v.strip() != ""])
                except (KeyError, ValueError) as exc:
                    raise InputError(f"{path}: model {row.get('id')}: bad minPoint/maxPoint ({exc})") from exc
                if lo.shape != (3,) or hi.shape != (3,) or not np.isfinite([lo, hi]).all():
                    continue  # malformed rows (a few have an empty coordinate) fall back to no box
                if (hi - lo).max() > CM_EXTENT:
                    lo, hi = lo / 100.0, hi / 100.0
                corners = np.array([lo, hi]) @ MODEL.T
                self.box[row["id"]] = (corners.min(axis=0), corners.max(axis=0))


class MeshCache:
    """3D-FUTURE ``raw_model.obj`` meshes in Z-up model space, parsed once and cached as .npz by file
    size and modification time, so a re-run does not re-parse OBJ files."""

    def __init__(self, future: Path, cache_dir: Path | None) -> None:
        self.future = future
        self.cache_dir = cache_dir
        self.hits = self.parsed = 0

    def path(self, model_id: str) -> Path | None:
        for path in (self.future / model_id / "raw_model.obj", self.future / "models" / model_id / "raw_model.obj"):
            if path.exists():
                return path
        return None

    def get(self, model_id: str) -> tuple[tuple[np.ndarray, np.ndarray, str] | None, str | None]:
        """``((vertices (n, 3), faces (m, 3), path) or None, problem)``: problem is None, ``unreadable``, ``empty``,
        ``bad indices`` or ``non-finite vertices`` (no mesh then), or ``rescaled from cm`` (mesh kept)."""
        path = self.path(model_id)
        if path is None:
            return None, None
        stat = path.stat()
        key = hashlib.sha1(f"{path.resolve()}:{stat.st_size}:{stat.st_mtime_ns}".encode()).hexdigest()[:16]
        cached = self.cache_dir / f"{model_id}-{key}.npz" if self.cache_dir else None
        if cached is not None and cached.exists():
            with np.load(cached) as z:
                self.hits += 1
                return (z["v"], z["f"], str(path)), (str(z["problem"]) or None) if "problem" in z else None
        mesh, problem = _parse_obj(path)
        self.parsed += 1
        if mesh is not None and cached is not None:
            cached.parent.mkdir(parents=True, exist_ok=True)
            tmp = cached.with_name(cached.name + ".tmp.npz")
            np.savez_compressed(tmp, v=mesh[0].astype(np.float32), f=mesh[1].astype(np.int32), problem=problem or "")
            tmp.replace(cached)
        return (None if mesh is None else (*mesh, str(path))), problem


def _parse_obj(path: Path) -> tuple[tuple[np.ndarray, np.ndarray] | None, str | None]:
    import trimesh

    try:
        mesh = trimesh.load(path, force="mesh", process=False)
        v = np.asarray(mesh.vertices, float)
        f = np.asarray(mesh.faces, np.int64)
    except Exception as exc:  # trimesh raises many kinds for broken OBJ files
        log.warning("%s: unreadable mesh (%s: %s); using the box", path, type(exc).__name__, exc)
        return None, "unreadable"
    if len(v) == 0 or len(f) == 0:
        return None, "empty"
    if f.min() < 0 or f.max() >= len(v):
        return None, "bad indices"
    if not np.isfinite(v).all():
        return None, "non-finite vertices"
    problem = None
    if np.ptp(v, axis=0).max() > CM_EXTENT:
        v, problem = v / 100.0, "rescaled from cm"
    return (v @ MODEL.T, f), problem
