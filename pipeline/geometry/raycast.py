"""Ray casting through trimesh with the Embree backend (embreex); trimesh's pure-Python backend on request.

One :class:`RoomScene` per room holds every mesh of the room in one BVH, with a face -> owner lookup.
"""
from __future__ import annotations

import logging
import warnings
from collections.abc import Callable
from types import SimpleNamespace
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike

from ..errors import PlanitError
from .meshes import Mesh, combine

log = logging.getLogger("planit.raycast")
# accept(ray (k,), owner (k,), layer (k,), face (k,)) -> (k,) bool: which hits a ray takes (RoomScene.first_accepted)
Accept = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], np.ndarray]


class BackendError(PlanitError):
    """The requested ray backend is not available."""


def intersector_class(backend: str) -> type[Any]:
    """The trimesh intersector class for ``backend`` ('embree' or 'python'); fail clearly if Embree is missing."""
    if backend == "embree":
        import importlib.util

        if importlib.util.find_spec("embreex") is None:
            raise BackendError("extract.backend is 'embree' but trimesh cannot load embreex (pip install "
                               "embreex==4.4.0.post1; there is no wheel for Linux aarch64). Set extract.backend: "
                               "python to use trimesh's pure-Python backend instead (about 1000x slower).")
        return EmbreeIntersector
    if backend == "python":
        warnings.warn("using trimesh's pure-Python ray backend: about 1000x slower than Embree", RuntimeWarning, stacklevel=2)
        from trimesh.ray.ray_triangle import RayMeshIntersector
        return RayMeshIntersector
    raise BackendError(f"unknown ray backend '{backend}' (embree | python)")


class EmbreeIntersector:
    """First-hit queries on one triangle mesh through embreex, sharing one Embree device across scenes.

    trimesh's own Embree wrapper rehashes the mesh on every query and builds a new device per scene;
    for thousands of small per-room scenes those costs dominate, so the extraction talks to embreex
    directly (same library, same float32 Embree kernels) and keeps trimesh for meshes and the
    pure-Python fallback. Vertices are stored relative to the mesh's minimum corner for float32 precision.
    """

    _device = None

    def __init__(self, mesh: Any) -> None:
        from embreex import rtcore, rtcore_scene
        from embreex.mesh_construction import TriangleMesh

        if EmbreeIntersector._device is None:
            EmbreeIntersector._device = rtcore.EmbreeDevice()
        vertices = np.asarray(mesh.vertices, dtype=np.float64)
        self.origin = vertices.min(axis=0) if len(vertices) else np.zeros(3)
        self.scene = rtcore_scene.EmbreeScene(EmbreeIntersector._device)
        TriangleMesh(scene=self.scene, vertices=(vertices - self.origin).astype(np.float32),
                     indices=np.asarray(mesh.faces, dtype=np.int32))

    def intersects_first(self, ray_origins: np.ndarray, ray_directions: np.ndarray) -> np.ndarray:
        """Index of the first triangle each ray hits, -1 for none (directions must be unit vectors)."""
        origins = (np.asarray(ray_origins, dtype=np.float64) - self.origin).astype(np.float32)
        return cast(np.ndarray, self.scene.run(origins, np.asarray(ray_directions, dtype=np.float32)))


class RoomScene:
    """All meshes of one room in one ray-casting scene (one BVH), with a face -> (owner, layer) lookup.

    Parameters
    ----------
    parts : list of (vertices (n, 3), faces (m, 3))
    owners : (len(parts),) int, the owner of each part (an object or wall index)
    layers : (len(parts),) int, a tag per part (the extraction uses 0 = meshes, 1 = floor-plan prisms)
    intersector : class from :func:`intersector_class`
    """

    def __init__(self, parts: list[Mesh], owners: ArrayLike, layers: ArrayLike, intersector: type[Any]) -> None:
        vertices, faces = combine(parts)
        counts = [len(f) for _, f in parts]
        self.owner = np.repeat(np.asarray(owners, dtype=np.int64), counts)
        self.layer = np.repeat(np.asarray(layers, dtype=np.int8), counts)
        if intersector is EmbreeIntersector:  # needs only the arrays: no trimesh import on the fast path
            mesh: object = SimpleNamespace(vertices=vertices, faces=faces)
        else:
            import trimesh

            mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=False, validate=False)
        v0 = vertices[faces[:, 0]]
        self._normal = np.cross(vertices[faces[:, 1]] - v0, vertices[faces[:, 2]] - v0)
        self._offset = np.einsum("ij,ij->i", self._normal, v0)  # face planes: normal . x = offset
        self._step = max(1e-8, float(np.ptp(vertices, axis=0).max()) * 1e-6)
        self.up = self._normal[:, 2] > 0  # faces whose outward normal points up (surfaces that can hold things)
        self._rays = intersector(mesh)

    def first_accepted(self, origins: np.ndarray, directions: np.ndarray, accept: Accept, max_dist: ArrayLike = np.inf,
                       max_steps: int = 256) -> tuple[np.ndarray, np.ndarray]:
        """Nearest hit per ray that ``accept`` takes, stepping through the hits it refuses.

        ``accept(ray (k,), owner (k,), layer (k,), face (k,)) -> (k,) bool``. A ray retires at its first accepted hit,
        when it leaves the scene, or beyond ``max_dist`` (scalar or per ray). Directions must be unit vectors.
        Returns ``owner (n,)`` (-1: none) and ``distance (n,)`` (inf: none).
        """
        origins = np.array(origins, dtype=np.float64).reshape(-1, 3)
        directions = np.array(directions, dtype=np.float64).reshape(-1, 3)
        n = len(origins)
        best_owner = np.full(n, -1, dtype=np.int64)
        best_dist = np.full(n, np.inf)
        travelled = np.zeros(n)
        limit = np.broadcast_to(np.asarray(max_dist, dtype=float), (n,))
        live = np.arange(n)
        at = origins.copy()
        last = np.full(n, -1, dtype=np.int64)
        for _ in range(max_steps):
            if not len(live):
                break
            tri = np.asarray(self._rays.intersects_first(ray_origins=at[live], ray_directions=directions[live]), np.int64)
            hit = tri >= 0
            live, tri = live[hit], tri[hit]
            d = directions[live]
            nrm = self._normal[tri]
            denom = np.einsum("ij,ij->i", nrm, d)
            flat = denom == 0
            step = (self._offset[tri] - np.einsum("ij,ij->i", nrm, at[live])) / np.where(flat, 1.0, denom)
            step = np.where(flat, 0.0, np.maximum(step, 0.0))
            dist = travelled[live] + step
            inside = dist <= limit[live]
            live, tri, d, step, dist = live[inside], tri[inside], d[inside], step[inside], dist[inside]
            ok = accept(live, self.owner[tri], self.layer[tri], tri)
            best_owner[live[ok]] = self.owner[tri[ok]]
            best_dist[live[ok]] = dist[ok]
            live, tri, d, step = live[~ok], tri[~ok], d[~ok], step[~ok]
            stuck = last[live] == tri  # re-hit the same face: push further
            push = self._step * np.where(stuck, 64.0, 1.0)
            at[live] += d * (step + push)[:, None]
            travelled[live] += step + push
            last[live] = tri
        return best_owner, best_dist
