"""Model retrieval: a placed object takes a model, with its scale and size, from an instance of its category in the
training rooms (the category's empirical size prior; PlanIT retrieves the model closest to predicted extents).
Symmetry must match the planned node's where the category has such instances."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..geometry.boxes import rotation
from ..room import BOX_COLUMNS


@dataclass(frozen=True)
class Instance:
    """One model as it stood in a training room: half extents, the box centre relative to the model origin in the
    object's frame (x, y, z), the scale, and the height of the box bottom above the floor or its support."""
    model_id: str
    half: tuple[float, float, float]
    offset: tuple[float, float, float]
    scale: tuple[float, float, float]
    lift: float


class ModelPool:
    """Instances per category (and symmetry) of the training rooms' objects."""

    def __init__(self, objects: pd.DataFrame, symmetry: dict[str, str], floor_contact: float = 0.05):
        self.by_cat: dict[str, list[Instance]] = {}
        self.sym: dict[str, list[str]] = {}
        self._sizes: dict[str, np.ndarray] = {}
        b = objects[BOX_COLUMNS].to_numpy(float)
        p = objects[["px", "py", "pz"]].to_numpy(float)
        s = objects[["sx", "sy", "sz"]].to_numpy(float)
        local = np.einsum("nji,nj->ni", rotation(b[:, 6]), b[:, :2] - p[:, :2])  # R(-yaw) (c - p)
        bottom = b[:, 2] - b[:, 5]
        for k, (cat, model) in enumerate(zip(objects["category"].astype(str), objects["model_id"].astype(str))):
            inst = Instance(model, tuple(b[k, 3:6]), (local[k, 0], local[k, 1], b[k, 2] - p[k, 2]), tuple(s[k]),
                            float(bottom[k]) if bottom[k] >= floor_contact else 0.0)
            self.by_cat.setdefault(cat, []).append(inst)
            self.sym.setdefault(cat, []).append(symmetry.get(model, "none"))

    def has(self, category: str) -> bool:
        return category in self.by_cat

    def sizes(self, category: str) -> np.ndarray:
        """``(m, 2)`` the category's distinct footprint half extents (m), computed once."""
        if category not in self._sizes:
            self._sizes[category] = np.unique(np.array([i.half[:2] for i in self.by_cat[category]]), axis=0)
        return self._sizes[category]

    def pick(self, category: str, symmetry: str, rng: np.random.Generator, grounded: bool = False,
             fits: Callable[[np.ndarray], np.ndarray] | None = None) -> Instance:
        """A random instance of the category, of the node's symmetry where the category has one; ``grounded``: one
        that stood on the floor where the category has such (a floor node with planned spatial edges: extraction
        sees no spatial relation of an object hanging above the floor, e.g. an AI2-THOR counter-top slab); ``fits``:
        ``(n, 3)`` half extents -> ``(n,)`` bool, one it accepts where the category has such (an object planned on a
        placed support: one that can stand on it, ``Search.fits``)."""
        if category not in self.by_cat:
            raise KeyError(f"no training instance of category '{category}'")
        pool = self.by_cat[category]
        keep = [k for k, inst in enumerate(pool) if inst.lift == 0.0] if grounded else []
        keep = keep or list(range(len(pool)))
        if fits is not None:
            keep = [k for k, ok in zip(keep, fits(np.array([pool[k].half for k in keep]))) if ok] or keep
        same = [k for k in keep if self.sym[category][k] == symmetry]
        return pool[int(rng.choice(same or keep))]


def nearest(pool: ModelPool, category: str, half: np.ndarray) -> Instance | None:
    """The training instance of ``category`` whose half extents ``(3,)`` are nearest to ``half`` (m; None: the
    category has no instance): retrieval by a predicted size, as PlanIT retrieves the model closest to the extents."""
    insts = pool.by_cat.get(category)
    if not insts:
        return None
    return insts[int(np.argmin(np.linalg.norm(np.array([i.half for i in insts]) - half, axis=1)))]


def nearest_within(pool: ModelPool, category: str, half: np.ndarray) -> Instance | None:
    """The training instance of ``category`` nearest to ``half`` ``(3,)`` among those whose footprint half extents
    fit inside ``half[:2]`` (a decoded box's model never reaches past the box); the smallest footprint when none
    fits; None when the category has no instance."""
    insts = pool.by_cat.get(category)
    if not insts:
        return None
    h = np.array([i.half for i in insts])
    fits = (h[:, :2] <= np.asarray(half)[:2] + 1e-9).all(1)
    if not fits.any():
        return insts[int(np.argmin(h[:, 0] * h[:, 1]))]
    return insts[int(np.argmin(np.where(fits, np.linalg.norm(h - half, axis=1), np.inf)))]


def place(inst: Instance, x: float, y: float, support: float | None, yaw: float) -> tuple[np.ndarray, np.ndarray]:
    """Box ``(7,)`` and pose ``(7,)`` (px, py, pz, yaw, sx, sy, sz) of the instance with its box centred on
    ``(x, y)``, turned to ``yaw``, its bottom on the ``support`` height (m), or for a floor object (None) at the
    instance's own height above the floor."""
    hx, hy, hz = inst.half
    cz = (inst.lift if support is None else support) + hz
    o = rotation(yaw) @ np.array(inst.offset[:2])
    box = np.array([x, y, cz, hx, hy, hz, yaw])
    pose = np.array([x - o[0], y - o[1], cz - inst.offset[2], yaw, *inst.scale])
    return box, pose
