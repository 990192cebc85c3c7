"""Axes and architecture meshes the exports share.

The project is right-handed, z up (``docs/data-model.md``). USD, glTF and 3D-FRONT are right-handed, y up: a point
``(x, y, z)`` becomes ``(x, z, -y)`` (``Y_UP``), a proper rotation, so a yaw about +z is the same yaw about +y.
Unity (AI2-THOR) is left-handed, y up: ``(x, y, z)`` becomes ``(x, z, y)``, a mirror, so a yaw counter-clockwise
about +z is a rotation of ``-yaw`` about Unity's +y.
"""
from __future__ import annotations

import numpy as np

from ..geometry import meshes
from ..geometry.meshes import Mesh
from ..placement.export import floor_mesh, opening_mesh
from ..room import RoomInput, Walls, wall_footprints

Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])  # project (x, y, z) -> (x, z, -y)


def y_up(points: np.ndarray) -> np.ndarray:
    """``(n, 3)`` project points in a right-handed y-up frame."""
    return np.asarray(points, float).reshape(-1, 3) @ Y_UP.T


def floor_top(outline: np.ndarray) -> Mesh:
    """The floor's ``(k, 2)`` outline as triangles at z = 0, counter-clockwise seen from above (normal +z)."""
    v, f = floor_mesh(outline)
    top = f[(v[f][:, :, 2] == 0.0).all(axis=1)]
    used, faces = np.unique(top, return_inverse=True)
    return v[used], faces.reshape(-1, 3)


def inner_face(a: np.ndarray, b: np.ndarray, z0: float, z1: float) -> Mesh:
    """A vertical quad over the ``(2,)`` segment ``a -> b`` from ``z0`` to ``z1``, facing its left (into a room whose
    walls run counter-clockwise)."""
    v = np.array([[a[0], a[1], z0], [b[0], b[1], z0], [b[0], b[1], z1], [a[0], a[1], z1]], float)
    return v, np.array([[0, 2, 1], [0, 3, 2]])


def architecture(room: RoomInput, walls: Walls) -> list[tuple[str, str, Mesh]]:
    """``(element id, kind, z-up world mesh)`` of the floor, each wall (a prism behind its inner face, as in the
    GLB) and each door and window (a box over its segment, through its wall)."""
    out = [("floor", "floor", floor_top(room.outline))]
    out += [(wid, "wall", meshes.prisms(c[None], 0.0, walls.height)) for wid, c in zip(walls.ids, wall_footprints(walls))]
    out += [(str(o["element_id"]), str(o["kind"]), opening_mesh(o, walls)) for o in room.openings]
    return out
