"""Interpenetration depth between two objects' meshes, with Embree: one implementation for every collision check.

Boxes overstate overlap wherever a shape is not a box (an L-shaped sofa's box swallows its coffee table, a table's
box holds the chair tucked under it). Where both objects have a mesh, the depth is measured on the meshes: the
overlap of their boxes is sampled on a grid, each point is tested inside or outside each mesh by ray parity (three
skewed directions, majority vote, so a mesh with small holes still reads right; one mesh per ray scene, so rays
step through that mesh's faces alone, and the second mesh only at the points inside the first), and the depth is the thickness of
the region inside both: twice its largest inscribed radius (a Euclidean distance transform). For a slab of overlap,
or a box corner pushed into a box, that is the smallest push that clears it; a corner turned 45 deg reads 0.83 of its
depth (the wedge's inscribed diameter). Accurate to one grid pitch.

A grid coarser than the parts it samples misses them: two bookshelves whose 2 cm panels cut through each other
read 0 on a 6 cm grid. Where the grid finds less than two pitches, a surface screen looks where the surfaces
cross: points sampled on each mesh's faces in the overlap (about one per ``surface_spacing`` squared) are tested
inside the other mesh, and around those inside it the region inside both is measured the same way on small fine
grids (cubes of ``surface_window`` at ``min_pitch``); the depth is the larger of the two measures.
"""
from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from scipy import ndimage

from .meshes import Mesh, transform
from .raycast import RoomScene

# skewed so that rays do not graze the axis-aligned faces and edges furniture is made of
DIRECTIONS = np.array([[1.0, 0.137, 0.071], [-0.113, 1.0, 0.059], [0.067, -0.091, 1.0]])
DIRECTIONS /= np.linalg.norm(DIRECTIONS, axis=1, keepdims=True)


@dataclass(frozen=True)
class Measure:
    """How a pair of meshes is measured: one ``penetration`` section of the config (``filter``,
    ``instantiate.checks``, ``evaluate.collision``; keys and units in the schema), built once where a stage reads it.
    ``measure``: ``mesh`` or ``box``; the sampling grid (``resolution``, ``min_pitch`` m, ``max_cells``) and the
    surface screen (``surface_spacing`` m, None: no screen; ``max_surface_points``, ``surface_window`` m,
    ``max_windows``)."""

    measure: str
    resolution: int
    min_pitch: float
    max_cells: int
    surface_spacing: float | None
    max_surface_points: int
    surface_window: float
    max_windows: int


@dataclass(frozen=True)
class CollisionTest:
    """Which pairs penetrate: deeper than ``limit`` (m) by ``measure``, each mesh pair it clears measured again by
    ``confirm`` where given (so a coarse measure may screen but never clear a pair the finer one finds); ``intersector``:
    the ray backend's class (None: every pair measured as boxes, e.g. a filter run without meshes)."""

    measure: Measure
    limit: float
    intersector: type[Any] | None
    confirm: Measure | None = None

    @classmethod
    def of(cls, penetration: Mapping[str, Any], limit: float, intersector: type[Any] | None,
           confirm: Mapping[str, Any] | None = None) -> "CollisionTest":
        """From the config's ``penetration`` section(s) and limit."""
        return cls(Measure(**penetration), float(limit), intersector, None if confirm is None else Measure(**confirm))


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

    # every hit is refused, so the scene steps through them all
    def count(ray: np.ndarray, owner: np.ndarray, layer: np.ndarray, face: np.ndarray) -> np.ndarray:
        crossings[:] += np.bincount(ray, minlength=len(points))
        return np.zeros(len(ray), dtype=bool)

    scene.first_accepted(points, np.broadcast_to(direction, points.shape), count, max_steps=1024)
    return cast(np.ndarray, crossings % 2 == 1)


def mesh_scene(mesh: tuple[np.ndarray, np.ndarray], intersector: type[Any]) -> RoomScene:
    """A ray scene ``mesh (vertices (v, 3), faces (f, 3))`` alone, for :func:`inside_scene`."""
    return RoomScene([mesh], np.array([0]), np.array([0]), intersector)


def inside_scene(scene: RoomScene, points: np.ndarray) -> np.ndarray:
    """``(n,)`` bool: each point ``(n, 3)`` inside the scene's mesh, by the parity of the crossings of a ray in each
    of :data:`DIRECTIONS`, the majority of the three deciding (the third ray is cast only where the first two
    disagree)."""
    if not len(points):
        return np.zeros(0, dtype=bool)
    first, second = (crossings_odd(scene, points, d) for d in DIRECTIONS[:2])
    out = first & second
    split = np.flatnonzero(first != second)
    if len(split):
        out[split] = crossings_odd(scene, points[split], DIRECTIONS[2])
    return cast(np.ndarray, out)


