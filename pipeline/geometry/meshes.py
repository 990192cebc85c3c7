"""Triangle meshes as ``(vertices (n, 3) float, faces (m, 3) int)`` pairs, built with trimesh.creation."""
from __future__ import annotations

from types import ModuleType
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike

Mesh = tuple[np.ndarray, np.ndarray]


def _creation() -> ModuleType:
    """trimesh.creation, imported on first use (trimesh takes ~0.7 s to import; most stages never need it)."""
    import trimesh.creation

    return trimesh.creation


def _pair(m: Any) -> Mesh:
    return np.asarray(m.vertices, dtype=float), np.asarray(m.faces, dtype=np.int64)


def box(extents: ArrayLike, centre: ArrayLike = (0.0, 0.0, 0.0)) -> Mesh:
    """Axis-aligned box of full ``extents`` (x, y, z) centred at ``centre``."""
    m = _creation().box(extents=np.asarray(extents, dtype=float))
    m.apply_translation(centre)
    return _pair(m)


def cylinder(radius: float, height: float, centre: ArrayLike = (0.0, 0.0, 0.0), sections: int = 12) -> Mesh:
    """Vertical cylinder."""
    m = _creation().cylinder(radius=radius, height=height, sections=sections)
    m.apply_translation(centre)
    return _pair(m)


def cone(radius: float, height: float, base: ArrayLike = (0.0, 0.0, 0.0), sections: int = 12) -> Mesh:
    """Vertical cone standing on ``base``."""
    m = _creation().cone(radius=radius, height=height, sections=sections)
    m.apply_translation(base)
    return _pair(m)


def sphere(radius: float, centre: ArrayLike = (0.0, 0.0, 0.0), subdivisions: int = 1) -> Mesh:
    m = _creation().icosphere(subdivisions=subdivisions, radius=radius)
    m.apply_translation(centre)
    return _pair(m)


def combine(parts: list[Mesh]) -> Mesh:
    """Concatenate meshes into one (faces re-indexed)."""
    verts, faces, offset = [], [], 0
    for v, f in parts:
        verts.append(v)
        faces.append(f + offset)
        offset += len(v)
    return np.concatenate(verts), np.concatenate(faces)


def to_origin_bottom_centre(mesh: Mesh) -> Mesh:
    """Translate so the bounding box is centred on x, y and rests on z = 0."""
    v, f = mesh
    lo, hi = v.min(axis=0), v.max(axis=0)
    shift = np.array([-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -lo[2]])
    return v + shift, f


def transform(vertices: np.ndarray, position: ArrayLike, yaw: float, scale: ArrayLike = (1.0, 1.0, 1.0)) -> np.ndarray:
    """Model -> world: ``Rz(yaw) (scale * v) + position``."""
    v = np.asarray(vertices, dtype=float) * np.asarray(scale, dtype=float)
    c, s = np.cos(yaw), np.sin(yaw)
    out = np.empty_like(v)
    out[:, 0] = c * v[:, 0] - s * v[:, 1]
    out[:, 1] = s * v[:, 0] + c * v[:, 1]
    out[:, 2] = v[:, 2]
    return cast(np.ndarray, out + np.asarray(position, dtype=float))


def prisms(corners: np.ndarray, z0: float, z1: float) -> Mesh:
    """Vertical prisms over ``(n, k, 2)`` convex counter-clockwise outlines: one closed mesh each, concatenated.

    Faces are ordered prism by prism: ``2 * k + 2 * (k - 2)`` faces per prism.
    """
    corners = np.asarray(corners, dtype=float)
    n, k, _ = corners.shape
    bottom = np.concatenate([corners, np.full((n, k, 1), z0)], axis=2)
    top = np.concatenate([corners, np.full((n, k, 1), z1)], axis=2)
    verts = np.concatenate([bottom, top], axis=1).reshape(-1, 3)  # per prism: k bottom then k top
    i = np.arange(k)
    j = (i + 1) % k
    sides = np.concatenate([np.stack([i, j, j + k], 1), np.stack([i, j + k, i + k], 1)])
    fan = np.arange(1, k - 1)
    caps = np.concatenate([np.stack([np.zeros_like(fan), fan + 1, fan], 1),
                           np.stack([np.full_like(fan, k), fan + k, fan + 1 + k], 1)])
    local = np.concatenate([sides, caps])
    faces = (local[None, :, :] + (2 * k * np.arange(n))[:, None, None]).reshape(-1, 3)
    return verts, faces


def faces_per_prism(k: int = 4) -> int:
    return 2 * k + 2 * (k - 2)
