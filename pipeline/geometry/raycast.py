"""Ray casting through trimesh with the Embree backend (embreex); trimesh's pure-Python backend on request.

One :class:`RoomScene` per room holds every mesh of the room in one BVH, with a face -> owner lookup.
"""
from __future__ import annotations

import logging
import warnings

import numpy as np
import trimesh

from .meshes import Mesh, combine

log = logging.getLogger("planit.raycast")


class BackendError(RuntimeError):
    """The requested ray backend is not available."""


def intersector_class(backend: str):
    """The trimesh intersector class for ``backend`` ('embree' or 'python'); fail clearly if Embree is missing."""
    if backend == "embree":
        from trimesh.ray import has_embree

        if not has_embree:
            raise BackendError("extract.backend is 'embree' but trimesh cannot load embreex (pip install "
                               "embreex==4.4.0.post1; there is no wheel for Linux aarch64). Set extract.backend: "
                               "python to use trimesh's pure-Python backend instead (about 1000x slower).")
        from trimesh.ray.ray_pyembree import RayMeshIntersector
        return RayMeshIntersector
    if backend == "python":
        warnings.warn("using trimesh's pure-Python ray backend: about 1000x slower than Embree", RuntimeWarning, stacklevel=2)
        from trimesh.ray.ray_triangle import RayMeshIntersector
        return RayMeshIntersector
    raise BackendError(f"unknown ray backend '{backend}' (embree | python)")


class RoomScene:
    """All meshes of one room in one ray-casting scene (one BVH), with a face -> (owner, layer) lookup.

    Parameters
    ----------
    parts : list of (vertices (n, 3), faces (m, 3))
    owners : (len(parts),) int, the owner of each part (an object or wall index)
    layers : (len(parts),) int, a tag per part (the extraction uses 0 = meshes, 1 = floor-plan prisms)
    intersector : class from :func:`intersector_class`
    """

    def __init__(self, parts: list[Mesh], owners, layers, intersector) -> None:
        vertices, faces = combine(parts)
        counts = [len(f) for _, f in parts]
        self.owner = np.repeat(np.asarray(owners, dtype=np.int64), counts)
        self.layer = np.repeat(np.asarray(layers, dtype=np.int8), counts)
        mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=False, validate=False)
        self._rays = intersector(mesh)

    def hits(self, origins: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Every hit of every ray, sorted by ray then distance.

        Returns ``(ray (k,) int, owner (k,) int, layer (k,) int, distance (k,) float)``; directions must be
        unit vectors.
        """
        origins = np.array(origins, dtype=np.float64).reshape(-1, 3)
        directions = np.array(directions, dtype=np.float64).reshape(-1, 3)
        if len(origins) == 0:
            return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.int8), np.zeros(0)
        tri, ray, loc = self._rays.intersects_id(ray_origins=origins.copy(), ray_directions=directions.copy(),
                                                 multiple_hits=True, return_locations=True)
        tri, ray = np.asarray(tri, dtype=np.int64), np.asarray(ray, dtype=np.int64)
        loc = np.asarray(loc, dtype=float).reshape(-1, 3)
        dist = np.einsum("ij,ij->i", loc - origins[ray], directions[ray])
        order = np.lexsort((dist, ray))
        tri = tri[order]
        return ray[order], self.owner[tri], self.layer[tri], dist[order]


def first_accepted(ray: np.ndarray, owner: np.ndarray, dist: np.ndarray, accept: np.ndarray,
                   n_rays: int) -> tuple[np.ndarray, np.ndarray]:
    """Nearest accepted hit per ray: ``(owner (n_rays,), distance (n_rays,))``, -1 / inf where none.

    ``accept`` is a boolean mask over the hits (sorted by ray then distance, as :meth:`RoomScene.hits` returns).
    """
    best_owner = np.full(n_rays, -1, dtype=np.int64)
    best_dist = np.full(n_rays, np.inf)
    r, o, d = ray[accept], owner[accept], dist[accept]
    if len(r):
        first = np.unique(r, return_index=True)[1]
        best_owner[r[first]] = o[first]
        best_dist[r[first]] = d[first]
    return best_owner, best_dist
