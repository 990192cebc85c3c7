"""Interpenetration depth between two objects' meshes, with Embree: one implementation for every collision check.

Boxes overstate overlap wherever a shape is not a box (an L-shaped sofa's box swallows its coffee table, a table's
box holds the chair tucked under it). Where both objects have a mesh, the depth is measured on the meshes: the
overlap of their boxes is sampled on a grid, each point is tested inside or outside each mesh by ray parity (three
skewed directions, majority vote, so a mesh with small holes still reads right; one mesh per ray scene, so rays
step through that mesh's faces alone, and the second mesh only at the points inside the first), and the depth is the thickness of
the region inside both: twice its largest inscribed radius (a Euclidean distance transform). For a slab of overlap,
or a box corner pushed into a box, that is the smallest push that clears it; a corner turned 45 deg reads 0.83 of its
depth (the wedge's inscribed diameter). Accurate to one grid pitch.
"""
from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from scipy import ndimage

from .meshes import transform
from .raycast import RoomScene

# skewed so that rays do not graze the axis-aligned faces and edges furniture is made of
DIRECTIONS = np.array([[1.0, 0.137, 0.071], [-0.113, 1.0, 0.059], [0.067, -0.091, 1.0]])
DIRECTIONS /= np.linalg.norm(DIRECTIONS, axis=1, keepdims=True)


def box_overlap(lo_a: np.ndarray, hi_a: np.ndarray, lo_b: np.ndarray, hi_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The axis-aligned overlap ``(lo (3,), hi (3,))`` of two axis-aligned boxes (empty where any ``hi <= lo``)."""
    return np.maximum(lo_a, lo_b), np.minimum(hi_a, hi_b)


def grid(lo: np.ndarray, hi: np.ndarray, resolution: int, min_pitch: float, max_cells: int) -> tuple[np.ndarray, float]:
    """Cell centres ``(nx, ny, nz, 3)`` over the box ``[lo, hi]`` with one empty cell of padding on each side, and the
    pitch: fine enough for ``resolution`` cells along the longest side and 6 across the thinnest, never below
    ``min_pitch``, coarsened until at most ``max_cells`` cells."""
    size = np.maximum(hi - lo, 1e-9)
    pitch = max(min(float(size.max()) / resolution, float(size.min()) / 6), min_pitch)
    pitch = max(pitch, float(np.prod(size)) ** (1 / 3) / max_cells ** (1 / 3))
    axes = [np.arange(a - pitch / 2, b + pitch, pitch) for a, b in zip(lo, hi)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1), pitch


def crossings_odd(scene: RoomScene, points: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """``(n,)`` bool: whether a ray from each point along ``direction (3,)`` crosses the scene's faces an odd
    number of times."""
    crossings = np.zeros(len(points), dtype=np.int64)

    def count(ray, owner, layer, face):  # every hit is refused, so the scene steps through them all
        crossings[:] += np.bincount(ray, minlength=len(points))
        return np.zeros(len(ray), dtype=bool)

    scene.first_accepted(points, np.broadcast_to(direction, points.shape), count, max_steps=1024)
    return crossings % 2 == 1


def inside(mesh: tuple[np.ndarray, np.ndarray], points: np.ndarray, intersector) -> np.ndarray:
    """``(n,)`` bool: each point inside the mesh ``(vertices (v, 3), faces (f, 3))``, by the parity of the crossings
    of a ray in each of :data:`DIRECTIONS`, the majority of the three deciding (the third ray is cast only where
    the first two disagree)."""
    scene = RoomScene([mesh], np.array([0]), np.array([0]), intersector)
    first, second = (crossings_odd(scene, points, d) for d in DIRECTIONS[:2])
    out = first & second
    split = np.flatnonzero(first != second)
    if len(split):
        out[split] = crossings_odd(scene, points[split], DIRECTIONS[2])
    return out


def thickness(mask: np.ndarray, pitch: float) -> float:
    """Thickness (m) of a voxel region, within a pitch: twice its largest inscribed radius (the distance from a cell
    centre to the nearest outside cell centre, so half a cell too much on each side); 0 when empty."""
    if not mask.any():
        return 0.0
    return (2.0 * float(ndimage.distance_transform_edt(mask).max()) - 1.0) * pitch + pitch / 2


def mesh_penetration(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray], intersector, cfg: dict) -> float:
    """Penetration depth (m) of two meshes in world coordinates, each ``(vertices (n, 3), faces (m, 3))``; ``cfg``:
    ``resolution``, ``min_pitch`` (m) and ``max_cells`` of the sampling grid."""
    lo, hi = box_overlap(a[0].min(0), a[0].max(0), b[0].min(0), b[0].max(0))
    if np.any(hi <= lo):
        return 0.0
    cells, pitch = grid(lo, hi, cfg["resolution"], cfg["min_pitch"], cfg["max_cells"])
    points = cells.reshape(-1, 3)
    both = inside(a, points, intersector)
    both[both] = inside(b, points[both], intersector)  # only the points inside the first mesh can be in both
    return thickness(both.reshape(cells.shape[:3]), pitch)


def penetrating_pairs(box_depth: np.ndarray, objs: dict, cfg: dict) -> Iterator[tuple[int, int, float, str]]:
    """Pairs ``(i, j, depth, measure)``, deepest box overlap first, that penetrate deeper than ``max_penetration``:
    measured on the meshes where both objects have one (``penetration.measure: mesh``), else on the boxes.

    ``cfg['confirm']`` (optional, a finer ``penetration``): a mesh pair the first grid clears is measured again on
    this one, so a coarse grid may screen but never clear a pair that the finer measure finds penetrating (the
    depth is accurate to one pitch only)."""
    pen, limit = cfg["penetration"], cfg["max_penetration"]
    i, j = np.nonzero(np.triu(box_depth > limit, 1))
    for k in np.argsort(-box_depth[i, j], kind="stable"):
        a, b = int(i[k]), int(j[k])
        ma, mb = objs["meshes"][a], objs["meshes"][b]
        if pen["measure"] == "box" or ma is None or mb is None:
            yield a, b, float(box_depth[a, b]), "boxes"
            continue
        d = _mesh_depth(world_mesh(ma, objs["poses"][a]), world_mesh(mb, objs["poses"][b]), float(box_depth[a, b]), cfg)
        if d > limit:
            yield a, b, d, "meshes"


def _mesh_depth(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray], box_depth: float, cfg: dict) -> float:
    """Two world meshes' penetration on ``cfg['penetration']``'s grid, measured again on ``cfg['confirm']``'s where
    the first finds at most ``max_penetration`` (``confirm.measure: box`` takes the boxes' depth instead)."""
    d = mesh_penetration(a, b, cfg["intersector"], cfg["penetration"])
    confirm = cfg.get("confirm")
    if confirm is None or d > cfg["max_penetration"]:
        return d
    return box_depth if confirm["measure"] == "box" else mesh_penetration(a, b, cfg["intersector"], confirm)


def deepest_penetration(box_depth: np.ndarray, objs: dict, cfg: dict) -> tuple[int, int, float, str] | None:
    """The first of :func:`penetrating_pairs` (None if no pair penetrates)."""
    return next(penetrating_pairs(box_depth, objs, cfg), None)


def world_mesh(mesh: tuple[np.ndarray, np.ndarray], pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A model's ``(vertices, faces)`` placed by a pose row ``(px, py, pz, yaw, sx, sy, sz)``."""
    return transform(mesh[0], pose[:3], pose[3], pose[4:]), mesh[1]
