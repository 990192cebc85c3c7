"""Functional symmetry types detected from a model's mesh (PlanIT Fig. 3).

A model has a symmetry when its surface maps onto itself under the type's transforms (in the floor plane,
about the centre of its bounding box): the symmetric Chamfer distance between surface samples and their
transformed copy must stay under ``tolerance`` times the model's diagonal.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import cast

import numpy as np
import trimesh
from scipy.spatial import cKDTree

TYPES = ("none", "left-right", "front-back", "rotational-2", "rotational-4", "corner-left", "corner-right", "radial")


def _rot(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


TRANSFORMS = {
    "mirror_x": np.diag([-1.0, 1.0, 1.0]),  # left-right: reflect across the front axis
    "mirror_y": np.diag([1.0, -1.0, 1.0]),  # front-back
    "rot180": _rot(np.pi),
    "rot90": _rot(np.pi / 2),
    "rot_odd": _rot(2 * np.pi / 7),  # an angle no polygonal object of a few sides keeps
    "rot_45": _rot(np.pi / 4),
    "diag": np.array([[0, 1.0, 0], [1.0, 0, 0], [0, 0, 1]]),  # reflect across y = x (corner-left)
    "antidiag": np.array([[0, -1.0, 0], [-1.0, 0, 0], [0, 0, 1]]),  # reflect across y = -x (corner-right)
}


def surface_samples(vertices: np.ndarray, faces: np.ndarray, count: int, seed: int = 0) -> np.ndarray:
    """``(count, 3)`` points on the surface, centred on the bounding box centre in x and y."""
    mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=False, validate=False)
    pts, _ = trimesh.sample.sample_surface(mesh, count, seed=seed)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    centre = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, 0.0])
    return cast(np.ndarray, np.asarray(pts) - centre)


class Invariances:
    """Which transforms of :data:`TRANSFORMS` map the sampled surface (``points (n, 3)``) onto itself, tested only
    when asked (``inv["rot90"]``) and then remembered: :func:`classify` stops at the first type that holds."""

    def __init__(self, points: np.ndarray, tolerance: float) -> None:
        self.points = points
        self.limit = tolerance * float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
        self.tree = cKDTree(points)
        self.known: dict[str, bool] = {}

    def __getitem__(self, name: str) -> bool:
        if name not in self.known:
            m = TRANSFORMS[name]  # orthogonal: the distance from p to the moved surface M q is |M^T p - q|
            d1 = self.tree.query(self.points @ m.T)[0]  # moved samples -> surface
            d2 = self.tree.query(self.points @ m)[0]  # samples -> moved surface, without a second tree
            self.known[name] = float(max(d1.mean(), d2.mean())) <= self.limit
        return self.known[name]


def invariances(points: np.ndarray, tolerance: float) -> dict[str, bool]:
    """Every transform of :data:`TRANSFORMS` tested: whether it maps the sampled surface onto itself."""
    inv = Invariances(points, tolerance)
    return {name: inv[name] for name in TRANSFORMS}


def classify(inv: Invariances | Mapping[str, bool]) -> str:
    """Symmetry type from invariances (a mapping transform name -> bool), most symmetric first."""
    if inv["rot_odd"] and inv["rot_45"]:
        return "radial"
    if inv["rot90"]:
        return "rotational-4"
    if inv["rot180"]:
        return "rotational-2"
    if inv["mirror_x"]:
        return "left-right"
    if inv["mirror_y"]:
        return "front-back"
    if inv["diag"]:  # mirror axis through the back-left and front-right corners
        return "corner-left"
    if inv["antidiag"]:  # mirror axis through the back-right and front-left corners
        return "corner-right"
    return "none"


def detect(vertices: np.ndarray, faces: np.ndarray, tolerance: float = 0.02, samples: int = 1500, seed: int = 0) -> str:
    """Symmetry type of a model-space mesh (front = +Y)."""
    if len(faces) == 0:
        return "none"
    points = surface_samples(np.asarray(vertices, float), np.asarray(faces), samples, seed)
    return classify(Invariances(points, tolerance))