def thickness(mask: np.ndarray, pitch: float) -> float:
    """Thickness (m) of a voxel region, within a pitch: twice its largest inscribed radius (the distance from a cell
    centre to the nearest outside cell centre, so half a cell too much on each side); 0 when empty."""
    if not mask.any():
        return 0.0
    return (2.0 * float(ndimage.distance_transform_edt(mask).max()) - 1.0) * pitch + pitch / 2


def mesh_penetration(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray], intersector: type[Any],
                     m: Measure, enough: float = np.inf) -> float:
    """Penetration depth (m) of two meshes in world coordinates, each ``(vertices (n, 3), faces (m, 3))``, by the
    grid and the surface screen of ``m`` (:func:`surface_depth`), which runs where the grid finds less than two
    pitches: a region the grid misses is thinner than that (at most sqrt 3 pitches), so where it finds more the
    screen cannot find deeper. ``enough`` (m): a caller that asks only whether the depth exceeds it gets the grid's
    depth, without the screen, once that already does (a lower bound above ``enough``, never a different verdict)."""
    lo, hi = box_overlap(a[0].min(0), a[0].max(0), b[0].min(0), b[0].max(0))
    if np.any(hi <= lo):
        return 0.0
    scenes = mesh_scene(a, intersector), mesh_scene(b, intersector)
    cells, pitch = grid(lo, hi, m.resolution, m.min_pitch, m.max_cells)
    points = cells.reshape(-1, 3)
    both = inside_scene(scenes[0], points)
    both[both] = inside_scene(scenes[1], points[both])  # only the points inside the first mesh can be in both
    depth = thickness(both.reshape(cells.shape[:3]), pitch)
    if m.surface_spacing is None or depth >= 2 * pitch or depth > enough:
        return depth
    return max(depth, surface_depth((a, b), scenes, lo, hi, m))


def surface_points(mesh: tuple[np.ndarray, np.ndarray], lo: np.ndarray, hi: np.ndarray, spacing: float,
                   max_points: int, inset: float, rng: np.random.Generator) -> np.ndarray:
    """Points ``(k, 3)`` on the mesh's faces inside the box ``[lo, hi]``: uniform over the area, about one per
    ``spacing`` squared, sparser where that would put more than ``max_points`` in the box (faces are drawn whole
    and the points outside dropped; the area in the box is estimated from each face's box), each moved ``inset``
    (m) inward, against its face's normal (outward by the winding), so that none lies on a face another mesh
    shares."""
    v, f = mesh
    below, above = v < lo, v > hi  # (n, 3) per axis: a face whose corners all lie on one side misses the box
    off = below[f[:, 0]] & below[f[:, 1]] & below[f[:, 2]] | above[f[:, 0]] & above[f[:, 1]] & above[f[:, 2]]
    tri = v[f[~off.any(1)]]  # (m, 3 corners, 3)
    t_lo, t_hi = tri.min(1), tri.max(1)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = 0.5 * np.linalg.norm(normal, axis=1)
    extent = t_hi - t_lo
    share = np.where(extent > 1e-9, (np.minimum(t_hi, hi) - np.maximum(t_lo, lo)) / np.maximum(extent, 1e-9), 1.0)
    in_box = float(area @ share.prod(1))
    if in_box <= 0:
        return np.zeros((0, 3))
    density = min(1.0 / spacing ** 2, max_points / in_box)
    n = int(min(np.ceil(density * area.sum()), 8 * max_points))
    pick = rng.choice(len(tri), n, p=area / area.sum())
    u, v = rng.random((2, n))
    out = u + v > 1  # fold the far half of the unit square back onto the triangle
    u[out], v[out] = 1 - u[out], 1 - v[out]
    t = tri[pick]
    points = t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + v[:, None] * (t[:, 2] - t[:, 0])
    points -= normal[pick] * (inset / (2 * area[pick]))[:, None]
    return cast(np.ndarray, points[np.all((points >= lo) & (points <= hi), axis=1)])


def surface_depth(meshes: tuple[Mesh, Mesh], scenes: tuple[RoomScene, RoomScene], lo: np.ndarray, hi: np.ndarray,
                  m: Measure) -> float:
    """Thickness (m) of the region inside both meshes where their surfaces cross: the points of each mesh's surface
    in the overlap ``[lo, hi]`` (:func:`surface_points`, seeded) that lie inside the other mesh bound that region, so
    :func:`window_depth` measures it around them; 0 where no surface point is inside the other mesh. The points lie
    a tenth of ``min_pitch`` inside their own mesh: one on a face that the other mesh touches from outside would
    read either way (parity on a face), and take a window from a place where the surfaces cross."""
    rng = np.random.default_rng(0)
    found = []
    for mesh, other in zip(meshes, scenes[::-1]):
        points = surface_points(mesh, lo, hi, cast(float, m.surface_spacing), m.max_surface_points, m.min_pitch / 10, rng)
        found.append(points[inside_scene(other, points)])
    seeds = np.concatenate(found)
    return window_depth(scenes, seeds, lo, hi, m) if len(seeds) else 0.0


def window_depth(scenes: tuple[RoomScene, RoomScene], seeds: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                 m: Measure) -> float:
    """:func:`thickness` of the region inside both meshes in cubes of side ``surface_window`` (m) at pitch
    ``min_pitch``, each centred on one of the points ``seeds (n, 3)`` in the overlap ``[lo, hi]``: one per
    window-sized block holding seeds, at most ``max_windows`` spread over the blocks' sorted order. The cubes'
    cells lie on one lattice, each tested once; those centred outside ``[lo, hi]`` are outside untested."""
    pitch = m.min_pitch
    side = max(2, int(round(m.surface_window / pitch)))
    dims = np.ceil((hi - lo) / pitch).astype(np.int64) + 2 * side + 1
    cell = np.floor((seeds - lo) / pitch).astype(np.int64) + side  # >= side: a cube's cells have no negative index
    _, first = np.unique(np.ravel_multi_index((cell // side).T, dims), return_index=True)
    if len(first) > m.max_windows:
        first = first[np.linspace(0, len(first) - 1, m.max_windows).astype(np.int64)]
    offsets = np.stack(np.meshgrid(*[np.arange(side) - side // 2] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    cells = np.ravel_multi_index((cell[first][:, None, :] + offsets).reshape(-1, 3).T, dims)  # (windows * side**3,)
    keys, back = np.unique(cells, return_inverse=True)
    centres = lo + (np.column_stack(np.unravel_index(keys, dims)) - side + 0.5) * pitch
    both = np.all((centres >= lo) & (centres <= hi), axis=1)
    both[both] = inside_scene(scenes[0], centres[both])
    both[both] = inside_scene(scenes[1], centres[both])
    windows = both[back].reshape(-1, side, side, side)
    # one outside layer around each cube, so that stacked along x the cubes' distances stay their own
    return thickness(np.pad(windows, ((0, 0), (1, 1), (1, 1), (1, 1))).reshape(-1, side + 2, side + 2), pitch)


def penetrating_pairs(box_depth: np.ndarray, objs: dict[str, Any], test: CollisionTest,
                      exact: bool = False) -> Iterator[tuple[int, int, float, str]]:
    """Pairs ``(i, j, depth, measure)``, deepest box overlap first, that penetrate deeper than ``test.limit``:
    measured on the meshes where both objects have one (``measure: mesh``), else on the boxes; a mesh pair the first
    measure clears is measured again by ``test.confirm`` where given (the depth is accurate to one pitch only).
    ``exact``: each pair's depth measured in full; else a mesh pair's depth is a lower bound above the limit where the
    coarse grid alone shows it penetrating (the same pairs)."""
    i, j = np.nonzero(np.triu(box_depth > test.limit, 1))
    for k in np.argsort(-box_depth[i, j], kind="stable"):
        a, b = int(i[k]), int(j[k])
        ma, mb = objs["meshes"][a], objs["meshes"][b]
        if test.measure.measure == "box" or test.intersector is None or ma is None or mb is None:
            yield a, b, float(box_depth[a, b]), "boxes"
            continue
        d = _mesh_depth(world_mesh(ma, objs["poses"][a]), world_mesh(mb, objs["poses"][b]), float(box_depth[a, b]), test,
                        np.inf if exact else test.limit)
        if d > test.limit:
            yield a, b, d, "meshes"


def _mesh_depth(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray], box_depth: float,
                test: CollisionTest, enough: float) -> float:
    """Two world meshes' penetration by ``test.measure``, measured again by ``test.confirm`` where the first finds
    at most the limit (a ``box`` confirm takes the boxes' depth instead); each measure stops once past ``enough``
    (:func:`mesh_penetration`)."""
    d = mesh_penetration(a, b, cast(type, test.intersector), test.measure, enough)
    if test.confirm is None or d > test.limit:
        return d
    if test.confirm.measure == "box":
        return box_depth
    return mesh_penetration(a, b, cast(type, test.intersector), test.confirm, enough)


def deepest_penetration(box_depth: np.ndarray, objs: dict[str, Any], test: CollisionTest,
                        exact: bool = False) -> tuple[int, int, float, str] | None:
    """The first of :func:`penetrating_pairs` (None if no pair penetrates)."""
    return next(penetrating_pairs(box_depth, objs, test, exact), None)


def world_mesh(mesh: tuple[np.ndarray, np.ndarray], pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A model's ``(vertices, faces)`` placed by a pose row ``(px, py, pz, yaw, sx, sy, sz)``."""
    return transform(mesh[0], pose[:3], pose[3], pose[4:]), mesh[1]
